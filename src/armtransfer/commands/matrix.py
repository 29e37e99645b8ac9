"""armtransfer matrix: every ordered source -> target pair of a set of robots, one command.

The runs go through the sweep store (resumable after a crash, local or Ray); when they are
done, ``matrix.md``, ``matrix.json`` and ``matrix.png`` (one heatmap per method) are written
into the store, as ``armtransfer summarize DIR`` also does for a matrix store.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from armtransfer.checks import integer_text
from armtransfer.commands import common
from armtransfer.commands.sweep import add_executor_arguments, check_executor_options, run_sweep
from armtransfer.errors import InvalidParameterError, InvalidTaskError
from armtransfer.experiments import matrix, sweep as sweeps
from armtransfer.experiments.learner_trial import refuse_methods
from armtransfer.experiments.store import ResultStore
from armtransfer.io import write_bytes_atomic, write_json_atomic, write_text_atomic
from armtransfer.learning import methods
from armtransfer.learning.learners import SARSA, get, parse
from armtransfer.models import ARMS
from armtransfer.tasks.grid_robots import GRID_ROBOTS
from armtransfer.tasks.specs import CUSTOM, xml_arm_name
from armtransfer.worlds.resolve import is_default

HELP = "Measure which robots help which: every ordered source -> target pair of a set of robots, as a heatmap."
EXAMPLE = "armtransfer matrix --robots coarse,fine --tasks 1 --trials 5 --out runs/matrix"


def _task_list(text: str) -> list[str]:
    """'1-4', '1,3', '2' or task names -> the parts, each a task or a range of numbered tasks
    (checked against the world in :func:`world_tasks`)."""
    parts = [part.strip() for part in text.split(",")]
    if not any(parts):
        raise argparse.ArgumentTypeError(f"no tasks in {text!r}")
    if not all(parts):
        raise argparse.ArgumentTypeError(f"tasks are names, numbers or ranges like 1-4 or 1,3, got {text!r}")
    return parts


def world_tasks(parts: list[str] | None, layout) -> list:
    """The tasks of ``--tasks`` in the world (every task of it when None): numbers on the rooms
    (its Table I tasks), names elsewhere; a one-line error naming an unknown one."""
    names = [t[0] for t in layout.tasks]
    rooms = is_default(layout)
    if parts is None:
        return [int(n) for n in names] if rooms else names
    text = ",".join(parts)

    def known(name: str) -> str:
        if name not in names:
            where = "" if rooms else f" of world {layout.name}"
            raise InvalidTaskError(f"unknown task {name[:40]} in {text[:80]!r}{where}; valid tasks: {', '.join(names)}")
        return name

    out: list[str] = []
    for part in parts:
        lo, dash, hi = part.partition("-")
        if dash and integer_text(lo, signed=False) is not None and integer_text(hi, signed=False) is not None:
            first, last = known(str(int(lo))), known(str(int(hi)))  # both ends first: '1-9999999999' lists nothing
            out.extend(known(str(t)) for t in range(int(first), int(last) + 1))
        elif integer_text(part, signed=False) is not None:
            out.append(known(str(int(part))))
        elif rooms:
            raise InvalidTaskError(f"tasks are numbers or ranges like 1-4 or 1,3, got {text[:80]!r}")
        else:
            out.append(known(part))
    return [int(t) for t in out] if rooms else out


def _robot_list(text: str) -> list[str]:
    robots = [r.strip() for r in text.split(",") if r.strip()]
    if not robots:
        raise argparse.ArgumentTypeError(f"no robots in {text!r}")
    return robots


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--robots", type=_robot_list, required=True, metavar="SPEC,SPEC,...",
                   help="robot specs: coarse, fine, ARM:ACTIONS (see `armtransfer arms list`), and the arm "
                        "of --arm-xml as custom:ACTIONS or NAME:ACTIONS")
    common.add_world_argument(p)
    p.add_argument("--tasks", type=_task_list, default=None, metavar="1-4",
                   help="tasks of the world: Table I tasks on rooms, names or ranges of numbers (default: all, "
                        "1-4 on rooms)")
    p.add_argument("--methods", nargs="+", default=["none", "pseudo", "dense"], metavar="METHOD",
                   help="methods; 'none' is always run as the baseline (default: none pseudo dense)")
    p.add_argument("--trials", type=common.positive_int, default=10, help="trials per run (default 10)")
    p.add_argument("--seeds", type=common.non_negative_int, nargs="+", default=[0], help="seeds (default 0)")
    p.add_argument("--trajectory", choices=["learned", "optimal"], default="learned",
                   help="each source's learned path (default) or its shortest path")
    p.add_argument("--out", required=True, help="result store directory (re-running resumes)")
    common.add_preset_argument(p)
    common.add_learner_argument(p, several=True)
    p.add_argument("--max-total-steps", type=common.positive_int, default=None,
                   help="steps per trial at most (default: the preset's, 20,000,000); an outside learner's budget")
    common.add_arm_file_arguments(p)
    add_executor_arguments(p)


def run(args: argparse.Namespace) -> int:
    check_executor_options(args)
    for m in args.methods:
        methods.get(m)
    common.refuse_unused_method_options(args, "--methods")
    learners = parse(args.learner)  # a typo lists the valid names
    for name in learners:
        if name != SARSA:
            refuse_methods(get(name), methods.with_baselines(["none", *args.methods]))
    layout = common.world_of(args)
    tasks = world_tasks(args.tasks, layout)
    robots, arms = arm_file_robots(args)
    sweep = matrix.matrix_sweep(robots, tasks, args.methods, args.trials, args.seeds, args.trajectory,
                                arms=arms, world=args.world, preset=args.preset, learners=learners,
                                max_total_steps=args.max_total_steps)
    code = run_sweep(sweep, args)
    text = write_summary(ResultStore.open_existing(args.out), Path(args.out))
    print(text)
    return code


def arm_file_robots(args: argparse.Namespace) -> tuple[list[str], dict]:
    """The robots with the arm of --arm-xml (``custom`` or its name) named by its name, and
    that arm as a sweep's ``[arms.NAME]`` table: the store's runs name the arm as ``arms list``
    prints it, and carry its file and options."""
    common.check_arm_flags(args)
    if not args.arm_xml:
        return list(args.robots), {}
    options = common.arm_file_options(args)
    name = xml_arm_name(args.arm_xml, options.pop("arm_name"))
    if name in ARMS or name in GRID_ROBOTS or ":" in name or name == CUSTOM:
        raise InvalidParameterError(f"the arm of --arm-xml is named {name!r}, as a built-in robot is (or not a "
                                    "name); give it another with --arm-name")
    robots = [name + spec[len(CUSTOM):] if spec.partition(":")[0] == CUSTOM else spec for spec in args.robots]
    if not any(spec.partition(":")[0] == name for spec in robots):
        raise InvalidParameterError(f"--arm-xml is given but no robot of --robots names it ({CUSTOM}:ACTIONS or "
                                    f"{name}:ACTIONS)")
    table = {"xml": str(Path(args.arm_xml).expanduser().resolve())}
    table.update({k: (list(v) if isinstance(v, tuple) else v) for k, v in options.items() if v is not None})
    return robots, {name: table}


def write_summary(store: ResultStore, out: Path) -> str:
    """matrix.md, matrix.json and matrix.png of a matrix store; returns the markdown."""
    spec = store.meta["spec"]
    if not matrix.is_matrix(spec):
        raise InvalidParameterError(f"{str(out)!r} holds a sweep, not a matrix")
    records = store.records()
    robots = list(dict.fromkeys(s for p in spec["pairs"] for s in p))
    cells = matrix.cells(records)
    text = matrix.markdown(cells, robots) if cells else "(no finished runs yet)"
    expected = len(store_runs(spec))
    header = (f"# Matrix {spec['name']!r}\n\n{len(records)} of {expected} runs finished; tasks "
              f"{', '.join(map(str, spec['tasks']))}; {spec['trials']} trials per run and seed; seeds "
              f"{', '.join(map(str, spec['seeds']))}; {spec['trajectory']} trajectories"
              + (f"; learners {', '.join(spec['learner'])}" if "learner" in spec else "") + ".\n\n")
    write_json_atomic(out / "matrix.json", {
        "robots": robots, "families": {r: matrix.family(r) for r in robots}, "runs": len(records),
        "expected_runs": expected,
        "cells": [c.__dict__ for c in cells], "families_summary": matrix.family_rows(cells)})
    write_text_atomic(out / "matrix.md", header + text + "\n")
    if cells:
        write_bytes_atomic(out / "matrix.png", matrix.heatmap_png(cells, robots))
    return header + text


def store_runs(spec: dict) -> list:
    return sweeps.expand(spec)
