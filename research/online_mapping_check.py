"""Do the online mapping's macros do what robot 1's actions did? A check of the action sequence
mapping learned at first exposure, as ``research/first_exposure.py`` learns and reuses it.

    python research/online_mapping_check.py --out runs/mapping_check          # the 4 robot pairs, 20 trials
    python research/online_mapping_check.py --fast --out /tmp/mapping_check   # a smoke run in seconds

For each robot pair, tasks 1-4 in order: the mapping learned from ``guided``'s first exposures on
the earlier tasks (``experiment.online_mapping``) is applied to this task's transferred
trajectory (``mapping.MacroTable``). Every target state labelled with a cell that has a macro
then runs that macro, without wind, through the robot's own transitions. A macro does what
robot 1 did when it ends in the cell robot 1's key reached, s_t(i+L) for a key of L actions at
trajectory position i. Also counted: runs that end closer to that cell (in grid steps) than
they started. The mapping assumes an action sequence does the same thing wherever it runs;
these counts show where that holds.

Writes ``DIR/online_mapping_check.md`` and ``.json``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from armtransfer import script
from armtransfer.io import check_output_dir, staged_directory, write_json_atomic, write_text_atomic
from armtransfer.experiments import experiment
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.mapping import ActionMapping, MacroTable
from armtransfer.experiments.tables import markdown_table
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.specs import resolve

PAIRS = [("coarse", "fine"), ("fine", "coarse"),
         ("planar2:joint", "ur5e_like:cartesian"), ("ur5e_like:cartesian", "planar2:joint")]


def check_macros(mapping: ActionMapping, traj: Trajectory, target) -> dict:
    """Run every macro of ``mapping`` on ``traj`` from every target state of its cell."""
    layout = target.layout
    table = MacroTable(mapping, traj, target)
    cells = [*traj.cells, traj.goal]
    runs = exact = closer = 0
    for cell, macro in table.by_cell.items():
        want = np.array(layout.xy(int(cells[macro.position + len(macro.key)])))
        here = np.array(layout.xy(int(cell)))
        for s in target.states_at(cell):
            x = int(s)
            for a in macro.actions:
                x = int(target.next_state[x, a])
            got = np.array(layout.xy(int(target.label[x])))
            runs += 1
            exact += int((got == want).all())
            closer += int(np.abs(got - want).sum() < np.abs(here - want).sum())
    return {"cells_with_macro": len(table.by_cell), "trajectory_cells": len(traj),
            "mean_macro_length": (float(np.mean([len(m.actions) for m in table.by_cell.values()]))
                                  if table.by_cell else None),
            "runs": runs, "ends_at_robot1_cell": exact, "ends_closer": closer}


def run_pair(src_name: str, dst_name: str, tasks: list[int], trials: int, seed: int) -> list[dict]:
    source, target = resolve(src_name), resolve(dst_name)
    config = LearnerConfig(max_episodes=1)  # the mapping learns from the first exposure only
    online = None
    rows = []
    for task in tasks:
        start, goal = TABLE_I[task].cells()
        traj = experiment.source_trajectory("learned", source, start, goal, LearnerConfig(), seed)
        if online is not None and len(online):
            rows.append({"pair": f"{src_name} → {dst_name}", "task": task, "entries": len(online),
                         **check_macros(online, traj, target)})
        res = experiment.run_method("guided", target, start, goal, [traj], trials, seed, config)
        online = experiment.online_mapping(source, target, start, goal, res, traj, mapping=online)
    return rows


def pct(k: int, n: int) -> str:
    return "n/a" if n == 0 else f"{100 * k / n:.0f}%"


def markdown(rows: list[dict], trials: int, seed: int, seconds: float) -> str:
    head = ["source → target", "task", "mapping entries", "cells with a macro / trajectory cells",
            "mean macro length", "macro runs", "end in robot 1's cell", "end closer to it"]
    body = [[r["pair"], str(r["task"]), str(r["entries"]), f"{r['cells_with_macro']} / {r['trajectory_cells']}",
             "n/a" if r["mean_macro_length"] is None else f"{r['mean_macro_length']:.1f}", str(r["runs"]),
             pct(r["ends_at_robot1_cell"], r["runs"]), pct(r["ends_closer"], r["runs"])] for r in rows]
    return (f"## The online mapping's macros, learned from `guided`'s first exposures ({trials} trials, "
            f"seed {seed}) on the earlier tasks\n\n" + markdown_table(head, body) + f"\n\n({seconds:.0f} s)\n")


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    script.experiment_options(p, fast="a smoke run: the grid robots, tasks 1-2, 2 trials")
    args = p.parse_args(argv)
    return script.run(_run, args)


def _run(args: argparse.Namespace) -> int:
    script.check_trials_seed(args.trials, args.seed)
    check_output_dir(args.out)
    pairs, tasks, trials = PAIRS, [1, 2, 3, 4], args.trials
    if args.fast:
        pairs, tasks, trials = PAIRS[:2], [1, 2], 2
    t0 = time.perf_counter()
    rows = []
    for src_name, dst_name in pairs:
        for r in run_pair(src_name, dst_name, tasks, trials, args.seed):
            rows.append(r)
            print(f"{r['pair']} task {r['task']}: {r['runs']} macro runs, "
                  f"{pct(r['ends_at_robot1_cell'], r['runs'])} end in robot 1's cell", flush=True)
    seconds = time.perf_counter() - t0
    with staged_directory(args.out) as tmp:
        write_text_atomic(tmp / "online_mapping_check.md", markdown(rows, trials, args.seed, seconds))
        write_json_atomic(tmp / "online_mapping_check.json", {
            "trials": trials, "seed": args.seed, "fast": args.fast, "seconds": seconds, "rows": rows})
    print(f"wrote {Path(args.out) / 'online_mapping_check.md'} ({seconds:.0f} s)")
    return 0


if __name__ == "__main__":
    script.exit_with(main)
