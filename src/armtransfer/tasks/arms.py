"""Arms as discrete robots: ``arm_robot("planar2", "joint")`` or ``robot("ur5e_like:cartesian")``.

A robot name is ``ARM:ACTIONS``. The result is a ``tasks.robot.DiscreteRobot`` whose
labels are the shared rooms-world cells, so every learner runs on it unchanged. Its
``arm`` (an ``ik.description.ArmDescription``) holds ``qpos`` [n_states, nq] (the joint
configuration of every state, to replay paths with the position servos), ``tip``
[n_states, 3], ``reach`` (fraction of free cells reached), ``cache`` ("hit", "miss",
"stale", "corrupt") and the compile settings (``xml_path``, ``tool``, ``mount``, ``yaw``,
``cell_size``, ``layout``: enough to rebuild the exact MuJoCo scene, as
``armtransfer.ik.replay`` does). A bring-your-own arm file without a mount is mounted by
:func:`automatic_mount`.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import sys
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import cast
from pathlib import Path

import numpy as np

import armtransfer.checks as checks
from armtransfer.errors import (ArmModelError, ArmTransferError, InvalidCellError, OutputError, UnknownArmError,
                                UnreachableTableError)
from armtransfer.ik import cache as _cache
from armtransfer.ik.actions import ACTION_MODELS, action_model
from armtransfer.ik.description import ArmDescription
from armtransfer.ik.joint_ranges import check_joint_ranges
from armtransfer.ik.tool import Tool, parse_held
from armtransfer.ik.workspace import DEFAULT_CELL, WALL_HEIGHT, world_cell
from armtransfer.io import check_input, check_writable, parse_json_bytes, read_input, write_json_atomic
from armtransfer.models import ARMS
from armtransfer.tasks.catalog import world_tasks
from armtransfer.tasks.grid_robots import GRID_ROBOTS
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.worlds.layout import ROOMS, Layout

SIDECAR_FORMAT = "armtransfer-generated-arm/1"
"""The JSON ``armtransfer arms generate`` writes beside an arm: its mount and tool."""
COVERS = 0.95
"""A mount beside the table whose reach estimate is at least this share (with every Table I
cell reached) is taken without trying mounts on the table."""


class NotCached(Exception):
    """An arm asked for ``only_cached`` that the cache does not hold (no user error: the caller's
    signal to show it as not compiled)."""


def parse_robot_spec(spec: str) -> tuple[str, str]:
    """'planar2:joint' -> ('planar2', 'joint'); the action model defaults to the arm's first."""
    arm, _, actions = spec.partition(":")
    if arm not in ARMS:
        raise UnknownArmError(f"unknown arm {arm!r}; valid arms: {', '.join(ARMS)}")
    actions = actions or ARMS[arm].actions[0]
    check_actions(arm, actions)
    return arm, actions


def check_actions(arm: str, actions: str) -> None:
    model = action_model(actions)
    allowed = _allowed_actions(ARMS[arm].kind)
    if model.name not in allowed:
        raise UnknownArmError(
            f"arm {arm!r} has no action model {actions!r}; valid action models: {', '.join(allowed)}")


def _allowed_actions(kind: str) -> tuple[str, ...]:
    """Every action model of an arm of this kind: all of them; a spatial arm's ``joint``
    acts over the 3D workspace (``ik.voxels``)."""
    return tuple(ACTION_MODELS)


def _listed_actions(kind: str) -> tuple[str, ...]:
    if kind == "planar":
        return tuple(ACTION_MODELS)
    return tuple(a for a in ACTION_MODELS if ACTION_MODELS[a].kind == "cartesian")


def robot_specs() -> list[str]:
    """Every built-in robot name on the table plane, ``ARM:ACTIONS`` (a spatial arm's
    ``joint`` robot, over the 3D workspace, is left out: see :func:`spatial_joint_specs`)."""
    return [f"{arm}:{a}" for arm, info in ARMS.items() for a in _listed_actions(info.kind)]


def spatial_joint_specs() -> list[str]:
    """The built-in robots that act in joint space over the 3D workspace."""
    return [f"{arm}:joint" for arm, info in ARMS.items() if info.kind != "planar"]


def is_spatial_joint(robot: DiscreteRobot) -> bool:
    """Whether the robot's labels are voxels of the 3D workspace (``worlds.voxels``)."""
    return robot.arm is not None and robot.arm.levels > 0


def robot(spec: str, **kwargs) -> DiscreteRobot:
    arm, actions = parse_robot_spec(spec)
    return arm_robot(arm, actions, **kwargs)


def _layout_data(layout: Layout) -> dict:
    return {"lo": layout.lo, "hi": layout.hi, "walls": layout.walls, "doors": layout.doors}


def tasks_solvable(robot: DiscreteRobot, tasks=None) -> int:
    """How many of ``tasks`` (its world's tasks by default: Table I on the rooms) the robot can
    solve: both cells reached and the goal reachable from the start."""
    solved = 0
    for task in (tasks if tasks is not None else world_tasks(robot.layout)):
        try:
            s, g = task.cells(robot.layout)
            start = robot.start_state(s)
            robot.start_state(g, what="goal")
        except InvalidCellError:
            continue
        solved += robot.shortest_path(start, g) is not None
    return solved


def make_tool(tip_site: str | None = None, tip_body: str | None = None, tip_offset=None, tool=None) -> Tool:
    """The tool point of a bring-your-own arm: ``tip_site`` or ``tip_body`` (not both; the site
    ``tip`` when neither is given), with an optional offset in its frame (metres), and the tool
    the hand holds there, ``tool`` (``"stylus[:LENGTH[:RADIUS]]"`` or a ``Stylus``), if any."""
    if tip_site is not None and tip_body is not None:
        raise ArmModelError("give the tool point as a tip site or a tip body, not both")
    offset = tuple(tip_offset) if tip_offset is not None else (0.0, 0.0, 0.0)
    held = parse_held(tool) if tool is not None else None
    if tip_body is not None:
        return Tool(site=None, body=tip_body, offset=offset, held=held)
    return Tool(site=tip_site or "tip", offset=offset, held=held)


ARM_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+-]{0,63}")
"""A bring-your-own arm's name: it is written ``NAME:ACTIONS`` on the command line, in lists
separated by commas, in file names and in tables, so it is 1 to 64 letters, digits, '_', '.',
'+' or '-' (no ':', ',', space or control character)."""
ARM_NAME_FORM = "1 to 64 letters, digits, '_', '.', '+' or '-', not starting with '.', '+' or '-'"
RESERVED_NAMES = ("custom", "gen")
"""Names a robot spec gives a meaning of its own (``custom[:ACTIONS]``, ``gen:...``)."""


def check_arm_name(name: object, what: str) -> str:
    """``name`` when a bring-your-own arm may go by it: :data:`ARM_NAME`'s form, and not the
    name of a built-in arm or grid robot (two different robots would share one name in tables,
    results and the cache); else ``ArmModelError``, one line naming the valid forms."""
    if not isinstance(name, str) or not ARM_NAME.fullmatch(name):
        shown = repr(name) if not isinstance(name, str) or len(name) <= 60 else f"{name[:40]!r}... ({len(name)} characters)"
        raise ArmModelError(f"{what} must be {ARM_NAME_FORM} (a robot is written NAME:ACTIONS), got {shown}; "
                            "give another with --arm-name (arm_name=)")
    taken = {*ARMS, *GRID_ROBOTS, *RESERVED_NAMES}
    if name in taken:
        raise ArmModelError(f"{what} {name!r} is the name of a built-in robot; give the arm another with "
                            f"--arm-name (arm_name=), not one of {', '.join(sorted(taken))}")
    return name


def file_arm_name(path: Path) -> str:
    """A bring-your-own arm's name: its MJCF ``model`` attribute, else the file's stem."""
    try:
        check_input(path, "arm MJCF", ArmModelError)  # a FIFO would hang the parser
    except ArmModelError:
        return path.stem  # the error is the reader's to give
    try:
        for _, element in ET.iterparse(str(path), events=("start",)):
            name = (element.get("model") or "").strip()
            return name or path.stem
    except (ET.ParseError, OSError):
        pass
    return path.stem


def arm_robot(arm: str | None, actions: str, *, cell_size: float | None = None,
              xml_path: str | Path | None = None, tip_site: str | None = None,
              tip_body: str | None = None, tip_offset=None, arm_name: str | None = None,
              base_pos: tuple[float, float, float] | None = None, base_yaw: float | None = None,
              joint_step: float | None = None, tip_down: bool | None = None, layout: Layout = ROOMS,
              cache: bool = True, progress: bool = False, tool=None, only_cached: bool = False) -> DiscreteRobot:
    """Compile (or load from the cache) the discrete robot of an arm and action model.

    Built-in arms are named by ``arm``. A bring-your-own arm is the MJCF file ``xml_path``
    (MuJoCo Menagerie files work as they are), its tool point ``tip_site`` or ``tip_body``
    with ``tip_offset`` (metres, in that site's or body's frame), and its name ``arm_name``
    (default: the file's ``model`` attribute). Its base pose ``base_pos``/``base_yaw`` is in
    the table frame (tabletop z = 0, cell (x, y) centred at (x * cell_size, y * cell_size));
    without ``base_pos`` it is chosen automatically (see :func:`automatic_mount`). A spatial
    bring-your-own arm keeps its tool pointing down unless ``tip_down=False``. ``tool`` puts a
    pen in the hand, ``"stylus[:LENGTH[:RADIUS]]"`` (metres; see ``ik.tool.Stylus``), for any arm
    whose tool is kept pointing down; the cell is read at the pen's end. The cell size is the
    world's (``ik.workspace.world_cell``: 1 cm on the rooms) unless given. ``only_cached``: load
    it from the cache or raise :class:`NotCached`, never compile (``arms list``'s listing)."""
    model = action_model(actions)
    stylus = parse_held(tool) if tool is not None else None
    cell_size, base_pos, base_yaw = _checked_pose(cell_size, base_pos, base_yaw, layout)
    if joint_step is not None:
        joint_step = checks.real(joint_step, "the joint step (radians)", 0.0, math.pi, lo_open=True,
                                 error=ArmModelError)
    if tip_down is not None:
        tip_down = checks.flag(tip_down, "tip_down", error=ArmModelError)
    cache = checks.flag(cache, "cache", error=ArmModelError)
    if xml_path is None:
        given = [k for k, v in (("tip_site", tip_site), ("tip_body", tip_body), ("tip_offset", tip_offset),
                                ("arm_name", arm_name)) if v is not None]
        if given:
            raise ArmModelError(f"{given[0]} goes with an arm file (xml_path), not the built-in arm {arm!r}")
    if xml_path is not None:
        path = Path(checks.path(xml_path, "the arm file (xml_path)", error=ArmModelError))
        if tip_offset is not None:
            tip_offset = checks.point(tip_offset, "the tip offset (metres)", limit=checks.MAX_METRES, error=ArmModelError)
        for what, value in (("tip_site", tip_site), ("tip_body", tip_body), ("arm_name", arm_name)):
            if value is not None:
                checks.name(value, what, error=ArmModelError)
        xml_bytes = read_input(path, "arm MJCF", ArmModelError)
        check_joint_ranges(path, repr(str(path)))  # before a mount is searched or anything compiled
        tool = make_tool(tip_site, tip_body, tip_offset, stylus)
        name = arm_name or arm or file_arm_name(path)
        check_arm_name(name, "--arm-name (arm_name)" if arm_name or arm else
                       f"the name of {path.name} (its MJCF model attribute)")
        kind, source = "custom", "given"
        generated = read_sidecar(path) if base_pos is None else None
        if generated is not None:  # mounted as it was generated, unless told otherwise
            base_pos, base_yaw = tuple(generated["mount_pos"]), float(generated["mount_yaw"])
            tip_down = generated["tip_down"] if tip_down is None else tip_down
            joint_step = joint_step or generated["joint_step"]
            source = "generated"
        if base_pos is None:
            pose = automatic_mount(path, tool, cell_size=cell_size, layout=layout, yaw=base_yaw,
                                   cache=cache, progress=progress)
            base_pos, base_yaw, source = pose.pos, pose.yaw, "automatic"
        mount = cast(tuple[float, float, float], tuple(float(v) for v in base_pos))
        yaw = float(base_yaw or 0.0)
        step = joint_step  # None: the compile picks the finest step its lattice allows
    else:
        if arm not in ARMS:
            raise UnknownArmError(f"unknown arm {arm!r}; valid arms: {', '.join(ARMS)}")
        check_actions(arm, actions)
        info = ARMS[arm]
        path, name, tool = info.xml_path, arm, Tool(site=info.tip_site, held=stylus)
        xml_bytes = path.read_bytes()
        mount, source = _builtin_mount(info, cell_size, layout), "built-in"
        if base_pos is not None:
            mount, source = cast(tuple[float, float, float], tuple(float(v) for v in base_pos)), "given"
        yaw = info.mount_yaw if base_pos is None else float(base_yaw or 0.0)
        kind, tip_down = info.kind, info.tip_down
        step = joint_step or (info.joint_step if info.kind == "planar" else None)  # spatial: ik.voxels chooses
    parts = {
        "version": 6, "arm_xml": _sha(xml_bytes), "assets": _assets_sha(path), "tool": tool.key(),
        "mount": mount, "yaw": yaw, "actions": model.name, "cells": model.cells, "tip_down": tip_down,
        "joint_step": step if model.kind == "joint" else None, "cell": cell_size,
        "wall_height": WALL_HEIGHT, "layout": _layout_data(layout),
    }
    spatial = model.kind == "joint" and kind != "planar" and not _is_planar_file(path, tool, mount, yaw, cell_size,
                                                                                 layout, kind)
    if spatial:  # over the 3D workspace: its own key (the 2D robots' keys are as they were)
        from armtransfer.ik.voxels import LEVELS, MAX_STATES, MOVED, SPATIAL_STEPS, STEP_CELLS  # MuJoCo, only when an arm is built

        parts["workspace"] = {"levels": LEVELS, "moved": MOVED, "max_states": MAX_STATES,
                              "steps": list(SPATIAL_STEPS), "step_cells": STEP_CELLS, "version": 1}
    key = _cache.cache_key(parts)
    robot_name = f"{name}:{model.name}"
    start = time.perf_counter()

    def build() -> dict[str, np.ndarray]:
        if progress:
            print(f"compiling {robot_name} ...", file=sys.stderr, flush=True)
        return _compile(_scene(path, tool, mount, yaw, cell_size, layout), model, tip_down, step, progress, spatial)

    arrays, status = _load_or_build(robot_name, key, _arrays_check(layout, _levels(spatial)), build, cache,
                                    only_cached)
    return _robot_of(arrays, layout, model, DescriptionFacts(
        name=name, kind=kind, status=status, key=key, seconds=time.perf_counter() - start, cell_size=cell_size,
        mount=mount, yaw=yaw, path=path, tool=tool, step=step, source=source))


@dataclass(frozen=True)
class DescriptionFacts:
    """What :func:`arm_robot` knows of a robot besides its compiled arrays."""

    name: str
    kind: str
    status: str
    key: str
    seconds: float
    cell_size: float
    mount: tuple[float, float, float]
    yaw: float
    path: Path
    tool: Tool
    step: float | None
    source: str


def _load_or_build(robot_name: str, key: str, check, build, cache: bool,
                   only_cached: bool) -> tuple[dict[str, np.ndarray], str]:
    """(arrays, cache status): from the arm cache, else built and saved (under the cache's build
    lock, so each arm compiles once however many processes ask); ``only_cached`` never builds."""
    if only_cached:
        loaded = _cache.load(robot_name, key, check)[0] if cache else None
        if loaded is None:
            raise NotCached(f"robot {robot_name} is not in the arm cache")
        return loaded, "hit"
    if not cache:
        return build(), "off"
    _check_cache_dir()
    loaded, status = _cache.load(robot_name, key, check)
    if loaded is not None:
        return loaded, status
    with _cache.building(_cache.entry_path(robot_name, key)):
        meanwhile, again = _cache.load(robot_name, key, check)  # built by another process while we waited
        if meanwhile is None:
            arrays = build()
            _cache.save(robot_name, key, arrays)
            return arrays, status
        return meanwhile, again


def _robot_of(arrays: dict[str, np.ndarray], layout: Layout, model, facts: DescriptionFacts) -> DiscreteRobot:
    """The discrete robot of an arm's compiled arrays, with its description."""
    dof = int(arrays["qpos"].shape[1])
    step = facts.step
    if "joint_step" in arrays:
        step = float(arrays["joint_step"])
    label = arrays["label"]
    levels = int(arrays["levels"]) if "levels" in arrays else 0
    if levels:
        from armtransfer.ik.voxels import workspace_voxels  # MuJoCo, only when an arm is built

        reach = float(len(np.unique(label)) / workspace_voxels(layout, facts.cell_size).free.sum())
    else:
        reach = float(len(np.unique(label)) / layout.free.sum())
    chain, held = _chain_of(arrays)
    clearance = float(arrays.get("clearance", 0.0))
    clearance_geom = str(arrays.get("clearance_geom", ""))
    description = ArmDescription(
        name=facts.name, actions=model.name, dof=dof, kind=facts.kind, qpos=arrays["qpos"], tip=arrays["tip"],
        reach=reach, cache=facts.status, key=facts.key, seconds=facts.seconds, cell_size=facts.cell_size,
        mount=facts.mount, yaw=facts.yaw, xml_path=str(facts.path), tool=facts.tool,
        joint_step=step if model.kind == "joint" else None, layout=layout,
        lattice=arrays.get("lattice"), mount_source=facts.source, chain=chain, held=held,
        clearance=clearance, clearance_geom=clearance_geom, levels=levels,
        moved=tuple(int(j) for j in arrays["moved"]) if "moved" in arrays else (),
    )
    names = (tuple(f"q{j + 1}{sign}" for j in description.moved for sign in ("+", "-")) if levels
             else model.action_names(dof))
    return DiscreteRobot(
        name=f"{facts.name}:{model.name}",
        next_state=arrays["next_state"],
        wind_state=arrays["wind_state"],
        label=label,
        action_names=names,
        cell_step=model.cells,
        canonical=arrays["canonical"],
        layout=layout,
        arm=description,
    )


def _is_planar_file(path, tool: Tool, mount, yaw: float, cell: float, layout: Layout, kind: str) -> bool:
    """Whether the arm moves its tool in a plane (all joint axes vertical): a built-in arm's
    kind says; a bring-your-own arm's scene is built to see."""
    if kind != "custom":
        return kind == "planar"
    return bool(_scene(path, tool, mount, yaw, cell, layout).planar)


def _levels(spatial: bool) -> int:
    from armtransfer.ik.voxels import LEVELS  # MuJoCo, only when an arm is built

    return LEVELS if spatial else 0


def _arrays_check(layout: Layout, levels: int = 0):
    """Whether a cache entry's arrays make a robot on ``layout`` (its voxels at ``levels``
    levels when not 0): every array there with its shape, states and cells in range,
    positions finite."""
    n_labels = layout.n_cells * max(levels, 1)
    def check(arrays: dict[str, np.ndarray]) -> bool:
        nxt, wind, label, qpos, tip = (arrays[k] for k in ("next_state", "wind_state", "label", "qpos", "tip"))
        canonical = arrays["canonical"]
        n = len(label)
        ints = all(np.issubdtype(a.dtype, np.integer) for a in (nxt, wind, label, canonical))
        return (ints and n > 0 and nxt.ndim == 2 and nxt.shape[0] == n and nxt.shape[1] > 0
                and wind.shape == (n,) and label.shape == (n,) and qpos.ndim == 2 and qpos.shape[0] == n
                and tip.shape == (n, 3) and canonical.shape == (n_labels,)
                and (not levels or ("moved" in arrays and int(arrays.get("levels", 0)) == levels
                                    and arrays["moved"].shape == (nxt.shape[1] // 2,)))
                and bool(np.all((nxt >= 0) & (nxt < n))) and bool(np.all((wind >= 0) & (wind < n)))
                and bool(np.all((label >= 0) & (label < n_labels)))
                and bool(np.all((canonical >= -1) & (canonical < n)))
                and bool(np.all(np.isfinite(qpos))) and bool(np.all(np.isfinite(tip))))

    return check


def _checked_pose(cell_size, base_pos, base_yaw, layout: Layout) -> tuple:
    """The cell size (the world's when None), base position and yaw checked: finite, in metres
    up to ``checks.MAX_METRES``."""
    if cell_size is None:
        cell_size = world_cell(layout)
    cell_size = checks.real(cell_size, "the cell size (metres)", 0.0, checks.MAX_METRES, lo_open=True,
                            error=ArmModelError)
    if base_yaw is not None:
        base_yaw = checks.real(base_yaw, "the base yaw (radians)", error=ArmModelError)
    if base_pos is not None:
        base_pos = checks.point(base_pos, "the base position (metres)", limit=checks.MAX_METRES, error=ArmModelError)
    return cell_size, base_pos, base_yaw


def _builtin_mount(info, cell_size: float, layout: Layout) -> tuple[float, float, float]:
    mount = info.mount_pos
    if info.kind == "planar" and layout.width == ROOMS.width:  # hang over the same cell whatever the cell size
        mount = (mount[0] * cell_size / DEFAULT_CELL, mount[1] * cell_size / DEFAULT_CELL, mount[2])
    elif info.kind == "planar":  # another world: over the same point of a table scaled as the rooms' is
        scale = cell_size / world_cell(layout)
        mount = (mount[0] * scale, mount[1] * scale, mount[2])
    return mount


def _chain_of(arrays: dict) -> tuple[tuple[str, ...], tuple[tuple[str, float], ...]]:
    """The chain and held joints, stored with the arrays (as text) so a cache hit has them."""
    chain = tuple(str(v) for v in arrays.get("chain", ()))
    held = tuple((h.split("=")[0], float(h.split("=")[1])) for h in (str(v) for v in arrays.get("held", ())))
    return chain, held


def mount_search(path: Path, tool: Tool, *, cell_size: float | None = None, layout: Layout = ROOMS,
                 yaw: float | None = None) -> list[tuple[int, float, "object"]]:
    """Every base pose the automatic mount tries, best first, as (Table I cells reached,
    estimated share of free cells, ``ik.mount.Pose``).

    First the poses of ``ik.mount.candidates`` (beside the table; over it for an arm with
    vertical joint axes). A spatial arm that none of them lets cover the table (an estimate
    of at least ``COVERS`` with every Table I cell) also tries ``ik.mount.on_table``, each
    pose standing on the tabletop and on the lowest pedestal of ``ik.mount.LIFTS`` (on the
    table its turning links pass a few centimetres from the 2 cm walls; the pedestal lifts
    them clear), and the best five poses standing on the tabletop on each pedestal. Each pose
    is estimated with light seeds (``ik.mount.estimate_reach``); when no pose reaches a
    cell, the first ``RETRIES`` are estimated again with the full seeds, so that a search
    that cannot succeed ends soon.
    """
    from armtransfer.ik import mount as _mount  # MuJoCo, only when an arm is built
    cell_size = world_cell(layout) if cell_size is None else cell_size
    origin = _scene(path, tool, (0.0, 0.0, 0.0), 0.0, cell_size, layout)
    must = sorted({c for t in world_tasks(layout) for c in t.cells(layout)})
    scored: list = []

    def score(batch: list) -> None:
        for pose in batch:
            i = len(scored)
            share, hit = _mount.estimate_reach(path, tool, pose, layout, cell_size, must=must,
                                               rng=np.random.default_rng(i), light=True)
            scored.append((hit, share, -i, pose))
        scored.sort(key=lambda t: (t[0], t[1], t[2]), reverse=True)

    score(_mount.candidates(origin, layout.width * cell_size / 2, yaw))
    if not origin.planar and not (scored and scored[0][0] == len(must) and scored[0][1] >= COVERS):
        standing = {pose for *_, pose in scored}
        inside = _mount.on_table(origin, yaw)  # too small to cover the table from beside it
        standing |= set(inside)
        score(inside + [pose.lifted(_mount.LIFTS[0]) for pose in inside])
        tried = {pose for *_, pose in scored}
        best = [pose for *_, pose in scored if pose in standing][:5]
        score([lifted for pose in best for h in _mount.LIFTS  # on a pedestal
               if (lifted := pose.lifted(h)) not in tried])
    if scored and scored[0][1] == 0.0:  # nothing found with the light seeds: look harder at a few
        for k, (_, _, i, pose) in enumerate(scored[:RETRIES]):
            share, hit = _mount.estimate_reach(path, tool, pose, layout, cell_size, must=must,
                                               rng=np.random.default_rng(-i))
            scored[k] = (hit, share, i, pose)
        scored.sort(key=lambda t: (t[0], t[1], t[2]), reverse=True)
    return [(hit, share, pose) for hit, share, _, pose in scored]


RETRIES = 8
"""Poses a mount search estimates again with the full seeds (``ik.mount.SEEDS``,
``ik.mount.RESTARTS``) when the light seeds found no cell from any pose."""


COMPILES = 2
"""Poses ``compile_order`` takes from each of its two rankings; the automatic mount compiles
the first of them, and the next only when a compile fails, this many in all."""


def compile_order(scored: list, n: int = COMPILES) -> list:
    """The poses of ``mount_search`` (best first) that ``automatic_mount`` compiles in full, in
    order: the best ``n`` as ranked, then up to ``n`` more, best estimate first, whose
    estimate beats the lowest of those (none when the ranking is by the estimate alone)."""
    first = scored[:n]
    if not first:
        return []
    floor = min(t[1] for t in first)
    by_share = sorted(scored, key=lambda t: t[1], reverse=True)  # stable: ties keep their rank
    return first + [t for t in by_share if t not in first and t[1] > floor][:n]


def automatic_mount(path: Path, tool: Tool, *, cell_size: float | None = None, layout: Layout = ROOMS,
                    yaw: float | None = None, cache: bool = True, progress: bool = False):
    """A base pose for an arm that came without one (``ik.mount.Pose``).

    The poses of :func:`mount_search` are ranked by their quick estimate (Table I cells
    reached, then the share of the lattice). Only the winner is compiled in full (the 1-cell
    cartesian model: reach is the tool's workspace, whatever the action model); the next of
    :func:`compile_order` only when a compile fails, ``COMPILES`` in all. When no pose
    reaches a cell, or none compiles, the error names the cause measured at the best pose
    (``ik.diagnose``). The choice is cached under the arm file's content (meshes included),
    tool, cell size and layout, so it is made once.
    """
    from armtransfer.ik import mount as _mount  # MuJoCo, only when an arm is built

    cell_size = world_cell(layout) if cell_size is None else cell_size
    parts = {"version": 11, "what": "mount", "compiles": COMPILES, "covers": COVERS,
             "arm_xml": _sha(path.read_bytes()), "assets": _assets_sha(path), "tool": tool.key(),
             "cell": cell_size, "yaw": yaw, "layout": _layout_data(layout), "stride": _mount.STRIDE,
             "seeds": [_mount.SEEDS, _mount.RESTARTS, RETRIES], "gaps": _mount.GAPS,
             "grid": _mount.PLANAR_GRID, "lifts": _mount.LIFTS}
    if layout != ROOMS:  # the choice ranks poses by the world's task cells (the rooms' key is as it was)
        parts["tasks"] = [[name, list(start), list(goal)] for name, start, goal in layout.tasks]
    key = _cache.cache_key(parts)
    entry = _cache.cache_dir() / f"mount-{key[:16]}.json"
    if cache:
        _check_cache_dir()
        cached = _cached_pose(entry, key)
        if cached is not None:  # checked by what it claims: the compiled pose solves and reaches as stored
            pose, rank = _mount.Pose(*cached[0]), cached[1]
            try:
                robot = _mount_robot(path, tool, pose, cell_size, layout, cache)
                assert robot.arm is not None  # an arm file compiles to an arm robot
                if (tasks_solvable(robot), round(robot.arm.reach, 9)) == rank:
                    return pose
            except (ArmModelError, UnreachableTableError):
                pass

    def unreachable(best) -> UnreachableTableError:
        """The error, with the cause measured at the best pose tried (``ik.diagnose``)."""
        from armtransfer.ik.diagnose import why_unreachable  # MuJoCo, only when an arm is built

        cause, planar = "", False
        if best is not None:
            scene = _scene(path, tool, best.pos, best.yaw, cell_size, layout)
            cause, planar = why_unreachable(scene, not scene.planar), scene.planar
            cause = f" (at the best, {best.describe()}: {cause})" if cause else ""
        hint = "" if planar else tool.axis_hint()
        return UnreachableTableError(
            f"the arm's tool ({tool.describe()}) cannot reach the table from any base pose tried{cause}; give "
            f"--base-pos X,Y,Z and --base-yaw" + (f"; {hint}" if hint else ""))
    if progress:
        print(f"choosing a mount for {path.name}: estimating the reach of base poses (once; the choice is "
              "cached) ...", file=sys.stderr, flush=True)
    scored = mount_search(path, tool, cell_size=cell_size, layout=layout, yaw=yaw)
    if not scored or scored[0][1] == 0.0:
        raise unreachable(scored[0][2] if scored else None)
    best = None
    for hit, share, pose in compile_order(scored)[:COMPILES]:
        if progress:
            print(f"  mount candidate: {pose.describe()} (estimated reach {share:.0%})", file=sys.stderr, flush=True)
        try:
            robot = _mount_robot(path, tool, pose, cell_size, layout, cache)
        except ArmModelError:
            continue
        assert robot.arm is not None  # an arm file compiles to an arm robot
        best = ((tasks_solvable(robot), robot.arm.reach), pose)
        break
    if best is None:
        raise unreachable(scored[0][2])
    pose = best[1]
    if cache:
        _cache.clear(entry)
        write_json_atomic(entry, {"key": key, "pos": list(pose.pos), "yaw": pose.yaw,
                                  "solvable": best[0][0], "reach": round(best[0][1], 9)})
    return pose


def _mount_robot(path: Path, tool: Tool, pose, cell_size: float, layout: Layout, cache: bool) -> DiscreteRobot:
    """The 1-cell cartesian robot of the arm file at ``pose``: how the automatic mount ranks it."""
    return arm_robot(None, "cartesian", cell_size=cell_size, xml_path=path, tip_site=tool.site, tip_body=tool.body,
                     tip_offset=tool.offset, base_pos=pose.pos, base_yaw=pose.yaw, layout=layout, cache=cache,
                     tool=tool.held)


def _cached_pose(entry: Path, key: str) -> tuple[tuple[tuple[float, float, float], float], tuple[int, float]] | None:
    """((position, yaw), (tasks solvable, reach)) of the mount choice cached in ``entry`` for
    ``key``, or None when there is none or it is not one (not a regular file, not JSON,
    another key, numbers of the wrong kind or out of range): it is then chosen again."""
    raw = _cache.read_regular(entry)
    try:
        data = parse_json_bytes(raw) if raw is not None else None
        if not isinstance(data, dict) or data.get("key") != key:
            return None
        pos = checks.point(data.get("pos"), "pos", limit=checks.MAX_METRES)
        yaw = checks.real(data.get("yaw"), "yaw")
        rank = checks.whole(data.get("solvable"), "solvable", 0, checks.MAX_COUNT), checks.real(data.get("reach"), "reach", 0, 1)
        return ((pos[0], pos[1], pos[2]), yaw), rank
    except (ValueError, ArmTransferError):
        return None


def _check_cache_dir() -> None:
    """The arm cache must take files before any compiling starts (one line otherwise)."""
    root = _cache.cache_dir()
    try:
        if root.exists() and not root.is_dir():
            raise OutputError(f"{str(root)!r} is not a directory")
        check_writable(root / "probe.npz")
    except OutputError as err:
        raise OutputError(f"the arm cache cannot be used ({err}); set ARMTRANSFER_CACHE to a writable "
                          "directory, or pass --no-cache") from None


def read_sidecar(xml_path: str | os.PathLike) -> dict | None:
    """The generator's JSON beside an arm file, checked, or None when there is none (a file
    of the generator's format that is malformed is a one-line error naming it)."""
    path = Path(xml_path).with_suffix(".json")
    try:
        raw: bytes | None = read_input(path, "generated arm's file", ArmModelError)
    except ArmModelError:  # absent, or no regular file of a readable size: not the generator's
        raw = None
    try:
        data = parse_json_bytes(raw) if raw is not None else None
    except ValueError:
        return None
    if not (isinstance(data, dict) and data.get("format") == SIDECAR_FORMAT):
        return None  # not the generator's: the arm is mounted as any other
    where = f"the generated arm's file {str(path)!r}"
    try:
        data["mount_pos"] = list(checks.point(data.get("mount_pos"), "mount_pos", limit=checks.MAX_METRES,
                                              error=ArmModelError))
        data["mount_yaw"] = checks.real(data.get("mount_yaw"), "mount_yaw", error=ArmModelError)
        data["tip_down"] = checks.flag(data.get("tip_down"), "tip_down", error=ArmModelError)
        if data.get("joint_step") is not None:
            data["joint_step"] = checks.real(data["joint_step"], "joint_step", 0.0, math.pi, lo_open=True,
                                             error=ArmModelError)
        else:
            data["joint_step"] = None
    except ArmModelError as err:
        raise ArmModelError(f"{where}: {err}; write it again with 'armtransfer arms generate' or delete it") from None
    return data


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _assets_sha(path: Path) -> str:
    """A hash of every file MuJoCo reads for the arm file but the file itself (its includes,
    meshes, textures: ``ik.scene.model_files``), names and contents; a missing one counts as
    missing. Only those files are read, never a whole folder."""
    from armtransfer.ik.scene import model_files  # MuJoCo, only when an arm is built

    h = hashlib.sha256()
    for f in model_files(path)[1:]:
        h.update(str(f.relative_to(path.parent) if f.is_relative_to(path.parent) else f).encode() + b"\0")
        data = _cache.read_regular(f)
        h.update(b"missing" if data is None else hashlib.sha256(data).digest())
    return h.hexdigest()


def arm_scene(arm: str | None = None, *, cell_size: float | None = None, xml_path=None,
              tip_site: str | None = None, tip_body: str | None = None, tip_offset=None,
              base_pos=None, base_yaw: float | None = None, layout: Layout = ROOMS, tool=None):
    """The MuJoCo scene (``ik.scene.ArmScene``) a robot of this arm is compiled in (a
    bring-your-own arm without ``base_pos`` at the origin)."""
    cell_size, base_pos, base_yaw = _checked_pose(cell_size, base_pos, base_yaw, layout)
    if xml_path is not None:
        return _scene(Path(xml_path), make_tool(tip_site, tip_body, tip_offset, tool), base_pos or (0.0, 0.0, 0.0),
                      base_yaw or 0.0, cell_size, layout)
    if arm not in ARMS:
        raise UnknownArmError(f"unknown arm {arm!r}; valid arms: {', '.join(ARMS)}")
    info = ARMS[arm]
    return _scene(info.xml_path, Tool(site=info.tip_site, held=parse_held(tool) if tool is not None else None),
                  _builtin_mount(info, cell_size, layout), info.mount_yaw,
                  cell_size, layout)


def walls_cause(robot: DiscreteRobot) -> str:
    """Why an arm robot reaches less than ``ik.walls.REACH_OK`` of the free cells, when its
    geometry meets the walls: the geometry, its width against a door's, and the remedy (see
    ``ik.walls``); "" when it reaches enough, is no arm, or the walls are not the cause."""
    from armtransfer.ik import walls as _walls  # MuJoCo, only when an arm is built

    arm = robot.arm
    if arm is None or arm.reach >= _walls.REACH_OK:
        return ""
    scene = _scene(arm.xml_path, arm.tool, arm.mount, arm.yaw, arm.cell_size, arm.layout)
    reached = np.zeros(arm.layout.n_cells, dtype=bool)
    reached[np.unique(robot.label % arm.layout.n_cells)] = True  # a voxel label: the cell under it
    return _walls.wall_cause(scene, not scene.planar, reached)


def _scene(path, tool: Tool, mount, yaw, cell, layout):
    from armtransfer.ik.scene import build_scene  # MuJoCo, only when an arm is built

    return build_scene(Path(path), tool, mount, yaw, cell, layout=layout)


def _compile(scene, model, tip_down, step, progress, spatial: bool = False) -> dict:
    from armtransfer.ik.compile import compile_cartesian, compile_joint  # MuJoCo, only when an arm is built

    if spatial:
        from armtransfer.ik.voxels import compile_spatial_joint  # MuJoCo, only when an arm is built

        arrays = compile_spatial_joint(scene, step, progress)
    elif model.kind == "joint":
        arrays = compile_joint(scene, step, progress)
    else:
        arrays = compile_cartesian(scene, (not scene.planar) if tip_down is None else tip_down, model.cells,
                                   progress)
    arrays["chain"] = np.array(list(scene.chain), dtype=str).reshape(-1)
    arrays["held"] = np.array([f"{n}={v!r}" for n, v in scene.held], dtype=str).reshape(-1)
    arrays["clearance"] = np.array(scene.clearance)
    arrays["clearance_geom"] = np.array(scene.clearance_geom)
    return arrays


__all__ = ["is_spatial_joint", "spatial_joint_specs", "walls_cause", "arm_robot", "arm_scene", "automatic_mount", "make_tool", "compile_order", "mount_search", "parse_robot_spec", "robot", "robot_specs",
           "tasks_solvable"]
