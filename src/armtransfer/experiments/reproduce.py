"""``armtransfer reproduce``: runs the paper's experiments on our rooms world and returns
their results as one JSON-able dict; ``reproduce_report`` writes report.md from it.

The paper's protocol by default: the transferred trajectory is the source robot's
converged greedy path after learning (``trajectory="learned"``; ``"optimal"``: its
breadth-first shortest path), and the mapping of each task is learned from ONE converged
trial of it (``mapping_from="single"``, the first converged one in trial order; ``"pooled"``:
every converged trial). The other choice of each is run too, on coarse -> fine, for the
report's comparison (``alternatives``).

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

from typing import Any

from collections.abc import Callable

from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.worlds.layout import ROOMS
from armtransfer.experiments import beyond, calibrated, experiment, paper
from armtransfer.experiments.stats import metrics
from armtransfer.learning.mapping import ActionMapping, MacroTable
from armtransfer.learning import presets
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.errors import InvalidParameterError

TASKS = (1, 2, 3, 4)
TRAJECTORIES = ("learned", "optimal")
MAPPING_FROM = ("single", "pooled")


def source_traj(task: int, source: str, kind: str, seed: int, config: LearnerConfig) -> trajectories.Trajectory:
    """The trajectory the source robot hands over on a Table I task (``learned``/``optimal``)."""
    start, goal = TABLE_I[task].cells()
    return experiment.source_trajectory(kind, grid_robot(source), start, goal, config, seed)


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
    kind: str = "learned",
) -> dict:
    src, tgt = grid_robot(source), grid_robot(target)
    start, goal = TABLE_I[task].cells()
    if traj is None:
        traj = source_traj(task, source, kind, seed, config)
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
        "distance": tgt.distance(tgt.start_state(start), goal),
        "trajectory_kind": kind,
        "trajectory_length": len(traj),
        "trajectory_cells": len(traj) * src.cell_step,
        "results": summary,
    }


def plan(trials: int, preset: str = presets.DEFAULT) -> int:
    """How many trials ``run_all`` runs (for progress bars)."""
    main = 2 * len(TASKS) * 3 + len(paper.TABLE_IV_WAYPOINTS) + 1 + 3 * len(TASKS)
    alternatives = len(TASKS) + len(TASKS)  # pseudo with the other trajectory; the other mapping
    study = calibrated.plan(trials) if preset == presets.PAPER_CALIBRATED else 0
    return trials * (main + alternatives) + beyond.plan(trials) + study


TOP_ENTRIES = 12


def mapping_protocol(
    source: str,
    target: str,
    trials: int,
    seed: int,
    config: LearnerConfig,
    wind: float = 0.0,
    tick: Callable[[], None] | None = None,
    kind: str = "learned",
    mapping_from: str = "single",
) -> dict:
    """Tasks 1-4 in order with method ``mapping``: task k uses the mapping learned on tasks
    1..k-1 (task 1 has none, so it equals ``pseudo``): from the first converged trial of
    each task (``single``, the paper's) or from all its converged trials (``pooled``)."""
    if mapping_from not in MAPPING_FROM:
        raise InvalidParameterError(f"unknown mapping source {mapping_from!r}; valid: {', '.join(MAPPING_FROM)}")
    src, tgt = grid_robot(source), grid_robot(target)
    mapping = ActionMapping.for_robots(src, tgt)
    out: dict = {"source": source, "target": target, "wind": wind, "tasks": {},
                 "trajectory_kind": kind, "mapping_from": mapping_from}
    figure = None
    for t in TASKS:
        start, goal = TABLE_I[t].cells()
        traj = source_traj(t, source, kind, seed, config)
        res, learned = experiment.run_mapping(tgt, start, goal, traj, mapping, trials, seed, config,
                                              wind=wind, on_trial=tick)
        learned_from = [k for k, trial in enumerate(res.trials) if trial.converged]
        if mapping_from == "single":
            learned = mapping.copy()
            learned_from = learned_from[:1]
            for k in learned_from:
                learned.learn_from(tgt, res.trials[k].greedy_path, traj)
        summary = experiment.summarize([res], baseline="")["mapping"]
        experiment.compact(summary)
        percent = [None if f is None else 100.0 * f for f in res.extra["mapped_fraction"]]
        e_mean, e_ci = metrics.mean_ci(percent)
        summary.update(mapped_percent_mean=e_mean, mapped_percent_ci95=e_ci,
                       entries_before=len(mapping), entries_after=len(learned),
                       mapping_learned_from_trials=learned_from, trajectory_length=len(traj))
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
        _improve(r, base)


def _improve(r: dict, base: dict) -> None:
    """Improvement of entry ``r`` over ``base``, paired trial by trial (common random numbers)."""
    cap = max(r.get("cap") or 0, base.get("cap") or 0)
    imp = metrics.paired_improvement(base["exploration_steps"], r["exploration_steps"], cap,
                                     paired=len(base["exploration_steps"]) == len(r["exploration_steps"]))
    r["improvement_percent"], r["improvement_ci95"], r["improvement_design"] = imp["percent"], imp["ci95"], imp["design"]


def run_all(
    trials: int, seed: int, config: LearnerConfig, tick: Callable[[], None] | None = None,
    trajectory: str = "learned", mapping_from: str = "single", preset: str = presets.DEFAULT,
) -> dict:
    """Everything the report needs, with the learner ``config``; ``preset`` names the preset it
    came from, and with ``paper-calibrated`` the calibrated learner's prediction and ablation
    (``experiments.calibrated``) run too."""
    presets.check(preset)
    if trajectory not in TRAJECTORIES:
        raise InvalidParameterError(f"unknown trajectory kind {trajectory!r}; valid: {', '.join(TRAJECTORIES)}")
    if mapping_from not in MAPPING_FROM:
        raise InvalidParameterError(f"unknown mapping source {mapping_from!r}; valid: {', '.join(MAPPING_FROM)}")
    out: dict = {"trials": trials, "seed": seed, "config": config.to_dict(), "preset": preset,
                 "trajectory": trajectory, "mapping_from": mapping_from}
    both = ("none", "pseudo")
    kw: dict[str, Any] = dict(tick=tick, kind=trajectory)
    out["table_ii"] = {t: _compare(t, "coarse", "fine", both, trials, seed, config, **kw) for t in TASKS}
    out["table_v"] = {t: _compare(t, "fine", "coarse", both, trials, seed, config, **kw) for t in TASKS}
    out["wind"] = {
        t: _compare(t, "coarse", "fine", both, trials, seed, config, wind=paper.WIND, **kw) for t in TASKS
    }
    coarse = grid_robot("coarse")
    start, goal = TABLE_I[2].cells()
    rows = {}
    for name, waypoints in paper.TABLE_IV_WAYPOINTS.items():
        traj = trajectories.via(coarse, start, goal, [ROOMS.cell(*w) for w in waypoints])
        methods = ("none", "pseudo") if name == "optimal" else ("pseudo",)
        rows[name] = _compare(2, "coarse", "fine", methods, trials, seed, config, traj=traj, tick=tick,
                              kind="optimal" if name == "optimal" else f"detour {name}")
    base = rows["optimal"]["results"]["none"]
    for name, row in rows.items():
        r = row["results"]["pseudo"]
        _improve(r, base)
        r["greedy_improvement_percent"] = metrics.improvement_percent(base["greedy_mean"], r["greedy_mean"])
    out["table_iv"] = rows
    mkw: dict[str, Any] = dict(tick=tick, kind=trajectory, mapping_from=mapping_from)
    out["mapping_coarse_fine"] = mapping_protocol("coarse", "fine", trials, seed, config, **mkw)
    _add_improvement(out["mapping_coarse_fine"], out["table_ii"])
    out["mapping_fine_coarse"] = mapping_protocol("fine", "coarse", trials, seed, config, **mkw)
    _add_improvement(out["mapping_fine_coarse"], out["table_v"])
    out["mapping_wind"] = mapping_protocol("coarse", "fine", trials, seed, config, wind=paper.WIND, **mkw)
    _add_improvement(out["mapping_wind"], out["wind"])
    # the other protocol choices, coarse -> fine, for the report's comparison
    other_kind = next(k for k in TRAJECTORIES if k != trajectory)
    other_from = next(k for k in MAPPING_FROM if k != mapping_from)
    alt_ii = {t: _compare(t, "coarse", "fine", ("pseudo",), trials, seed, config, tick=tick, kind=other_kind)
              for t in TASKS}
    for t in TASKS:
        _improve(alt_ii[t]["results"]["pseudo"], out["table_ii"][t]["results"]["none"])
    alt_map = mapping_protocol("coarse", "fine", trials, seed, config, tick=tick, kind=trajectory,
                               mapping_from=other_from)
    _add_improvement(alt_map, out["table_ii"])
    out["alternatives"] = {"trajectory": other_kind, "table_ii": alt_ii,
                           "mapping_from": other_from, "mapping_coarse_fine": alt_map}
    fine = grid_robot("fine")
    out["methods"] = beyond.run_methods(coarse, fine, trials, seed, config, tick=tick)
    out["oracle_text"], out["oracle"] = beyond.oracle_markdown(coarse, fine, trials, seed, config)
    if preset == presets.PAPER_CALIBRATED:
        out["calibrated"] = calibrated.run_study(config, trials, seed, tick=tick)
    return out


