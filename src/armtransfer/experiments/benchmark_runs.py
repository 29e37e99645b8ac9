"""The benchmark's runs, as the result store holds them: what one run is, how it is run, and
what a whole result of it looks like.

There are two kinds, each keyed by a hash of its full configuration (its content):

- a **source run**: robot 1 learns one (case, source seed)'s task without transfer; its
  result is the converged greedy path it hands over (as cell ids and action indices), or
  why there is none;
- a **trial run**: one trial of one method on robot 2, for one (case, source seed). A method
  that reads the trajectory carries robot 1's path in its configuration (so the trial is
  keyed by what it was handed, and can run anywhere, on any worker or cluster node, from
  its configuration alone); the other methods do not depend on robot 1 at all.

Every run names its ``learner``: the learner that runs a trial run's trial. ``sarsa`` (the
learner of Algorithm 1, :func:`armtransfer.experiments.experiment.run_method`) is the one
this build has; :data:`LEARNERS` maps a name to the function that runs one trial, so a learner
added later runs through the same store, its runs keyed apart from the built-in one's.

A trial run of a case with a continuous target (``suites.Case.state``) names ``state`` and
``noise``: its trial runs the linear learner on the target's continuous arm
(:func:`_continuous_trial`); robot 1's source run is the same table-based one.

A trial's random stream is ``SeedSequence([seed, 0, trial])``, the stream of trial ``trial``
of the whole method, so running the trials one by one, in any order and on any worker, gives
the bytes of running them together.
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable

from armtransfer.errors import ArmTransferError, PluginError
from armtransfer.experiments import engines, experiment
from armtransfer.experiments.stats import learning_metrics
from armtransfer.experiments.sweep import content_key
from armtransfer.learning import methods
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learner_names import SARSA
from armtransfer.learning.trial_result import TrialResult
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.robot import DiscreteRobot

SOURCE_FORMAT = "armtransfer-benchmark-source/1"
TRIAL_FORMAT = "armtransfer-benchmark-trial/1"
FORMATS = (SOURCE_FORMAT, TRIAL_FORMAT)

LEARNER = SARSA
"""The built-in learner: SARSA(lambda), Algorithm 1 with the method's shaping."""


def _key(run: dict) -> dict:
    return dict(run, key=content_key(run))


def needs_trajectory(method: str) -> bool:
    """Whether ``method``'s trials read robot 1's trajectory (so they wait for its source run)."""
    m = methods.get(method)
    return m.shaped and getattr(m, "uses_trajectory", True)


DEFAULT_WORLD = "rooms"


def robot_key(spec: str, world: str | None = None) -> str:
    """The key of robot ``spec`` in the world ``world`` in the robots handed to :func:`execute`:
    the spec alone in the paper's rooms."""
    return spec if world in (None, DEFAULT_WORLD) else f"{spec} in {world}"


def _in_world(run: dict, world: str) -> dict:
    if world != DEFAULT_WORLD:  # a run of the paper's rooms keeps the key it had before worlds
        run["world"] = world
    return run


def source_run(source: str, target: str, start: list[int], goal: list[int], seed: int,
               config: LearnerConfig, world: str = DEFAULT_WORLD) -> dict:
    """Robot 1 (``source``) learning the task from ``start`` to ``goal`` (x, y) with ``seed``;
    ``target`` names the case's robot 2 (a random task is drawn for both); ``world``: the
    world they move in."""
    return _key(_in_world({"format": SOURCE_FORMAT, "learner": LEARNER, "source": source, "target": target,
                           "start": list(start), "goal": list(goal), "seed": int(seed), "config": config.to_dict()},
                          world))


CONTINUOUS = "continuous"
"""A trial run's ``state`` when robot 2 is a continuous arm; a run without ``state`` is on the
target's compiled table (every run written before continuous targets, with its key)."""


def trial_run(method: str, trial: int, source: str, target: str, start: list[int], goal: list[int], wind: float,
              seed: int, config: LearnerConfig, source_result: dict | None, learner: str = LEARNER,
              world: str = DEFAULT_WORLD, state: str = "discrete", noise: float = 0.0,
              learner_options: dict | None = None) -> dict:
    """Trial ``trial`` of ``method`` on robot 2 (``target``). A method that reads the trajectory
    is handed ``source_result``'s (the result of the case's source run: its path, or why there
    is none); the others carry neither. Where robot 1 handed nothing over, the run also names
    ``told_nothing``: the method's baseline, which the trial then runs (:func:`trial_result`).
    ``state`` ``continuous``: robot 2 is ``target``'s continuous arm with actuation noise
    ``noise`` (the run names both; a discrete run names neither, keeping its key).
    ``learner_options``: an outside learner's own settings (``Learner.options``), in the run's
    configuration and so its key (none: the key it had before learners had options)."""
    run = {"format": TRIAL_FORMAT, "learner": learner, "method": method, "trial": int(trial), "source": source,
           "target": target, "start": list(start), "goal": list(goal), "wind": wind, "seed": int(seed),
           "config": config.to_dict()}
    if learner_options:
        run["learner_options"] = dict(learner_options)
    _in_world(run, world)
    if state == CONTINUOUS:
        run["state"], run["noise"] = CONTINUOUS, float(noise)
    elif state != "discrete" or noise:
        raise ValueError(f"a trial run's state is discrete or continuous (noise with continuous only), got "
                         f"{state!r} with noise {noise!r}")
    if needs_trajectory(method):
        if source_result is None:
            raise ValueError(f"a trial of {method} needs its source run's result")
        run["trajectory"] = source_result["trajectory"]
        run["source_failure"] = source_result["failure"]
        if source_result["trajectory"] is None:
            run["told_nothing"] = told_nothing(method)
    return _key(run)


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


def _cells(run: dict, robot: DiscreteRobot) -> tuple[int, int]:
    return robot.layout.cell(*run["start"]), robot.layout.cell(*run["goal"])


def _sarsa_trial(run: dict, target: DiscreteRobot) -> dict:
    """One trial of the built-in learner: the fields of :func:`trial_result`."""
    start, goal = _cells(run, target)
    traj = run.get("trajectory")
    given = [trajectory_of(traj)] if traj is not None else None
    res = experiment.run_method(run["method"], target, start, goal, given, 1, run["seed"],
                                LearnerConfig(**run["config"]), wind=run["wind"], threads=1,
                                first_trial=run["trial"])
    return _fields(res)


def _fields(res: experiment.MethodResult) -> dict:
    """The result fields of a run's one trial (``res.trials[0]``)."""
    t = res.trials[0]
    curve = learning_metrics.curve(t.episode_steps, t.greedy_steps)
    return {"error": None, "first_exposure": t.exploration_steps, "converged": bool(t.converged),
            "convergence_steps": t.total_steps if t.converged else None, "greedy_steps": t.greedy_steps,
            "episodes": int(t.episodes), "area": float(curve.sum()), "curve": [float(v) for v in curve],
            "K": res.extra.get("K"), **clock_fields(t),
            **({"warnings": res.extra["warnings"]} if res.extra.get("warnings") else {})}


CLOCK_FIELDS = ("good_path_steps", "shortest_path_steps", "settled_ratio", "final_ratio", "steps_run")
"""The good-path clock of a trial run's result (``trial_result.TrialResult``, ``learning.clock``)."""


def clock_fields(t: TrialResult) -> dict:
    """A trial's :data:`CLOCK_FIELDS`, and ``clock_note`` when its learner measures no good path."""
    out = {name: getattr(t, name) for name in CLOCK_FIELDS}
    note = t.clock_note
    if note:
        out["clock_note"] = note
    return out


def _continuous_trial(run: dict, target: DiscreteRobot) -> dict:
    """One trial on ``target``'s continuous arm (in ``target``'s world, with the run's actuation
    noise), placed over the start: the linear learner of ``armtransfer.transfer(...,
    state="continuous")`` (``experiments.continuous.run_method``, its tile coding), trial
    ``run["trial"]``'s streams; the fields of :func:`trial_result`. The arm is made for the trial
    (a few ms once its scene is cached), so trials on threads share no MuJoCo data."""
    from armtransfer.experiments import continuous
    from armtransfer.tasks.continuous import continuous_arm

    start, goal = _cells(run, target)
    arm = continuous_arm(run["target"], layout=target.layout, noise=run["noise"])
    arm.place(start)
    traj = run.get("trajectory")
    given = [trajectory_of(traj)] if traj is not None else None
    res = continuous.run_method(run["method"], arm, goal, given, 1, run["seed"], LearnerConfig(**run["config"]),
                                approx=continuous.approximation_for(arm), first_trial=run["trial"])
    return _fields(res)


def _outside_trial(run: dict, target: DiscreteRobot) -> dict:
    """One trial of a learner of ``armtransfer.learning.learners`` (``learner_trial``'s harness)."""
    from armtransfer.experiments import learner_trial

    traj = run.get("trajectory")
    return learner_trial.run_trial(learner_trial.known(run["learner"]), run, target,
                                   None if traj is None else trajectory_of(traj))


LEARNERS: dict[str, Callable[[dict, DiscreteRobot], dict]] = {LEARNER: _sarsa_trial}
"""Learner name -> the function running one trial run on robot 2: ``(run, target) -> result``
with the fields :func:`trial_problem` checks. It may raise an ``ArmTransferError`` (the method
refuses the case: recorded as the run's ``error``). A learner not here, of
``armtransfer.learning.learners.LEARNERS`` (a plugin's), runs through ``learner_trial``."""


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


def execute_recorded(run: dict, robots: dict[str, DiscreteRobot]) -> tuple[dict, float]:
    """:func:`execute` as a benchmark's workers run it: a run that raises is :class:`RunFailed`,
    its message carrying the traceback, which the store keeps beside the failure."""
    try:
        return execute(run, robots)
    except Exception as err:  # noqa: BLE001 - a failed run, its traceback kept for the store
        raise RunFailed(with_traceback(err)) from None


def execute(run: dict, robots: dict[str, DiscreteRobot]) -> tuple[dict, float]:
    """(result, seconds) of one benchmark run (``robots``: by spec); what it raises propagates."""
    t0 = time.perf_counter()
    if run["format"] == SOURCE_FORMAT:
        source = robots[robot_key(run["source"], run.get("world"))]
        start, goal = _cells(run, source)
        traj, why = learn_source(source, start, goal, run["seed"], LearnerConfig(**run["config"]))
        result: dict = {"trajectory": None if traj is None else trajectory_json(traj), "failure": why}
    elif run["format"] == TRIAL_FORMAT:
        result = trial_result(run, robots[robot_key(run["target"], run.get("world"))])
    else:
        raise ValueError(f"not a benchmark run: format {run.get('format')!r}")
    return result, time.perf_counter() - t0


def trial_result(run: dict, target: DiscreteRobot) -> dict:
    """A trial run's result: its learner's numbers, or ``error`` (and nothing else) when the
    method cannot run: a refusal of the case. With no trajectory to hand over, the trial is its
    baseline's (``told_nothing``): the same learner, seeds and case, byte for byte. A run written
    before that rule (no ``told_nothing``) keeps its result: an error."""
    if needs_trajectory(run["method"]) and run.get("trajectory") is None:
        if "told_nothing" not in run:
            return {"error": f"no trajectory: {run.get('source_failure')}"}
        skip = ("key", "trajectory", "source_failure", "told_nothing")
        return trial_result(dict({k: v for k, v in run.items() if k not in skip}, method=run["told_nothing"]), target)
    learner = LEARNERS.get(run["learner"])
    engine = engines.engine_of(run["learner"], run.get("state", "discrete"), "its case has")
    if engine == engines.CONTINUOUS:
        learner = _continuous_trial
    elif learner is None:
        from armtransfer.learning.learners import LEARNERS as OUTSIDE

        if run["learner"] not in OUTSIDE:  # a run of a learner this build does not have fails; it is no result
            valid = dict.fromkeys([*LEARNERS, *OUTSIDE])
            raise ArmTransferError(f"unknown learner {run['learner']!r}; valid learners: {', '.join(valid)}")
        learner = _outside_trial
    try:
        return learner(run, target)
    except PluginError as err:  # an outside learner's fault is no refusal of the case: its run fails
        if run["learner"] not in LEARNERS:
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
