"""``armtransfer arms``: transfer between arms (see ``armtransfer.commands.arm_transfer``), and
``armtransfer arms list``: the arm robots, their DOF, action models and reachability."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from armtransfer.commands import arm_transfer, common
from armtransfer.errors import ArmModelError
from armtransfer.ik.actions import ACTION_MODELS
from armtransfer.io import check_output_dir
from armtransfer.models import ARMS
from armtransfer.models.generate import FAMILIES, check_family
from armtransfer.tasks.arms import (NotCached, arm_robot, arm_scene, is_spatial_joint, robot_specs, spatial_joint_specs,
                                    tasks_solvable, walls_cause)
from armtransfer.tasks.generated import generate_arm
from armtransfer.worlds.resolve import is_default

HELP = ("Transfer a trajectory from one MuJoCo arm to another; write results, table, figures and a rollout video "
        "('arms list' lists the arms, 'arms generate' draws new ones).")
EXAMPLE = "armtransfer arms --fast --out runs/demo"


ARM_FILE_OPTIONS = {"arm_xml", "tip_site", "tip_body", "tip_offset", "tool", "arm_name", "base_pos", "base_yaw", "cell_size"}
LIST_ONLY = {"arm", "actions", "compile"}
LIST_OPTIONS = LIST_ONLY | ARM_FILE_OPTIONS | {"no_cache", "world", "compile"}
GENERATE_ONLY = {"family", "dof"}
GENERATE_OPTIONS = GENERATE_ONLY | {"seed", "out"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("action", nargs="?", choices=["list", "generate"],
                        help="'list': every built-in arm robot at once, with the figures of those in the arm cache; "
                             "the robots --arm, --actions or --arm-xml name (every one with --compile) are compiled "
                             "(or loaded) and reported, with progress; 'generate': draw "
                             "an arm from --family with --dof joints and --seed into --out; without "
                             "either, run a transfer")
    parser.add_argument("--family", default=None, help="arms generate: planar, spatial6 or spatial7")
    parser.add_argument("--dof", type=common.positive_int, default=None,
                        help="arms generate: joints (planar 2-7, spatial6 6, spatial7 7)")
    common.add_arm_file_arguments(parser)
    parser.add_argument("--arm", default=None, metavar="NAMES",
                        help="only these built-in arms, comma-separated (e.g. planar2,ur5e_like)")
    parser.add_argument("--actions", default=None,
                        help="only these action models, comma-separated (e.g. joint,cartesian)")
    parser.add_argument("--cell-size", type=float, default=None,
                        help="cell size in metres (default 0.01 on rooms; on a world of another size, the size "
                             "that keeps the table 0.51 m wide)")
    parser.add_argument("--no-cache", action="store_true", help="compile without the cache")
    parser.add_argument("--compile", action="store_true",
                        help="arms list: compile every built-in robot not in the cache yet (minutes on a new machine)")
    arm_transfer.add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    if args.action == "generate":
        common.refuse_other_options(args, GENERATE_OPTIONS, "'arms generate'")
        return generate(args)
    if args.action != "list":
        common.refuse_other_options(args, {a.dest for a in common.options_of(args)} - LIST_ONLY - GENERATE_ONLY,
                                    "an arm transfer ('arms' without list or generate)")
        return arm_transfer.run(args)
    common.refuse_other_options(args, LIST_OPTIONS, "'arms list'")
    common.check_arm_flags(args)
    return _list(args)


def _jobs(args: argparse.Namespace, layout) -> list[dict[str, Any]]:
    """The robots ``arms list`` reports: the built-in ones --arm and --actions pick, in the
    registry's order, then the arm file's (checked first, so a bad file fails fast)."""
    wanted = None
    if args.actions:
        wanted = [a.strip() for a in args.actions.split(",") if a.strip()]
        for a in wanted:
            if a not in ACTION_MODELS:
                raise ArmModelError(
                    f"unknown action model {a!r}; valid action models: {', '.join(ACTION_MODELS)}")
    arms = None
    if args.arm:
        arms = [a.strip() for a in args.arm.split(",") if a.strip()]
        for a in arms:
            if a not in ARMS:
                raise ArmModelError(f"unknown arm {a!r}; valid arms: {', '.join(ARMS)}")
    jobs: list[dict[str, Any]] = []
    order = list(ARMS)  # each arm's rows together: its robots on the plane, then its 3D joint robot
    for spec in sorted(robot_specs() + spatial_joint_specs(), key=lambda s: order.index(s.split(":")[0])):
        arm, actions = spec.split(":")
        if (wanted is None or actions in wanted) and (arms is None or arm in arms):
            jobs.append(dict(arm=arm, actions=actions))
    if args.arm_xml:
        custom = [a for a in (wanted or ["cartesian"])]
        # Validate the file before the long built-in listing, so bad input fails fast.
        options = common.arm_file_options(args)
        arm_scene(xml_path=args.arm_xml, cell_size=args.cell_size, layout=layout,
                  **{k: v for k, v in options.items() if k != "arm_name"})
        for a in custom:
            jobs.append(dict(arm=None, actions=a, xml_path=args.arm_xml, **options))
    return jobs


def _list(args: argparse.Namespace) -> int:
    """``arms list``: a row per robot, compiled where asked, from the cache otherwise."""
    layout = common.world_of(args)
    jobs = _jobs(args, layout)

    # compiled: the robots asked for by name (--arm, --actions), the arm file's, every one with --compile;
    # the others are listed at once, with their figures when the cache has them
    asked = args.arm is not None or args.actions is not None or args.compile
    to_compile = [i for i, job in enumerate(jobs) if asked or job.get("xml_path")]
    done = 0

    def build(i: int, job: dict):
        nonlocal done
        job = dict(job)
        if i not in to_compile:
            try:
                return arm_robot(job.pop("arm"), job.pop("actions"), cell_size=args.cell_size, layout=layout,
                                 only_cached=True, cache=not args.no_cache, **job)
            except NotCached:
                return None
        done += 1
        spec = f"{job['arm']}:{job['actions']}" if job.get("arm") else f"{job.get('xml_path')}:{job['actions']}"
        if common.interactive():
            print(f"[{done}/{len(to_compile)}] {spec}", file=sys.stderr, flush=True)
        return arm_robot(job.pop("arm"), job.pop("actions"), cell_size=args.cell_size, cache=not args.no_cache,
                         progress=common.interactive(), layout=layout, **job)

    # the bring-your-own arm first: a file that cannot be compiled fails before the listing
    built = {i: build(i, job) for i, job in enumerate(jobs) if job.get("xml_path")}
    tasks = "tableI" if is_default(layout) else "tasks"
    header = f"{'robot':<24} {'dof':>3} {'actions':>7} {'states':>7} {'reach':>6} {tasks:>6} {'cache':>6}"
    print(header, flush=True)
    robots, missing = [], []
    for i, job in enumerate(jobs):
        r = built[i] if i in built else build(i, job)
        if r is None:
            missing.append(f"{job['arm']}:{job['actions']}")
            print(f"{missing[-1]:<24} {ARMS[job['arm']].dof:>3} {'-':>7} {'-':>7} {'-':>6} {'-':>6} {'none':>6}",
                  flush=True)
            continue
        robots.append(r)
        solved = tasks_solvable(r)
        print(f"{r.name:<24} {r.arm.dof:>3} {r.n_actions:>7} {r.n_states:>7} "
              f"{r.arm.reach:>6.1%} {solved:>4}/{len(layout.tasks)} {r.arm.cache:>6}", flush=True)
    if missing:
        print(f"\n{len(missing)} robots are not compiled yet ('-'); a run that uses one compiles it once, or "
              "`armtransfer arms list --arm ARM[,ARM...]` (or --compile, every one: minutes) compiles and reports them")
    spatial = [r for r in robots if is_spatial_joint(r)]
    custom = [r for r in robots if r.arm.kind == "custom"]
    if spatial or custom:
        print()
    for r in spatial:
        moved = ", ".join(str(j + 1) for j in r.arm.moved)
        print(f"{r.name}: joint space over the 3D workspace ({r.arm.levels} levels); moves joints {moved} "
              f"and holds the others; its reach is of the free voxels")
    for r in custom:
        print(f"{r.name}: {mount_line(r.arm)}")
        if cause := walls_cause(r):
            print(f"{r.name}: reaches {r.arm.reach:.1%} of the free cells: {cause}")
    return 0


def mount_line(arm) -> str:
    """One line on a bring-your-own arm: its tool, chain, held joints and mount."""
    held = ", ".join(f"{n} at {v:g}" for n, v in arm.held)
    x, y, z = arm.mount
    return (f"tool {arm.tool.describe()}; {arm.dof} joints {'-'.join(arm.chain)}"
            + (f" (held: {held})" if held else "")
            + f"; {arm.mount_source} mount --base-pos={x:.4g},{y:.4g},{z:.4g} --base-yaw={arm.yaw:.4g}"
            + (f"; {note}" if (note := arm.clearance_note()) else ""))


def generate(args: argparse.Namespace) -> int:
    """``arms generate --family F --dof N --seed S --out DIR``: one usable arm, or why not."""
    if args.family is None or args.out is None:
        raise ArmModelError(f"arms generate needs --family ({', '.join(FAMILIES)}), --dof and --out DIR")
    known = FAMILIES.get(args.family)  # None: an unknown family, which check_family names before any dof
    dof = args.dof if args.dof is not None or known is None else known[0]
    check_family(args.family, dof)
    check_output_dir(args.out)  # absent or empty, as --out's help says
    with common.phase("drawing and compiling"):
        arm = generate_arm(args.family, dof, args.seed, args.out, progress=common.interactive())
    for line in arm.rejected:
        print(f"rejected {line}")
    print(f"wrote {arm.xml_path} (draw {arm.draws}; reaches {100 * arm.reach:.1f}% of the free cells; "
          f"every Table I task solvable); use it as the robot {arm.xml_path}:cartesian")
    return 0
