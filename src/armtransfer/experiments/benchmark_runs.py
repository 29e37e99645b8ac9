"""The benchmark's runs, as the result store holds them: what one run is, how it is run, and
what a whole result of it looks like.

There are two kinds (``run.SourceRun``, ``run.TrialRun``), each keyed by a hash of its full
configuration (its content):

- a **source run**: robot 1 learns one (case, source seed)'s task without transfer; its
  result is the converged greedy path it hands over (as cell ids and action indices), or
  why there is none;
- a **trial run**: one trial of one method on robot 2, for one (case, source seed). A method
  that reads the trajectory carries robot 1's path in its configuration (so the trial is
  keyed by what it was handed, and can run anywhere, on any worker or cluster node, from
  its configuration alone); the other methods do not depend on robot 1 at all.

Every run names its ``learner``: the learner that runs a trial run's trial. The engine that
runs it is chosen from the learner and the target's state (``engines.engine_for``): ``sarsa``
(Algorithm 1) by the compiled kernel, or on a continuous target (``suites.Case.state``, the run
names ``state`` and ``noise``) by the linear learner on the target's continuous arm; a learner of
the outside registry through the harness; robot 1's source run is always the table-based one.

A trial's random stream is ``SeedSequence([seed, 0, trial])``, the stream of trial ``trial``
of the whole method, so running the trials one by one, in any order and on any worker, gives
the bytes of running them together.
"""

from __future__ import annotations

import time
import traceback

from armtransfer.errors import ArmTransferError, PluginError
from armtransfer.experiments import engines, experiment
from armtransfer.experiments.stats import learning_metrics
from armtransfer.experiments.run import DEFAULT_WORLD, SOURCE_FORMAT, TRIAL_FORMAT, SourceRun, TrialRun
from armtransfer.learning import methods
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learner_names import SARSA
from armtransfer.learning.trial_result import TrialResult
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.robot import DiscreteRobot

FORMATS = (SOURCE_FORMAT, TRIAL_FORMAT)

LEARNER = SARSA
"""The built-in learner: SARSA(lambda), Algorithm 1 with the method's shaping."""


def needs_trajectory(method: str) -> bool:
    """Whether ``method``'s trials read robot 1's trajectory (so they wait for its source run)."""
    m = methods.get(method)
    return m.shaped and getattr(m, "uses_trajectory", True)


def robot_key(spec: str, world: str | None = None) -> str:
    """The key of robot ``spec`` in the world ``world`` in the robots handed to :func:`execute`:
    the spec alone in the paper's rooms."""
    return spec if world in (None, DEFAULT_WORLD) else f"{spec} in {world}"


def source_run(source: str, target: str, start: list[int], goal: list[int], seed: int,
               config: LearnerConfig, world: str = DEFAULT_WORLD) -> SourceRun:
    """Robot 1 (``source``) learning the task from ``start`` to ``goal`` (x, y) with ``seed``;
    ``target`` names the case's robot 2 (a random task is drawn for both); ``world``: the
    world they move in."""
    return SourceRun(learner=LEARNER, source=source, target=target, start=(start[0], start[1]), goal=(goal[0], goal[1]),
                     seed=int(seed), config=config.to_dict(), world=world)


CONTINUOUS = "continuous"
"""A trial run's ``state`` when robot 2 is a continuous arm (``run.TrialRun``)."""


def trial_run(method: str, trial: int, source: str, target: str, start: list[int], goal: list[int], wind: float,
              seed: int, config: LearnerConfig, source_result: dict | None, learner: str = LEARNER,
              world: str = DEFAULT_WORLD, state: str = "discrete", noise: float = 0.0,
              learner_options: dict | None = None) -> TrialRun:
    """Trial ``trial`` of ``method`` on robot 2 (``target``). A method that reads the trajectory
    is handed ``source_result``'s (the result of the case's source run: its path, or why there
    is none); the others carry neither. Where robot 1 handed nothing over, the run also names
    ``told_nothing``: the method's baseline, which the trial then runs (:func:`trial_result`).
    ``state`` ``continuous``: robot 2 is ``target``'s continuous arm with actuation noise
    ``noise``. ``learner_options``: an outside learner's own settings (``Learner.options``), in
    the run's configuration and so its key."""
    if state != CONTINUOUS and noise:
        raise ValueError(f"a trial run's noise goes with a continuous state, got {state!r} with noise {noise!r}")
    handed = {}
    if needs_trajectory(method):
        if source_result is None:
            raise ValueError(f"a trial of {method} needs its source run's result")
        handed = {"handed": True, "trajectory": source_result["trajectory"],
                  "source_failure": source_result["failure"],
                  "told_nothing": told_nothing(method) if source_result["trajectory"] is None else None}
    return TrialRun(learner=learner, method=method, trial=int(trial), source=source, target=target,
                    start=(start[0], start[1]), goal=(goal[0], goal[1]), wind=wind, seed=int(seed), config=config.to_dict(),
                    learner_options=learner_options, world=world, state=state,
                    noise=float(noise) if state == CONTINUOUS else None, **handed)


def told_nothing(method: str) -> str:
    """What a trial of ``method`` runs when robot 1 handed no trajectory over: the baseline that
    shares its learner and is told nothing (a robot 2 with nothing to read learns as it would
    without transfer)."""
    base = methods.get(method).baseline
    if base is None or needs_trajectory(base):
        raise ValueError(f"{method} has no baseline told nothing to learn as without a trajectory")
    return base


def trajectory_json(traj: Trajectory) -> dict:
    return {"cells": [int(c) for c in traj.cells], "actions": [int(a) for a in traj.actions], "goal": int(traj.goal),
            "source": traj.source}


def trajectory_of(data: dict) -> Trajectory:
    return Trajectory(tuple(data["cells"]), tuple(data["actions"]), int(data["goal"]), source=data["source"])


def learn_source(source: DiscreteRobot, start: int, goal: int, seed: int,
                 config: LearnerConfig) -> tuple[Trajectory | None, str | None]:
    """Robot 1's converged greedy path, or None and why not (it did not converge)."""
    try:
        return experiment.source_trajectory("learned", source, start, goal, config, seed), None
    except ArmTransferError:
        return None, (f"robot 1 ({source.name}) did not converge on a path within "
                      f"{config.max_episodes:,} episodes and {config.max_total_steps:,} steps")


def work_of(run: TrialRun) -> engines.Work:
    """What a trial run's engine learns: its one trial, on one thread (a pair's trials share the threads)."""
    return engines.Work(run.method, run.target, run.start, run.goal, 1, run.seed, run.learner_config(), wind=run.wind,
                        first_trial=run.trial, learner=run.learner, state=run.state, noise=run.noise or 0.0,
                        threads=1)


def _fields(res: experiment.MethodResult) -> dict:
    """The result fields of a run's one trial (``res.trials[0]``)."""
    t = res.trials[0]
    curve = learning_metrics.curve(t.episode_steps, t.greedy_steps)
    return {"error": None, "first_exposure": t.exploration_steps, "converged": bool(t.converged),
            "convergence_steps": t.total_steps if t.converged else None, "greedy_steps": t.greedy_steps,
            "episodes": int(t.episodes), "area": float(curve.sum()), "curve": [float(v) for v in curve],
            "K": res.extra.get("K"), **({} if res.evaluations is None else {"evaluations": res.evaluations[0]}),
            **clock_fields(t), **({"warnings": res.extra["warnings"]} if res.extra.get("warnings") else {})}


CLOCK_FIELDS = ("good_path_steps", "shortest_path_steps", "settled_ratio", "final_ratio", "steps_run")
"""The good-path clock of a trial run's result (``trial_result.TrialResult``, ``learning.clock``)."""


def clock_fields(t: TrialResult) -> dict:
    """A trial's :data:`CLOCK_FIELDS`, and ``clock_note`` when its learner measures no good path."""
    out = {name: getattr(t, name) for name in CLOCK_FIELDS}
    note = t.clock_note
    if note:
        out["clock_note"] = note
    return out


class RunFailed(ArmTransferError):
    """A run that raised: the first line of the message says what, the rest is the traceback
    (the store keeps it beside the failure, ``ResultStore.write_failure``)."""


def with_traceback(err: BaseException) -> str:
    """``err`` in one line, then its traceback: that of the exception it was raised from or
    while handling first (a plugin's own fault, which the one-line error names), then its own."""
    first = (str(err) if isinstance(err, ArmTransferError) else f"{type(err).__name__}: {err}").splitlines()
    inner = err.__cause__ or err.__context__
    parts = [] if inner is None else traceback.format_exception(inner)
    parts += traceback.format_exception(err, chain=False)
    return (first[0] if first else type(err).__name__) + "\n" + "".join(parts)


def execute_recorded(run: SourceRun, robots: dict[str, DiscreteRobot]) -> tuple[dict, float]:
    """:func:`execute` as a benchmark's workers run it: a run that raises is :class:`RunFailed`,
    its message carrying the traceback, which the store keeps beside the failure."""
    try:
        return execute(run, robots)
    except Exception as err:  # noqa: BLE001 - a failed run, its traceback kept for the store
        raise RunFailed(with_traceback(err)) from None


def execute(run: SourceRun, robots: dict[str, DiscreteRobot]) -> tuple[dict, float]:
    """(result, seconds) of one benchmark run, a source or trial run (``robots``: by
    :func:`robot_key`); what it raises propagates."""
    t0 = time.perf_counter()
    if isinstance(run, TrialRun):
        result = trial_result(run, robots[robot_key(run.target, run.world)])
    elif isinstance(run, SourceRun):
        source = robots[robot_key(run.source, run.world)]
        start, goal = source.layout.cell(*run.start), source.layout.cell(*run.goal)
        traj, why = learn_source(source, start, goal, run.seed, run.learner_config())
        result = {"trajectory": None if traj is None else trajectory_json(traj), "failure": why}
    else:
        raise ValueError(f"not a benchmark run: {type(run).__name__}")
    return result, time.perf_counter() - t0


def trial_result(run: TrialRun, target: DiscreteRobot) -> dict:
    """A trial run's result: its engine's numbers (``engines.engine_for``), or ``error`` (and
    nothing else) when the method cannot run: a refusal of the case. With no trajectory to hand
    over, the trial is its baseline's (``told_nothing``): the same learner, seeds and case, byte
    for byte. A run written before that rule (no ``told_nothing``) keeps its result: an error."""
    if run.handed and run.trajectory is None:
        if run.told_nothing is None:
            return {"error": f"no trajectory: {run.source_failure}"}
        return trial_result(run.as_baseline(), target)
    engine = engines.engine_for(run.learner, run.state, "its case has")
    given = None if run.trajectory is None else [trajectory_of(run.trajectory)]
    try:
        return _fields(engine.trials(work_of(run), target, given))
    except PluginError as err:  # an outside learner's fault is no refusal of the case: its run fails
        if run.learner != LEARNER:
            raise
        return {"error": str(err)}
    except ArmTransferError as err:
        return {"error": str(err)}


def _int_or_none(v: object) -> bool:
    return v is None or (isinstance(v, int) and not isinstance(v, bool))


def _number(v: object) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def result_problem(config: dict, result: dict) -> str | None:
    """What is wrong with a stored benchmark run's result (None: it is whole)."""
    if config.get("format") == SOURCE_FORMAT:
        traj, why = result.get("trajectory"), result.get("failure")
        if traj is None:
            return None if isinstance(why, str) else "has neither a trajectory nor why not"
        if not isinstance(traj, dict) or not all(isinstance(traj.get(k), list) for k in ("cells", "actions")) \
                or len(traj["cells"]) != len(traj["actions"]) or not traj["cells"] \
                or not all(isinstance(v, int) for v in (*traj["cells"], *traj["actions"], traj.get("goal"))):
            return "has no whole trajectory"
        return None
    if config.get("format") == TRIAL_FORMAT:
        return trial_problem(result)
    return f"is not a benchmark run (format {config.get('format')!r})"


def trial_problem(result: dict) -> str | None:
    if result.get("error") is not None:
        return None if isinstance(result["error"], str) else "has an error that is not a message"
    checks = {"first_exposure": _int_or_none, "convergence_steps": _int_or_none, "greedy_steps": _int_or_none,
              "episodes": lambda v: isinstance(v, int) and not isinstance(v, bool),
              "converged": lambda v: isinstance(v, bool), "area": _number,
              "curve": lambda v: isinstance(v, list) and all(map(_number, v))}
    for name, ok in checks.items():
        if not ok(result.get(name)):
            return f"has no {name!r} of a trial"
    clock = {"good_path_steps": _int_or_none, "shortest_path_steps": _int_or_none,
             "settled_ratio": lambda v: v is None or _number(v), "final_ratio": lambda v: v is None or _number(v),
             "steps_run": lambda v: v is None or _int_or_none(v)}
    for name, ok in clock.items():  # a result written before the good-path clock has none of them
        if name in result and not ok(result[name]):
            return f"has a {name!r} that is not a trial's"
    return None
