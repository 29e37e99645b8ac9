"""One benchmark trial of a learner from outside the package (``armtransfer.learning.learners``).

The learner is handed the case's training environment: the robot's ``RobotRoomsEnv`` (what
``armtransfer/Rooms-v0`` and ``armtransfer/ArmRooms-v0`` make) under a ``TimeLimit`` of
``registration.MAX_EPISODE_STEPS`` steps, wrapped in ``TransferReward`` with the method when
the method has a reward term (none for ``none``), and under it all the harness's
:class:`Monitor`, which counts every step and episode itself and checks every action. The
learner never reports a number.

It learns in chunks, ``model.learn(chunk)`` with ``chunk = budget // CHUNKS``, until the trial's
step budget (the section's ``max_total_steps``). After each chunk one greedy episode
(``predict(obs, deterministic=True)``) runs on a separate environment of the same case without
the reward term (its own wind stream), capped at :data:`EVAL_CAP` x the target's shortest path.
**Convergence**: :data:`EVALS` consecutive greedy episodes reach the goal in at most (1 +
:data:`TOLERANCE`) x the shortest path; the steps to convergence are the training steps at the
first of them; a trial that does not get there within the budget is censored at it. The trial
goes on until :data:`EVALS` consecutive greedy episodes are good, at most ``ceil(quality x
shortest)`` steps (``learning.clock``), or the budget; the good-path clock is the training steps at
the first of the last run of good evaluations, None when the last evaluation is not good.
From the monitored stream: the first exposure (training steps until the goal was first
reached; None, censored, if never within the budget), the episodes' steps (an unfinished
episode negative, as the kernel's) and the learning curve and its area
(``learning_metrics.curve``).

Seeds: ``SeedSequence([seed, 0, trial])``, as the kernel's trial ``trial``, gives the model's
seed, the training environment's and the evaluation environment's, so trial ``trial`` of a
method and of its baseline start from the same seeds.
"""

from __future__ import annotations

import math
import numbers
import sys
import time
from typing import Any

import gymnasium as gym
import numpy as np

from armtransfer.errors import ArmTransferError, InvalidParameterError, PluginError
from armtransfer.experiments.stats import learning_metrics
from armtransfer.learning import clock
from armtransfer.learning import learners as registry
from armtransfer.learning import methods, plugin_calls
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learners import Learner, Transfer
from armtransfer.learning.plugins import trajectory_xy
from armtransfer.learning.trajectory import Trajectory
from armtransfer.learning.transfer_reward import TransferReward
from armtransfer.registration import MAX_EPISODE_STEPS
from armtransfer.tasks.catalog import custom_task
from armtransfer.tasks.envs import RobotRoomsEnv
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.experiments.harness_terms import CHUNKS, EVAL_CAP, EVALS, TOLERANCE
from armtransfer.experiments.work import Work

HEARTBEAT_SECONDS = 30.0
"""A trial running longer says how far it has got on stderr every this many seconds (when asked
to, ``heartbeat=True``), so that a slow learner is not mistaken for a hung one."""

PROBE_STEPS = 64
"""Steps a learner learns in its probe before a benchmark opens its store."""


def reward_methods(names: list[str] | tuple[str, ...]) -> list[str]:
    """Those of ``names`` an outside learner runs: ``none`` and the methods whose transfer is a
    reward term alone (``TransferReward``); the others change how the kernel chooses actions."""
    return [n for n in names if n == "none" or n in methods.REWARD_ONLY]


def where(learner: Learner) -> str:
    return f"learner {learner.name!r} ({learner.origin})"


def action_of(raw: object, space: gym.spaces.Discrete, said: str) -> int:
    """The action index ``raw`` stands for (a Python or numpy integer, a 0-d or one-element integer
    array, an integral float); anything else (an object that raises as it is read included) is a
    one-line :class:`PluginError` starting ``said``."""
    try:
        return _action_of(raw, space, said)
    except (PluginError, KeyboardInterrupt):
        raise
    except BaseException as err:  # noqa: BLE001 - the plugin's object, said in one line
        raise PluginError(f"{said} an object that cannot be read as an action ({plugin_calls.fault(err)})") from None


def _action_of(raw: object, space: gym.spaces.Discrete, said: str) -> int:
    value = raw
    if isinstance(value, np.ndarray):
        if value.size != 1 or value.ndim > 1:
            raise PluginError(f"{said} an action of shape {value.shape}; an action of this environment is one "
                              f"integer in 0..{int(space.n) - 1}")
        value = value.reshape(()).item()
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise PluginError(f"{said} {type(raw).__name__} {_shown(raw)} as an action; an action of this environment is one "
                          f"integer in 0..{int(space.n) - 1}")
    number = float(value)
    if not math.isfinite(number) or not number.is_integer() or not 0 <= number < int(space.n):
        raise PluginError(f"{said} the action {value!r}, not in the action space {space} (one integer in "
                          f"0..{int(space.n) - 1})")
    return int(number)


class Monitor(gym.Wrapper):
    """What the harness knows of training: every step and episode, counted here; every action
    checked (a learner stepping with a non-action is refused, naming it)."""

    def __init__(self, env: gym.Env, said: str) -> None:
        super().__init__(env)
        self.said = said
        self.total = 0
        self.episode = 0
        self.episode_steps: list[int] = []
        self.first_exposure: int | None = None

    def reset(self, **kwargs: Any):
        if self.episode:  # an episode given up unfinished: negative, as the kernel's
            self.episode_steps.append(-self.episode)
            self.episode = 0
        return self.env.reset(**kwargs)

    def step(self, action: Any):
        space = self.action_space
        assert isinstance(space, gym.spaces.Discrete)
        a = action_of(action, space, f"{self.said}: its model stepped the environment with")
        obs, reward, terminated, truncated, info = self.env.step(a)
        self.total += 1
        self.episode += 1
        if terminated:
            if self.first_exposure is None:
                self.first_exposure = self.total
            self.episode_steps.append(self.episode)
            self.episode = 0
        elif truncated:
            self.episode_steps.append(-self.episode)
            self.episode = 0
        return obs, reward, terminated, truncated, info

    def stream(self) -> list[int]:
        """Every episode's steps, the one under way last (negative)."""
        return self.episode_steps + ([-self.episode] if self.episode else [])


def _call(said: str, what: str, fn: Any, *args: Any, **kwargs: Any) -> Any:
    """``fn(*args)``; whatever it raises is the learner's fault, in one line naming it
    (``plugin_calls.call``)."""
    return plugin_calls.call(said, what, fn, *args, **kwargs)


def _call_method(said: str, model: Any, what: str, *args: Any, **kwargs: Any) -> Any:
    """``model.what(*args)``, the attribute looked up inside the guard too."""
    return plugin_calls.call(said, what, lambda *a, **k: getattr(model, what)(*a, **k), *args, **kwargs)


def _shown(obj: object) -> str:
    try:
        text = repr(obj)
    except BaseException:  # noqa: BLE001
        return "(that cannot be shown)"
    return text if len(text) <= 80 else text[:77] + "..."


def case_env(target: DiscreteRobot, start: list[int], goal: list[int], wind: float,
             config: LearnerConfig) -> RobotRoomsEnv:
    """The case's environment (no reward term, no time limit)."""
    task = custom_task((int(start[0]), int(start[1])), (int(goal[0]), int(goal[1])), target.layout)
    return RobotRoomsEnv(target, task, wind=wind, step_reward=config.step_reward, goal_reward=config.goal_reward)


def training_env(target: DiscreteRobot, work: Work,
                 trajectory: Trajectory | list[Trajectory] | None) -> tuple[gym.Env, TransferReward | None]:
    """The case's training environment: the time limit of the registered ids, and the method's
    reward term when it has one (its ``K`` and ``beta`` the work's: a benchmark trial names
    neither, 'auto' and the method's default)."""
    env: gym.Env = gym.wrappers.TimeLimit(case_env(target, list(work.start), list(work.goal), work.wind, work.config),
                                          max_episode_steps=MAX_EPISODE_STEPS)
    if work.method == "none":
        return env, None
    if work.method not in methods.REWARD_ONLY:
        raise ArmTransferError(f"method {work.method!r} changes how the kernel chooses actions; an outside learner "
                               f"runs only none and the reward-term methods ({', '.join(methods.REWARD_ONLY)})")
    assert trajectory is not None
    wrapped = TransferReward(env, trajectory, method=work.method, K="auto" if work.K is None else work.K,
                             gamma=work.config.gamma, beta=work.beta)
    return wrapped, wrapped


def seeds(seed: int, trial: int) -> tuple[int, int, int]:
    """(the model's, the training environment's, the evaluation environment's) seed of trial ``trial``."""
    state = np.random.SeedSequence([int(seed), 0, int(trial)]).generate_state(3, dtype=np.uint32)
    return int(state[0]), int(state[1]), int(state[2])


def greedy_episode(model: Any, env: RobotRoomsEnv, cap: int, said: str) -> int | None:
    """Steps of one greedy episode to the goal (None: not within ``cap``)."""
    obs, _ = env.reset()
    space = env.action_space
    assert isinstance(space, gym.spaces.Discrete)
    for k in range(1, cap + 1):
        out = _call_method(said, model, "predict", obs, deterministic=True)
        if not isinstance(out, tuple) or len(out) != 2:
            raise PluginError(f"{said}: its predict returned {type(out).__name__}, not (action, state)")
        a = action_of(out[0], space, f"{said}: its predict returned")
        obs, _, terminated, _, _ = env.step(a)
        if terminated:
            return k
    return None


def trial(learner: Learner, work: Work, trial: int, target: DiscreteRobot,
          trajectory: Trajectory | list[Trajectory] | None, heartbeat: bool = False) -> tuple[dict, list[int]]:
    """Trial ``trial`` of ``work`` by ``learner``: (the fields of ``benchmark_runs.trial_problem``
    and the greedy evaluations, as ``[training steps, greedy steps or None]``; the monitored
    stream of every training episode's steps, an unfinished one negative, as the kernel's
    ``episode_steps``)."""
    said = where(learner)
    config = work.config
    budget = int(config.max_total_steps)
    model_seed, env_seed, eval_seed = seeds(work.seed, trial)
    inner, term = training_env(target, work, trajectory)
    env = Monitor(inner, said)
    env.reset(seed=env_seed)
    ev = case_env(target, list(work.start), list(work.goal), work.wind, config)
    ev.reset(seed=eval_seed)
    path = target.shortest_path(ev.start_state, ev.goal_cell)
    if path is None:
        raise ArmTransferError(f"{target.name} cannot reach the goal")
    optimal = max(len(path) - 1, 1)
    cap, good = EVAL_CAP * optimal, (1 + TOLERANCE) * optimal
    good_len = clock.good_length(config.quality, optimal)
    model = _call(said, "make", learner.make, env, model_seed, *handed(learner, work.method, target, trajectory, term))
    chunk = max(budget // CHUNKS, 1)
    evals: list[list[int | None]] = []
    converged_at: int | None = None
    greedy: int | None = None
    t0 = last_said = time.monotonic()
    while env.total < budget:
        if heartbeat and time.monotonic() - last_said >= HEARTBEAT_SECONDS:
            last_said = time.monotonic()
            _say(f"armtransfer: {said}: method {work.method}, trial {trial + 1}: {env.total:,} of "
                 f"{budget:,} steps learned in {last_said - t0:.0f} s")
        before = env.total
        _call_method(said, model, "learn", min(chunk, budget - env.total))
        if env.total == before:
            raise PluginError(f"{said}: its learn({min(chunk, budget - before)}) took no step of the environment")
        steps = greedy_episode(model, ev, cap, said)
        evals.append([env.total, steps])
        last = evals[-EVALS:]
        if converged_at is None and len(last) == EVALS and all(s is not None and s <= good for _, s in last):
            converged_at, greedy = last[0][0], last[-1][1]
        if converged_at is not None and len(last) == EVALS \
                and all(s is not None and s <= good_len for _, s in last):
            break  # converged on a good path; converged on a worse one, it goes on to the budget
    converged = converged_at is not None and converged_at <= budget
    first = env.first_exposure if env.first_exposure is not None and env.first_exposure <= budget else None
    stream = env.stream()
    curve = learning_metrics.curve(stream, greedy if converged else None)
    return {"error": None, "first_exposure": first, "converged": converged,
            "convergence_steps": converged_at if converged else None, "greedy_steps": greedy if converged else None,
            "episodes": len(stream), "area": float(curve.sum()), "curve": [float(v) for v in curve],
            "K": None if term is None else float(term.K), "evaluations": evals,
            **eval_clock(evals, optimal, good_len, greedy if converged else None, env.total)}, stream


def eval_clock(evals: list[list], optimal: int, good_len: int, settled: int | None, total: int) -> dict:
    """The good-path clock from the greedy evaluations (``[training steps, greedy steps or None]``):
    the training steps at the first evaluation of the last run of evaluations at most ``good_len``
    (and at most ``optimal``) steps that lasts to the end of the trial (None: the last one is not),
    the converged greedy episode's steps and the last one's over the shortest, the steps trained."""
    def held(limit: int) -> int | None:
        at = None
        for trained, steps in reversed(evals):
            if steps is None or steps > limit:
                break
            at = int(trained)
        return at

    last = evals[-1][1] if evals else None
    return {"good_path_steps": held(good_len), "shortest_path_steps": held(optimal),
            "settled_ratio": clock.ratio(settled, optimal), "final_ratio": clock.ratio(last, optimal),
            "steps_run": int(total)}


def _say(line: str) -> None:
    """A progress line on stderr, above a progress bar when one is drawn."""
    from tqdm import tqdm  # start-up: only when a long trial says how far it is

    tqdm.write(line, file=sys.stderr)


def handed(learner: Learner, method: str, target: DiscreteRobot, trajectory: Trajectory | list[Trajectory] | None,
           term: TransferReward | None) -> tuple:
    """``make``'s arguments after (env, seed): the :class:`~armtransfer.learning.learners.Transfer`
    for a learner that asks for it (``Learner.transfer``), else none."""
    if not learner.transfer:
        return ()
    trajs = [] if trajectory is None else trajectory if isinstance(trajectory, list) else [trajectory]
    return (Transfer(method, tuple(trajectory_xy(t, target) for t in trajs),
                     None if term is None else term.transfer.shaping),)


def probe(learner: Learner, target: DiscreteRobot, start: list[int], goal: list[int],
          seconds: float = plugin_calls.PROBE_SECONDS) -> None:
    """``learner`` made on the case's environment (no reward term), learning :data:`PROBE_STEPS`
    steps, then predicting greedily a few steps, in a child process under a time limit of
    ``seconds`` (``plugin_calls.within``): a learner that raises anything, acts outside the action
    space or does not return in time is refused now, in one line naming it and the call, before
    anything is learned or written."""
    said = f"{where(learner)}, on robot {target.name}"

    def work() -> None:
        config = LearnerConfig()
        env = Monitor(gym.wrappers.TimeLimit(case_env(target, start, goal, 0.0, config),
                                             max_episode_steps=MAX_EPISODE_STEPS), said)
        env.reset(seed=0)
        model = _call(said, "make", learner.make, env, 0, *handed(learner, "none", target, None, None))
        if model is None or not all(callable(getattr(model, m, None)) for m in ("learn", "predict")):
            raise PluginError(f"{said}: its make returned {type(model).__name__}, not a model with learn and predict")
        _call_method(said, model, "learn", PROBE_STEPS)
        greedy_episode(model, case_env(target, start, goal, 0.0, config), 4, said)

    plugin_calls.within(seconds, f"{said}: its probe", work)


def refuse_methods(learner: Learner, names: list[str] | tuple[str, ...]) -> None:
    """A method ``learner`` cannot run (one that changes how the kernel chooses actions, or
    the action sequence mapping, whose macros are the kernel's) is a one-line error naming the
    learner and listing the methods it runs."""
    can = [n for n in reward_methods(list(methods.METHODS)) if not methods.get(n).macros]
    for name in names:
        if name not in can:
            raise InvalidParameterError(f"{where(learner)} cannot run method {name!r}: an outside learner runs none "
                                        f"and the reward-term methods; valid methods: {', '.join(can)}")


def known(name: str) -> Learner:
    """The outside learner ``name`` (an unknown one: a one-line error listing the valid ones)."""
    return registry.get(name)
