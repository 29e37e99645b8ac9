"""Generated arms: draw from a family, keep the draw only if it is a usable arm.

``generate_arm("planar", 4, seed=7, out_dir="arms")`` draws arms from one
``numpy.random.Generator`` seeded with ``seed`` until one

1. meets the arm contract (``armtransfer.ik.contract``: names, tip site, home keyframe,
   position servos, a second of random control without MuJoCo warnings), after its home is
   solved by IK for spatial arms (tool down over the table's centre cell);
2. compiles to a discrete robot with the requested action model, and
3. solves every Table I task.

A rejected draw is recorded with its one-line reason and the next one is drawn. The accepted
arm is written to ``out_dir/<name>/``: ``<name>.xml``, ``<name>.json`` (family, seed,
parameters, mount, rejections) and ``README.md``; the folder appears only complete. The same
family, joint count and seed always write byte-identical files. Such a file is then a robot
spec anywhere: ``out_dir/<name>/<name>.xml:cartesian`` (its mount is read from the JSON).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from armtransfer.checks import integer_text
from armtransfer.errors import ArmModelError, ArmTransferError
from armtransfer.ik.cache import building, cache_dir
from armtransfer.ik.workspace import DEFAULT_CELL
from armtransfer.io import check_output_dir, staged_directory, write_json_atomic, write_text_atomic
from armtransfer.models.generate import ArmDraw, check_family, draw_arm, planar_tip_cells, with_home
from armtransfer.tasks.arms import SIDECAR_FORMAT, arm_robot, read_sidecar
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.worlds.layout import ROOMS, Layout

MAX_DRAWS = 12


@dataclass(frozen=True)
class GeneratedArm:
    name: str
    xml_path: Path
    draw: ArmDraw
    draws: int
    """How many draws it took (the accepted one included)."""
    rejected: list[str]
    reach: float
    """The share of free cells the compiled robot reaches."""


def arm_name(family: str, dof: int, seed: int) -> str:
    return f"gen_{family}{dof if family == 'planar' else ''}_s{seed}"


def generate_arm(family: str, dof: int, seed: int, out_dir: str | os.PathLike, *, actions: str = "cartesian",
                 max_draws: int = MAX_DRAWS, progress: bool = False) -> GeneratedArm:
    """Draw ``family`` arms with ``dof`` joints from ``seed`` until one is usable; write it."""
    check_family(family, dof)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ArmModelError(f"seed must be an integer >= 0, got {seed!r}")
    name = arm_name(family, dof, seed)
    final = Path(out_dir) / name
    check_output_dir(final, "--out")  # before the draws, not after
    rng = np.random.default_rng(seed)
    rejected: list[str] = []
    with tempfile.TemporaryDirectory(prefix="armgen-") as work:
        for k in range(max_draws):
            draw = draw_arm(family, dof, rng, name)
            reason, draw, reach = _try(draw, Path(work), actions, progress)
            if reason is None:
                with staged_directory(final, flag="--out") as tmp:
                    xml = tmp / f"{name}.xml"
                    write_text_atomic(xml, draw.xml)
                    write_json_atomic(tmp / f"{name}.json", sidecar(draw, seed, k, rejected, reach))
                    write_text_atomic(tmp / "README.md", readme(draw, seed, k, rejected, reach))
                return GeneratedArm(name, final / f"{name}.xml", draw, k + 1, rejected, reach)
            rejected.append(f"draw {k + 1}: {reason}")
    raise ArmModelError(f"no usable {family} arm with {dof} joints in {max_draws} draws from seed {seed}; "
                        f"the last: {rejected[-1]}")


def _try(draw: ArmDraw, work: Path, actions: str, progress: bool) -> tuple[str | None, ArmDraw, float]:
    """(why the draw is rejected or None, the draw with its solved home, reach)."""
    from armtransfer.ik.contract import problems  # MuJoCo, only when an arm is built

    if draw.kind == "planar":  # cheap first: can the tip be over every Table I cell at all?
        reached = planar_tip_cells(draw, DEFAULT_CELL)
        far = [ROOMS.xy(c) for t in TABLE_I.values() for c in t.cells()
               if not any((ROOMS.xy(c)[0] + dx, ROOMS.xy(c)[1] + dy) in reached for dx in (-1, 0, 1) for dy in (-1, 0, 1))]
        if far:
            return f"the tip cannot get near Table I cell {far[0]}", draw, 0.0
    path = work / f"{draw.name}.xml"
    path.write_text(draw.xml)
    if draw.tip_down:
        home, why = _solve_home(path, draw)
        if home is None:
            return why, draw, 0.0
        draw = with_home(draw, home)
        path.write_text(draw.xml)
    found = problems(path, ROOMS, mount=draw.mount_pos, yaw=draw.mount_yaw)
    if found:
        return found[0], draw, 0.0
    if draw.kind != "planar" and actions == "joint":
        return "spatial arms have no joint action model", draw, 0.0
    try:
        robot = robot_of(path, draw, actions, progress=progress)
    except ArmTransferError as err:
        return str(err), draw, 0.0
    unsolved = [n for n, t in TABLE_I.items() if not _solvable(robot, t)]
    if unsolved:
        return f"cannot solve Table I task{'s' if len(unsolved) > 1 else ''} {', '.join(map(str, unsolved))}", draw, 0.0
    return None, draw, robot.arm.reach


def _solve_home(path: Path, draw: ArmDraw) -> tuple[list[float] | None, str]:
    """A home with the tool down over the table's centre cell, by mink IK."""
    from armtransfer.ik.scene import build_scene  # MuJoCo, only when an arm is built
    from armtransfer.ik.solve import TipIK  # MuJoCo, only when an arm is built

    scene = build_scene(path, "tip", draw.mount_pos, draw.mount_yaw, layout=ROOMS)
    ik = TipIK(scene, tip_down=True, max_iters=200)
    res = ik.solve(np.zeros(2), scene.home)
    if not ik.ok(res):
        return None, f"no tool-down home over the table centre (IK error {1000 * res.error:.1f} mm)"
    return [round(float(v), 4) for v in res.q], ""


def robot_of(path: Path, draw: ArmDraw | dict, actions: str, **kwargs):
    """The discrete robot of a generated arm file (its mount from the draw or sidecar)."""
    d = draw if isinstance(draw, dict) else sidecar(draw, 0, 0, [], 0.0)
    return arm_robot(None, actions, xml_path=path, tip_site="tip", base_pos=tuple(d["mount_pos"]),
                     base_yaw=d["mount_yaw"], tip_down=d["tip_down"], joint_step=d["joint_step"], **kwargs)


def _solvable(robot, task) -> bool:
    start, goal = task.cells()
    have = set(np.unique(robot.label).tolist())
    if start not in have or goal not in have:
        return False
    return robot.shortest_path(robot.start_state(start), goal) is not None


def sidecar(draw: ArmDraw, seed: int, index: int, rejected: list[str], reach: float) -> dict:
    return {"format": SIDECAR_FORMAT, "name": draw.name, "family": draw.family, "dof": draw.dof, "seed": seed,
            "draw": index + 1, "params": draw.params, "mount_pos": list(draw.mount_pos),
            "mount_yaw": draw.mount_yaw, "tip_down": draw.tip_down, "kind": draw.kind,
            "joint_step": draw.joint_step, "reach": round(reach, 4), "rejected": rejected}


def readme(draw: ArmDraw, seed: int, index: int, rejected: list[str], reach: float) -> str:
    params = "\n".join(f"- `{k}`: {v}" for k, v in draw.params.items())
    why = "\n".join(f"- {r}" for r in rejected) or "- none"
    models = "joint, cartesian" if draw.kind == "planar" else "cartesian"
    return (f"# {draw.name}\n\nA generated arm of the `{draw.family}` family: {draw.dof} hinge joints, drawn with "
            f"seed {seed} (draw {index + 1}). Written by `armtransfer arms generate --family {draw.family} "
            f"--dof {draw.dof} --seed {seed}`.\n\n- Action models: {models}.\n- Mount: base at "
            f"{tuple(round(v, 4) for v in draw.mount_pos)} m, yaw {draw.mount_yaw:.4f} rad, tool "
            f"{'pointing down' if draw.tip_down else 'a vertical stylus'}.\n- Reach: {100 * reach:.1f}% of the "
            f"free cells with the cartesian model; every Table I task solvable.\n\n## Parameters\n\n{params}\n\n"
            f"## Rejected draws\n\n{why}\n")


def resolve_generated(spec: str, progress: bool = False, layout: Layout = ROOMS):
    """The robot of ``gen:FAMILY:DOF:SEED[:ACTIONS]``: the arm generated with those settings,
    kept in the cache directory (``$ARMTRANSFER_CACHE/generated``) after the first use, on the
    world ``layout`` (it is drawn for the rooms' table, which other worlds keep by default)."""
    xml, generated, actions = generated_file(spec, progress)
    return robot_of(xml, generated, actions, progress=progress, layout=layout)


def generated_file(spec: str, progress: bool = False) -> tuple[Path, dict, str]:
    """(the arm file, its sidecar, the action model named) of ``gen:FAMILY:DOF:SEED[:ACTIONS]``,
    generated into the cache directory at its first use."""
    parts = spec.split(":")
    numbers = [integer_text(p, signed=False) for p in parts[2:4]]
    if len(parts) not in (4, 5) or None in numbers:
        shown = spec if len(spec) <= 80 else f"{spec[:60]}... ({len(spec)} characters)"
        raise ArmModelError(f"a generated arm is gen:FAMILY:DOF:SEED[:ACTIONS], DOF and SEED integers, got {shown!r}")
    family, dof, seed = parts[1], int(parts[2]), int(parts[3])
    actions = parts[4] if len(parts) > 4 else "cartesian"
    name = arm_name(family, dof, seed)
    root = cache_dir() / "generated"
    xml = root / name / f"{name}.xml"
    with building(root / name):  # another process drawing the same arm is waited for, then its arm read
        try:
            generated = read_sidecar(xml) if xml.is_file() else None
        except ArmModelError:
            generated = None
        if generated is None:  # never made, or its files were changed or lost: drawn again (the same arm)
            if os.path.lexists(root / name):
                shutil.rmtree(root / name) if (root / name).is_dir() and not (root / name).is_symlink() \
                    else (root / name).unlink()
            generate_arm(family, dof, seed, root, progress=progress)
            generated = read_sidecar(xml)
            assert generated is not None  # generate_arm has just written it
    return xml, generated, actions
