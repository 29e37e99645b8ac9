"""Where `guided`'s first exposure is lost: the same learner given better trajectories than
robot 1 can hand over, as bounds (they use what robot 2 cannot know).

    python research/first_exposure_bounds.py --out runs/bounds          # ur5e -> planar2:joint, 20 trials
    python research/first_exposure_bounds.py --fast --out /tmp/bounds   # a smoke run in seconds

For each Table I task the source learns the task and hands over its converged greedy path, as
in ``research/first_exposure.py`` (same seed, same trials). The target then runs ``guided`` until
it first reaches the goal, given:

* ``trajectory``: that path, the method as it is;
* ``reachable cells only``: that path without the cells that are no target state's label (the
  target does not know them; a bound on what giving up on them sooner could save);
* ``target's own shortest path``: the cells of the target's own shortest path, in order (a
  bound on what any trajectory from robot 1 could give this learner).

Every trial counts: one that never reaches the goal counts at the step cap and the mean is a
lower bound (≥). Writes ``DIR/first_exposure_bounds.md`` and ``.json``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from armtransfer import script
from armtransfer.errors import ArmTransferError
from armtransfer.io import check_output_dir, staged_directory, write_json_atomic, write_text_atomic
from armtransfer.experiments import experiment
from armtransfer.experiments.stats import metrics
from armtransfer.learning.config import LearnerConfig
from armtransfer.experiments.tables import fmt_ci, markdown_table
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.specs import resolve

VARIANTS = ("trajectory", "reachable cells only", "target's own shortest path")


def reachable_only(traj: Trajectory, target) -> Trajectory:
    """``traj`` without the cells no state of ``target`` is labelled with (the goal is kept)."""
    labels = set(np.unique(target.label).tolist())
    keep = [(c, a) for c, a in zip(traj.cells, traj.actions) if int(c) in labels]
    if not keep:
        raise ArmTransferError(f"no cell of the trajectory is a label of {target.name}")
    return Trajectory(tuple(c for c, _ in keep), tuple(a for _, a in keep), traj.goal, source=traj.source)


def own_path(target, start_cell: int, goal_cell: int) -> Trajectory:
    """The cells of the target's own shortest path, repeats in a row merged (actions unused: 0)."""
    path = target.shortest_path(target.start_state(start_cell), goal_cell)
    cells: list[int] = []
    for s, _ in path[:-1]:
        c = int(target.label[s])
        if not cells or cells[-1] != c:
            cells.append(c)
    return Trajectory(tuple(cells), tuple(0 for _ in cells), goal_cell, source=f"{target.name} (own path)")


def run_task(source, target, task: int, trials: int, seed: int, config: LearnerConfig) -> dict:
    start, goal = TABLE_I[task].cells()
    path = target.shortest_path(target.start_state(start), goal)
    if path is None:
        raise ArmTransferError(f"{target.name} cannot reach Table I task {task}'s goal")
    optimal = len(path) - 1
    traj = experiment.source_trajectory("learned", source, start, goal, LearnerConfig(), seed)
    trajs = {"trajectory": traj, "reachable cells only": reachable_only(traj, target),
             "target's own shortest path": own_path(target, start, goal)}
    row = {"task": task, "optimal": optimal, "cells": {}, "unreachable_cells": len(traj) - len(trajs[VARIANTS[1]]),
           "stats": {}}
    for name, t in trajs.items():
        res = experiment.run_method("guided", target, start, goal, [t], trials, seed, config)
        steps = [r.exploration_steps for r in res.trials]
        row["cells"][name] = len(t)
        row["stats"][name] = {**metrics.exploration_stats(steps, config.max_total_steps), "exploration_steps": steps}
    return row


def ratio(entry: dict, optimal: int) -> str:
    lb = "≥ " if entry["mean_is_lower_bound"] else ""
    return f"{lb}{entry['mean'] / optimal:.2f} {fmt_ci([c / optimal for c in entry['ci95']], 2)}"


def markdown(pair: str, rows: list[dict], trials: int, seed: int, seconds: float) -> str:
    head = ["task", "optimal", "trajectory cells (unreachable)", *VARIANTS]
    body = [[str(r["task"]), str(r["optimal"]), f"{r['cells']['trajectory']} ({r['unreachable_cells']})",
             *[ratio(r["stats"][v], r["optimal"]) for v in VARIANTS]] for r in rows]
    return (f"## `guided` first exposure / optimal distance on {pair}, mean [95% CI], {trials} trials, seed {seed}\n\n"
            + markdown_table(head, body) + f"\n\n({seconds:.0f} s)\n")


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("--source", default="ur5e_like:cartesian")
    p.add_argument("--target", default="planar2:joint")
    p.add_argument("--tasks", type=int, nargs="+", default=[1, 2, 3, 4])
    script.experiment_options(p, fast="a smoke run: task 1, 2 trials")
    args = p.parse_args(argv)
    return script.run(_run, args)


def _run(args: argparse.Namespace) -> int:
    script.check_trials_seed(args.trials, args.seed)
    bad = [t for t in args.tasks if t not in TABLE_I]
    if bad:
        raise ArmTransferError(f"unknown Table I task {bad[0]}; valid: {', '.join(map(str, sorted(TABLE_I)))}")
    check_output_dir(args.out)
    source, target = resolve(args.source), resolve(args.target)
    tasks, trials = (args.tasks[:1], 2) if args.fast else (args.tasks, args.trials)
    config = LearnerConfig(max_episodes=1)  # the first exposure is the first episode's exploration
    t0 = time.perf_counter()
    rows = []
    for task in tasks:
        rows.append(run_task(source, target, task, trials, args.seed, config))
        r = rows[-1]
        print(f"task {task}: " + ", ".join(f"{v} {r['stats'][v]['mean'] / r['optimal']:.2f}x" for v in VARIANTS),
              flush=True)
    seconds = time.perf_counter() - t0
    pair = f"{args.source} → {args.target}"
    with staged_directory(args.out) as tmp:
        write_text_atomic(tmp / "first_exposure_bounds.md", markdown(pair, rows, trials, args.seed, seconds))
        write_json_atomic(tmp / "first_exposure_bounds.json", {
            "pair": pair, "trials": trials, "seed": args.seed, "fast": args.fast, "seconds": seconds,
            "config": config.to_dict(), "rows": rows})
    print(f"wrote {Path(args.out) / 'first_exposure_bounds.md'} ({seconds:.0f} s)")
    return 0


if __name__ == "__main__":
    script.exit_with(main)
