"""The first-exposure table: exploration steps until the goal is first reached, as a multiple of the
target's optimal distance, for every transfer method beside the new one (``guided``).

    python research/first_exposure.py --out runs/first_exposure      # 20 trials, every case
    python research/first_exposure.py --fast --out /tmp/fe             # a smoke run in seconds

For each robot pair and Table I task, the source learns the task (SARSA(lambda) without
transfer) and hands over its converged greedy path, the paper's protocol. The target then
learns with ``none``, ``pseudo``, ``dense``, ``oracle`` (a bound, not a method: potential
shaping from the true map distance, which no robot has) and ``guided``, and ``guided`` again
with the two control trajectories (its cells shuffled; a random walk of the source), which
replace the trajectory's goal s_tg too (``armtransfer.learning.controls``). The same controls
with the task's goal kept are run as an ablation: they show what the path's order adds to
knowing the goal, and are not one of its checks. Every
trial counts: one that never reaches the goal counts at the step cap and its mean is marked
as a lower bound (≥). Means and 95% CIs are ``experiment.summarize``'s (``metrics``).

Also measured: the greedy path length at convergence over the target's optimal distance,
the total steps to convergence, and the online action sequence mapping: from task 2 on,
method ``mapping`` runs with the mapping learned from ``guided``'s first exposures on the
earlier tasks (``experiment.online_mapping``), before any of them converged.

Writes ``DIR/first_exposure.md`` and ``DIR/first_exposure.json``.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

from armtransfer import script
from armtransfer.io import check_output_dir, staged_directory, write_json_atomic, write_text_atomic
from armtransfer.learning import controls, potentials, sarsa
from armtransfer.experiments import experiment
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.controls import CONTROLS
from armtransfer.experiments.tables import fmt_ci, markdown_table
from armtransfer.learning.shaping import Shaping
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.specs import resolve

PAIRS = [("coarse", "fine"), ("fine", "coarse"),
         ("planar2:joint", "ur5e_like:cartesian"), ("ur5e_like:cartesian", "planar2:joint")]
METHODS = ("none", "pseudo", "dense", "guided")
NEW = "guided"
COLUMNS = ("none", "pseudo", "dense", "oracle", NEW, f"{NEW} [shuffled]", f"{NEW} [random]")
ABLATION = tuple(f"{NEW} [{controls.label(k, keep_goal=True)}]" for k in CONTROLS)
"""The ablation's columns: the controls with the task's goal kept."""
TARGET_RATIO = 3.0
"""The first check: first-exposure exploration at most 3x the optimal distance..."""
TARGET_GREEDY = 1.05
"""... a greedy path within 5% of optimal ..."""
TARGET_CONTROL = 3.0
"""... and controls that need at least 3x more exploration than the method."""


def run_oracle(target, start, goal, trials, seed, config) -> experiment.MethodResult:
    """The oracle bound on the same trial streams: Phi = -2 x the true shortest-path distance."""
    shaping = Shaping.potential(potentials.oracle(target, goal, config.gamma, config.step_reward), 1.0)
    out = experiment.MethodResult("oracle")
    out.trials = experiment.map_trials(lambda k: sarsa.learn(target, target.start_state(start), goal, config,
                                                             experiment.trial_rng(seed, k), shaping=shaping), trials)
    return out


def run_case(source, target, task: int, trials: int, seed: int, config: LearnerConfig, online):
    """Every column on one task; returns (summary by label, optimal distance, source path
    length, the online mapping after this task)."""
    start, goal = TABLE_I[task].cells()
    traj = experiment.source_trajectory("learned", source, start, goal, LearnerConfig(), seed)  # robot 1 learns in full
    results, _ = experiment.run_all(source, target, start, goal, METHODS, [traj], trials, seed, config,
                                    controls=False)
    results.append(run_oracle(target, start, goal, trials, seed, config))
    first = dataclasses.replace(config, max_episodes=1)  # only their first exposure is reported
    for kind in CONTROLS:
        for keep in (False, True):
            results.append(experiment.run_control(NEW, kind, source, target, start, goal, [traj], trials, seed,
                                                  first, keep_goal=keep))
    if online is not None and len(online):  # the mapping learned during the earlier tasks
        res, _ = experiment.run_mapping(target, start, goal, traj, online, trials, seed, config)
        res.control = "online"
        results.append(res)
    guided = next(r for r in results if r.label == NEW)
    online = experiment.online_mapping(source, target, start, goal, guided, traj, mapping=online)
    summary = experiment.summarize(results, baseline="none", cap=config.max_total_steps)
    for entry in summary.values():
        experiment.compact(entry)
    optimal = len(target.shortest_path(target.start_state(start), goal)) - 1
    return summary, optimal, len(traj), online


def ratio_cell(entry: dict, optimal: int) -> str:
    """Mean [95% CI] of exploration steps / optimal distance (≥ when a trial hit the cap)."""
    if entry.get("mean") is None:
        return "n/a"
    lb = "≥ " if entry["mean_is_lower_bound"] else ""
    ci = [c / optimal for c in entry["ci95"]]
    return f"{lb}{entry['mean'] / optimal:.2f} {fmt_ci(ci, 2)}"


def greedy_cell(entry: dict, optimal: int) -> str:
    n = len(entry["converged"])
    k = sum(entry["converged"])
    if entry["greedy_mean"] is None:
        return f"n/a (0/{n})"
    tail = "" if k == n else f" ({k}/{n} conv.)"
    return f"{entry['greedy_mean'] / optimal:.3f}{tail}"


def total_cell(entry: dict) -> str:
    return "n/a" if entry["total_mean"] is None else f"{entry['total_mean']:,.0f}"


def verdict(entry: dict, controls: list[dict], optimal: int, ablation: list[dict]) -> dict:
    """The three checks on one case, from the measured means; and the same factor for
    the controls that keep the goal (the ablation, not a check)."""
    ratio = entry["mean"] / optimal
    greedy = None if entry["greedy_mean"] is None else entry["greedy_mean"] / optimal
    factors = [c["mean"] / entry["mean"] for c in controls]
    kept = [c["mean"] / entry["mean"] for c in ablation]
    return {
        "first_exposure_ratio": ratio, "first_exposure_ok": ratio <= TARGET_RATIO,
        "greedy_ratio": greedy, "greedy_ok": greedy is not None and greedy <= TARGET_GREEDY
        and all(entry["converged"]),
        "control_factors": factors, "controls_ok": all(f >= TARGET_CONTROL for f in factors),
        "goal_kept_factors": kept, "goal_kept_ok": all(f >= TARGET_CONTROL for f in kept),
    }


def markdown(rows: list[dict], trials: int, seed: int, seconds: float) -> str:
    head = ["source → target", "task", "optimal", *COLUMNS, "mapping (online)"]
    t1 = [[r["pair"], str(r["task"]), str(r["optimal"]),
           *[ratio_cell(r["summary"][c], r["optimal"]) for c in COLUMNS],
           ratio_cell(r["summary"]["mapping [online]"], r["optimal"]) if "mapping [online]" in r["summary"]
           else "n/a"] for r in rows]
    conv_cols = ("none", "pseudo", "dense", "oracle", NEW)
    t2 = [[r["pair"], str(r["task"]), str(r["optimal"]),
           *[greedy_cell(r["summary"][c], r["optimal"]) for c in conv_cols],
           *[total_cell(r["summary"][c]) for c in conv_cols]] for r in rows]
    head2 = ["source → target", "task", "optimal", *[f"{c}: greedy/optimal" for c in conv_cols],
             *[f"{c}: steps to converge" for c in conv_cols]]
    t3 = [[r["pair"], str(r["task"]), f"{v['first_exposure_ratio']:.2f}" + ("" if v["first_exposure_ok"] else " ✗"),
           ("n/a" if v["greedy_ratio"] is None else f"{v['greedy_ratio']:.3f}") + ("" if v["greedy_ok"] else " ✗"),
           ", ".join(f"{f:.1f}" for f in v["control_factors"]) + ("" if v["controls_ok"] else " ✗"),
           ", ".join(f"{f:.1f}" for f in v["goal_kept_factors"]) + ("" if v["goal_kept_ok"] else " ✗")]
          for r in rows for v in [r["verdict"]]]
    t4 = [[r["pair"], str(r["task"]), str(r["optimal"]),
           *[ratio_cell(r["summary"][c], r["optimal"]) for c in (NEW, *ABLATION)]] for r in rows]
    head3 = ["source → target", "task", f"{NEW} first exposure (≤ {TARGET_RATIO:g}×)",
             f"{NEW} greedy/optimal (≤ {TARGET_GREEDY:g})",
             f"controls / {NEW}: shuffled, random (≥ {TARGET_CONTROL:g}×)",
             f"ablation, goal kept / {NEW}: shuffled, random (not a check)"]
    return "\n\n".join([
        f"## First exposure: exploration steps / the target's optimal distance, mean [95% CI], "
        f"{trials} trials, seed {seed}",
        markdown_table(head, t1),
        "## Convergence: greedy path length / optimal (converged trials), and mean steps to converge",
        markdown_table(head2, t2),
        f"## The checks for `{NEW}` (✗: not met)",
        markdown_table(head3, t3),
        "## Ablation: the controls with the task's goal kept (what the path's order adds to knowing "
        "the goal), exploration steps / optimal distance",
        markdown_table(["source → target", "task", "optimal", NEW, *ABLATION], t4),
        f"({seconds:.0f} s)",
    ]) + "\n"


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    script.experiment_options(p, fast="a smoke run: task 1, the grid robots, 2 trials")
    args = p.parse_args(argv)
    return script.run(_run, args)


def _run(args: argparse.Namespace) -> int:
    script.check_trials_seed(args.trials, args.seed)
    check_output_dir(args.out)
    pairs, tasks, trials, config = PAIRS, (1, 2, 3, 4), args.trials, LearnerConfig()
    if args.fast:
        pairs, tasks, trials = PAIRS[:2], (1, 2), 2
        config = LearnerConfig(max_episodes=60, max_total_steps=400_000)
    t0 = time.perf_counter()
    rows = []
    for src_name, dst_name in pairs:
        source, target = resolve(src_name), resolve(dst_name)
        online = None
        for task in tasks:
            summary, optimal, src_len, online = run_case(source, target, task, trials, args.seed, config, online)
            v = verdict(summary[NEW], [summary[f"{NEW} [{k}]"] for k in CONTROLS], optimal,
                        [summary[c] for c in ABLATION])
            rows.append({"pair": f"{src_name} → {dst_name}", "task": task, "optimal": optimal,
                         "source_path": src_len, "summary": summary, "verdict": v})
            print(f"{src_name} -> {dst_name} task {task}: "
                  + ", ".join(f"{c} {summary[c]['mean'] / optimal:.2f}x" for c in (*COLUMNS, *ABLATION)),
                  flush=True)
    seconds = time.perf_counter() - t0
    with staged_directory(args.out) as tmp:
        write_text_atomic(tmp / "first_exposure.md", markdown(rows, trials, args.seed, seconds))
        write_json_atomic(tmp / "first_exposure.json", {
            "trials": trials, "seed": args.seed, "config": config.to_dict(), "fast": args.fast,
            "seconds": seconds,
            "targets": {"first_exposure": TARGET_RATIO, "greedy": TARGET_GREEDY, "controls": TARGET_CONTROL},
            "rows": rows})
    print(f"wrote {Path(args.out) / 'first_exposure.md'} ({seconds:.0f} s)")
    return 0


if __name__ == "__main__":
    script.exit_with(main)
