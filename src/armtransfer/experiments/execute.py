"""Run one sweep run: build its task, trajectory and learner, return a JSON-able result.

Robots come in already built (``robots`` maps a spec like ``"fine"`` or
``"planar2:joint"`` to a ``DiscreteRobot``), so an executor can build each robot once
and share it with every worker.
"""

from __future__ import annotations

import time

from armtransfer.tasks.catalog import custom_task
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning import methods, presets
from armtransfer.experiments import engines, experiment
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learner_names import SARSA


def learner_config(run: dict) -> LearnerConfig:
    """The learner settings a sweep run carries (every LearnerConfig field it names, over its preset)."""
    return presets.config(run.get("preset", presets.DEFAULT),
                          {k: run[k] for k in LearnerConfig.options() if k in run})


def robot_specs(runs: list[dict]) -> list[str]:
    """The distinct robots a list of runs needs, in first-seen order."""
    seen: dict[str, None] = {}
    for run in runs:
        seen.setdefault(run["source"], None)
        seen.setdefault(run["target"], None)
    return list(seen)


def execute(run: dict, robots: dict[str, DiscreteRobot]) -> tuple[dict, float]:
    """(result, seconds) of one run."""
    t0 = time.perf_counter()
    source, target = robots[run["source"]], robots[run["target"]]
    task = custom_task(tuple(run["start"]), tuple(run["goal"]), target.layout)  # the robots' world
    start, goal = task.cells()
    config = learner_config(run)
    traj = None
    if methods.get(run["method"]).shaped and methods.get(run["method"]).uses_trajectory:
        # robot 1 learns with its own step cap, whatever max_total_steps caps robot 2's trials at (as the
        # benchmark's source runs); a run without max_total_steps has one config for both, as before
        own = learner_config({k: v for k, v in run.items() if k != "max_total_steps"})
        traj = experiment.source_trajectory(run["trajectory"], source, start, goal, own, run["seed"])
    if engines.engine_of(run.get("learner", SARSA)) == engines.OUTSIDE:  # through the benchmark's harness
        from armtransfer.experiments import learner_transfer
        from armtransfer.learning.learners import get

        res = learner_transfer.run_method(get(run["learner"]), run["method"], target, list(run["start"]),
                                          list(run["goal"]), None if traj is None else [traj], run["trials"],
                                          run["seed"], config, wind=run["wind"], K=run["K"])
    else:
        res = experiment.run_method(
            run["method"], target, start, goal, traj, run["trials"], run["seed"], config,
            wind=run["wind"], K=run["K"],
        )
    result = {
        "exploration_steps": res.column("exploration_steps"),
        "total_steps": res.column("total_steps"),
        "greedy_steps": res.column("greedy_steps"),
        "converged": res.column("converged"),
        **experiment.clock_columns(res),
        "episodes": res.column("episodes"),
        "K": res.extra.get("K"),
        "trajectory_length": None if traj is None else len(traj),
    }
    return result, time.perf_counter() - t0
