"""``armtransfer reproduce``: the paper's experiments on our rooms world (the report is
written by ``armtransfer.learning.reproduce_report``).

What runs (every number with a 95% confidence interval over ``trials`` trials):
  * Table II A-C: coarse -> fine, tasks 1-4, no transfer vs transfer (pseudo rewards);
  * Table IV: task 2, coarse -> fine, with the optimal and three longer trajectories;
  * Table V A-C: fine -> coarse, tasks 1-4;
  * the wind experiment (section IV.C, Fig. 6): coarse -> fine with wind 0.01;
  * action sequence mapping (section III.C): tasks 1 -> 2 -> 3 -> 4 in order, each task using
    the mapping accumulated on the tasks before it, for coarse -> fine (Table II D-F, Table
    III, Fig. 7), fine -> coarse (Table V D-E) and coarse -> fine under wind 0.01.
"""

from __future__ import annotations

from collections.abc import Callable

from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.tasks.layout import ROOMS
from armtransfer.learning import beyond, experiment, metrics, paper
from armtransfer.learning.mapping import ActionMapping, MacroTable
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig

TASKS = (1, 2, 3, 4)


def _compare(
    task: int,
    source: str,
    target: str,
    methods: tuple[str, ...],
    trials: int,
    seed: int,
    config: LearnerConfig,
    wind: float = 0.0,
    traj: trajectories.Trajectory | None = None,
    tick: Callable[[], None] | None = None,
) -> dict:
    src, tgt = grid_robot(source), grid_robot(target)
    start, goal = TABLE_I[task].cells()
    if traj is None:
        traj = trajectories.shortest(src, start, goal)
    results = [
        experiment.run_method(m, tgt, start, goal, traj, trials, seed, config, wind=wind, on_trial=tick)
        for m in methods
    ]
    summary = experiment.summarize(results)
    for entry in summary.values():
        experiment.compact(entry)  # keep results.json small; `rooms --json` has everything
    return {
        "task": task,
        "source": source,
        "target": target,
        "wind": wind,
        "distance": len(tgt.shortest_path(tgt.start_state(start), goal)) - 1,
        "trajectory_length": len(traj),
        "trajectory_cells": len(traj) * src.cell_step,
        "results": summary,
    }


def plan(trials: int) -> int:
    """How many trials ``run_all`` runs (for progress bars)."""
    return trials * (2 * len(TASKS) * 3 + len(paper.TABLE_IV_WAYPOINTS) + 1 + 3 * len(TASKS)) + beyond.plan(trials)




def mapping_protocol(
    source: str,
    target: str,
    trials: int,
    seed: int,
    config: LearnerConfig,
    wind: float = 0.0,
    tick: Callable[[], None] | None = None,
) -> dict:
    """Tasks 1-4 in order with method ``mapping``: task k uses the mapping learned from the
    converged trials of tasks 1..k-1 (task 1 has none, so it equals ``pseudo``)."""
    src, tgt = grid_robot(source), grid_robot(target)
    mapping = ActionMapping.for_robots(src, tgt)
    out: dict = {"source": source, "target": target, "wind": wind, "tasks": {}}
    figure = None
    for t in TASKS:
        start, goal = TABLE_I[t].cells()
        traj = trajectories.shortest(src, start, goal)
        res, learned = experiment.run_mapping(tgt, start, goal, traj, mapping, trials, seed, config,
                                              wind=wind, on_trial=tick)
        summary = experiment.summarize([res], baseline="")["mapping"]
        experiment.compact(summary)
        percent = [None if f is None else 100.0 * f for f in res.extra["mapped_fraction"]]
        e_mean, e_ci = metrics.mean_ci(percent)
        summary.update(mapped_percent_mean=e_mean, mapped_percent_ci95=e_ci,
                       entries_before=len(mapping), entries_after=len(learned))
        out["tasks"][t] = summary
        # Fig. 7 candidate: the converged trial with the largest mapped fraction
        table = MacroTable(mapping, traj, tgt)
        for k, trial in enumerate(res.trials):
            f = res.extra["mapped_fraction"][k]
            if f is not None and (figure is None or f > figure["mapped_fraction"]):
                figure = {
                    "task": t, "trial": k, "mapped_fraction": f,
                    "source_cells": [list(ROOMS.xy(c)) for c in (*traj.cells, traj.goal)],
                    "target_cells": [list(ROOMS.xy(int(tgt.label[s]))) for s, _ in trial.greedy_path],
                    "segments": [list(seg) for seg in table.mapped_segments(tgt, trial.greedy_path)],
                    "macros": {f"{x},{y}": mapping.names(m.actions, "target")
                               for c, m in table.by_cell.items() for x, y in [ROOMS.xy(c)]},
                }
        mapping = learned
    out["mapping"] = mapping.to_json()
    out["figure"] = figure
    return out


def _add_improvement(protocol: dict, baseline: dict) -> None:
    """Column F (Table V: E): improvement of the mapping runs over no transfer."""
    for t in TASKS:
        r, base = protocol["tasks"][t], baseline[t]["results"]["none"]
        r["improvement_percent"] = metrics.improvement_percent(base["mean"], r["mean"])
        r["improvement_ci95"] = metrics.improvement_ci(base["exploration_steps"], r["exploration_steps"])


def run_all(
    trials: int, seed: int, config: LearnerConfig, tick: Callable[[], None] | None = None
) -> dict:
    out: dict = {"trials": trials, "seed": seed, "config": config.to_dict()}
    both = ("none", "pseudo")
    out["table_ii"] = {t: _compare(t, "coarse", "fine", both, trials, seed, config, tick=tick) for t in TASKS}
    out["table_v"] = {t: _compare(t, "fine", "coarse", both, trials, seed, config, tick=tick) for t in TASKS}
    out["wind"] = {
        t: _compare(t, "coarse", "fine", both, trials, seed, config, wind=paper.WIND, tick=tick) for t in TASKS
    }
    coarse = grid_robot("coarse")
    start, goal = TABLE_I[2].cells()
    rows = {}
    for name, waypoints in paper.TABLE_IV_WAYPOINTS.items():
        traj = trajectories.via(coarse, start, goal, [ROOMS.cell(*w) for w in waypoints])
        methods = ("none", "pseudo") if name == "optimal" else ("pseudo",)
        rows[name] = _compare(2, "coarse", "fine", methods, trials, seed, config, traj=traj, tick=tick)
    base = rows["optimal"]["results"]["none"]
    for name, row in rows.items():
        r = row["results"]["pseudo"]
        r["improvement_percent"] = metrics.improvement_percent(base["mean"], r["mean"])
        r["improvement_ci95"] = metrics.improvement_ci(base["exploration_steps"], r["exploration_steps"])
        r["greedy_improvement_percent"] = metrics.improvement_percent(base["greedy_mean"], r["greedy_mean"])
    out["table_iv"] = rows
    out["mapping_coarse_fine"] = mapping_protocol("coarse", "fine", trials, seed, config, tick=tick)
    _add_improvement(out["mapping_coarse_fine"], out["table_ii"])
    out["mapping_fine_coarse"] = mapping_protocol("fine", "coarse", trials, seed, config, tick=tick)
    _add_improvement(out["mapping_fine_coarse"], out["table_v"])
    out["mapping_wind"] = mapping_protocol("coarse", "fine", trials, seed, config, wind=paper.WIND, tick=tick)
    _add_improvement(out["mapping_wind"], out["wind"])
    fine = grid_robot("fine")
    out["methods"] = beyond.run_methods(coarse, fine, trials, seed, config, tick=tick)
    out["oracle_text"], out["oracle"] = beyond.oracle_markdown(coarse, fine, trials, seed, config)
    return out
