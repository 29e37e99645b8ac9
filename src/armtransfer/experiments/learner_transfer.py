"""A transfer run by a learner from outside the package (``armtransfer.transfer(learner=...)``,
``armtransfer rooms --learner``, ``armtransfer arms --learner``, a sweep's ``learner``).

Each method's trials run through the benchmark's harness (:mod:`learner_trial`) on the case's
environment, the method's reward term over it, ``none`` with none: trial ``k`` of every method
starts from the seeds of trial ``k`` of the kernel (``SeedSequence([seed, 0, k])``), so a method
and its baseline meet the same streams, and the same seed gives the same bytes when the
learner draws only from the seed it is handed. Each trial becomes a
:class:`~armtransfer.learning.trial_result.TrialResult` as the kernel's are, so the tables, JSON and
frames read alike:

- ``exploration_steps``: training steps until the goal was first reached (None: never, within
  the budget ``max_total_steps``);
- ``total_steps``: the steps to convergence (the harness's criterion, ``learner_trial``), or
  the steps trained, the budget, when the trial did not converge;
- ``greedy_steps``: the converged greedy episode's steps; ``episodes`` and ``episode_steps``:
  the monitored training episodes (an unfinished one negative). The greedy path itself is not
  recorded (the harness counts steps, not states): ``greedy_path`` is empty.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from armtransfer.experiments import learner_trial
from armtransfer.experiments.work import Work
from armtransfer.experiments.experiment import MethodResult
from armtransfer.learning import methods
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learners import Learner
from armtransfer.learning.trial_result import TrialResult
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.robot import DiscreteRobot

EMPTY = np.zeros(0, dtype=np.int64)


def trial_result(result: dict, stream: list[int]) -> TrialResult:
    """The harness's result of one trial as the kernel's :class:`TrialResult`."""
    trained = result["evaluations"][-1][0] if result["evaluations"] else 0
    converged = bool(result["converged"])
    return TrialResult(exploration_steps=result["first_exposure"], converged=converged,
                       total_steps=result["convergence_steps"] if converged else int(trained),
                       greedy_steps=result["greedy_steps"], episodes=int(result["episodes"]),
                       episode_steps=np.asarray(stream, dtype=np.int64), greedy_lengths=EMPTY, macro_steps=EMPTY,
                       good_path_steps=result.get("good_path_steps"),
                       shortest_path_steps=result.get("shortest_path_steps"),
                       settled_ratio=result.get("settled_ratio"), final_ratio=result.get("final_ratio"),
                       steps_run=int(result.get("steps_run") or 0))


def run_method(learner: Learner, method: str, target: DiscreteRobot, start: list[int], goal: list[int],
               trajs: Sequence[Trajectory] | None, trials: int, seed: int, config: LearnerConfig,
               wind: float = 0.0, K: float | str | None = "auto", beta: float | None = None,
               on_trial: Callable[[], None] | None = None, heartbeat: bool = False,
               first_trial: int = 0) -> MethodResult:
    """``trials`` trials of ``method`` by ``learner`` on ``target`` from ``start`` to ``goal``
    (x, y), one after the other (a Python learner holds the GIL), a shaped method paid for
    ``trajs``, numbered from ``first_trial`` (their seeds); ``evaluations``: each trial's
    greedy evaluations (``learner_trial.trial``). A learner's fault is a one-line ``PluginError``
    naming it."""
    learner_trial.refuse_methods(learner, [method])
    shaped = methods.get(method).shaped
    out = MethodResult(method)
    ks: list[float | None] = []
    out.evaluations = []
    work = Work(method, target.name, (start[0], start[1]), (goal[0], goal[1]), trials, int(seed), config,
                wind=float(wind), K="auto" if K is None else K, beta=beta, first_trial=first_trial, learner=learner.name)
    given = list(trajs) if shaped and trajs is not None else None
    for trial in range(first_trial, first_trial + trials):
        result, stream = learner_trial.trial(learner, work, trial, target, given, heartbeat=heartbeat)
        out.trials.append(trial_result(result, stream))
        out.evaluations.append(result["evaluations"])
        ks.append(result["K"])
        if on_trial is not None:
            on_trial()
    if shaped:
        out.extra["K"] = ks[0]
    return out


def run_all(learner: Learner, source: DiscreteRobot, target: DiscreteRobot, start: list[int], goal: list[int],
            method_names: Sequence[str], trajs: Sequence[Trajectory], trials: int, seed: int, config: LearnerConfig,
            wind: float = 0.0, K: float | str | dict = "auto", beta: float | None = None,
            tick: Callable[[], None] | None = None, heartbeat: bool = False) -> list[MethodResult]:
    """Every method of ``method_names`` by ``learner``, in that order. No controls: a control
    trajectory (``experiment.control_trajectories``) ends elsewhere than the task's goal, and
    the harness's reward term (``TransferReward``) pays only a trajectory of the task."""
    learner_trial.refuse_methods(learner, list(method_names))

    def k_of(name: str) -> float | str:
        return K.get(name, "auto") if isinstance(K, dict) else K

    return [run_method(learner, m, target, start, goal, trajs, trials, seed, config, wind, k_of(m), beta, tick,
                       heartbeat) for m in method_names]
