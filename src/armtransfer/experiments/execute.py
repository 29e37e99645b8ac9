"""Run one sweep run: build its task and trajectory, learn it with its engine, return a JSON-able result.

Robots come in already built (``robots`` maps a spec like ``"fine"`` or
``"planar2:joint"`` to a ``DiscreteRobot``), so an executor can build each robot once
and share it with every worker.
"""

from __future__ import annotations

import time

from armtransfer.tasks.catalog import custom_task
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning import methods
from armtransfer.experiments import engines, experiment
from armtransfer.experiments.run import SweepRun


def robot_specs(runs: list[SweepRun]) -> list[str]:
    """The distinct robots a list of runs needs, in first-seen order."""
    seen: dict[str, None] = {}
    for run in runs:
        seen.setdefault(run.source, None)
        seen.setdefault(run.target, None)
    return list(seen)


def work_of(run: SweepRun) -> engines.Work:
    """What the run's engine learns: all its trials, from trial 0."""
    return engines.Work(run.method, run.target, run.start, run.goal, run.trials, run.seed, run.learner_config(),
                        wind=run.wind, K=run.K, learner=run.learner)


def execute(run: SweepRun, robots: dict[str, DiscreteRobot]) -> tuple[dict, float]:
    """(result, seconds) of one run."""
    t0 = time.perf_counter()
    source, target = robots[run.source], robots[run.target]
    start, goal = custom_task(run.start, run.goal, target.layout).cells()  # the robots' world
    traj = None
    method = methods.get(run.method)
    if method.shaped and method.uses_trajectory:
        # robot 1 learns with its own step cap, whatever max_total_steps caps robot 2's trials at (as the
        # benchmark's source runs)
        traj = experiment.source_trajectory(run.trajectory, source, start, goal, run.learner_config(own_cap=True),
                                            run.seed)
    engine = engines.engine_for(run.learner)
    res = engine.trials(work_of(run), target, None if traj is None else [traj])
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
