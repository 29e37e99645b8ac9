"""SARSA(lambda) with knowledge-based pseudo rewards: the paper's Algorithm 1, compiled.

One call to :func:`learn` is one trial: episodes from the start state until the greedy
path has converged (or a limit is hit); when the harness hands the target's shortest path over
(``optimal``), until it has converged on a good path, at most ``ceil(quality x shortest)`` steps
long (``learning.clock``), so that a trial settled on a worse path goes on and pays for it. The inner loop is a numba kernel over the robot's
plain arrays, so it runs the same on grid robots and compiled arms.

Faithful to Algorithm 1:
  * Q(s, a) = 0 and e(s, a) = 0 at the start; traces are reset at every episode start.
  * epsilon-greedy: with probability epsilon a uniformly random action, otherwise an action
    of largest Q with ties broken uniformly at random.
  * delta = r + r'(s') + gamma Q(s', a') - Q(s, a), with Q(terminal, .) = 0;
    e(s, a) += 1 (accumulating); then for every (s, a): Q += alpha delta e; e *= gamma lambda.
  * The shaping term r' is the paper's pseudo reward i*K on reaching the i-th trajectory
    state (``pseudo``), or one of the other methods in :mod:`armtransfer.learning.methods`.

Method ``guided`` adds one step after every episode: value iteration over the pairs robot 2
has tried, on the successors it observed (``guide.planner``); it draws nothing.

The first episode's path, its loops erased, is kept as ``TrialResult.first_path`` for the
online action sequence mapping (``experiment.online_mapping``); it draws nothing.

Sparse traces: only pairs with a non-zero trace are stored. A trace that decays below
``trace_cutoff`` is dropped; with ``trace_cutoff=0`` nothing is dropped until it underflows
to 0, and the result is bit-for-bit the dense Algorithm 1 (``learning.reference``), as a
test checks.

The random stream, in the order it is drawn (the dense reference draws the same):
  1. choosing an action at a state with a macro (``learning.mapping``), when no macro is
     running: one draw u, the macro runs when u < 1 - epsilon. A running macro supplies
     its next action without a draw; it ends after its last action, or is abandoned when
     a step is blocked: the robot did not move, s' == s observed after wind (the robot
     cannot tell a wall from a gust that pushed it back). Right after an abandoned macro the next
     action is Algorithm 1's (no draw for a macro), so a macro blocked at its first step
     is not retried at once; after a macro that ran to its end, a macro at the state
     reached may start (macros chain);
  2. epsilon-greedy: one draw u; if u < epsilon one more draw picks the action as
     floor(u2 * n_actions); otherwise, when k > 1 actions tie for the largest Q, one more
     draw picks the floor(u2 * k)-th of them in index order;
     With a guide (method ``guided``, ``learning.guide``), in its exploration phase, the
     largest value is that of Q(s, a) - weight * score(a) instead of Q, and the extra draw
     is made only when m > 1 actions tie for it, picking the floor(u2 * m)-th of them in
     index order (no other draw is added);
  3. wind, only when its probability p > 0: one draw after every move, pushing when < p.
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numba
import numpy as np

from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.trial_result import TrialResult

from armtransfer.learning import clock as _clock
from armtransfer.learning import guide as _guide
from armtransfer.learning import jitcache as _jitcache
from armtransfer.learning import traces as _traces
from armtransfer.learning.guide import choice as _choice
from armtransfer.learning.guide import model as _model
from armtransfer.learning.guide import planner as _planner
from armtransfer.learning.guide import progress as _progress
from armtransfer.learning.shaping import (  # noqa: E402  (the kernel's shaping modes)
    MODE_FIRST_VISIT,
    MODE_NONE,
    MODE_POTENTIAL,
    MODE_PROGRESS,
    MODE_PSEUDO,
    Shaping,
)


class World(NamedTuple):
    """The robot's tables and the task, as the kernel reads them."""

    next_state: np.ndarray
    """int64 [S, A]: the state after each action."""
    wind_state: np.ndarray
    """int64 [S]: where a gust pushes each state."""
    label: np.ndarray
    """int64 [S]: the cell each state is labelled with."""
    start: int
    goal: int
    """The goal cell (a label)."""
    wind: float
    """The probability of a gust after a move."""
    good_len: int
    """The harness's measuring instrument, read only by the stopping rule: a settled greedy path
    ends the trial only when it is at most this long (-1: any settled path does). No choice of
    the learner reads it."""


class Rewards(NamedTuple):
    """The shaping term's arrays (``shaping.Shaping``, without its guide)."""

    mode: int
    bonus: np.ndarray
    traj_index: np.ndarray
    phi: np.ndarray


class Macros(NamedTuple):
    """The mapped macros, flat (``mapping.MacroTable.arrays``): a state's macro is
    actions[start[s]:start[s] + length[s]]; offered in the first ``episodes`` episodes."""

    start: np.ndarray
    length: np.ndarray
    actions: np.ndarray
    episodes: int


class Learning(NamedTuple):
    """The learner's parameters (``config.LearnerConfig``), as the kernel reads them."""

    alpha: float
    gamma: float
    lam: float
    epsilon: float
    step_reward: float
    goal_reward: float
    trace_cutoff: float
    max_episodes: int
    max_total_steps: int
    max_episode_steps: int
    patience: int
    run_on: float
    """A trial settled on a path that is not good runs on to (1 + run_on) x its steps then, at most."""

    @staticmethod
    def of(config: LearnerConfig) -> "Learning":
        return Learning(float(config.alpha), float(config.gamma), float(config.lam), float(config.epsilon),
                        float(config.step_reward), float(config.goal_reward), float(config.trace_cutoff),
                        int(config.max_episodes), int(config.max_total_steps), int(config.max_episode_steps),
                        int(config.patience), float(config.run_on))


class Outputs(NamedTuple):
    """What the kernel writes: Q, per-episode counts, and the paths it found."""

    Q: np.ndarray
    """float64 [S, A], learned in place (it may start from a given Q)."""
    episode_steps: np.ndarray
    """int64 [max_episodes]: steps per episode, negative when it hit a cap."""
    greedy_len: np.ndarray
    """int64 [max_episodes]: the greedy path's length after each episode (-1: misses the goal)."""
    macro_steps: np.ndarray
    """int64 [max_episodes]: steps taken inside macros per episode."""
    path_buf: np.ndarray
    """int64 [S + 1]: scratch, the greedy path after an episode."""
    prev_path: np.ndarray
    """int64 [S + 1]: the last greedy path that changed (the converged one at the end)."""
    fp_states: np.ndarray
    """int64 [S + 1]: the first episode's path, its loops erased."""
    fp_actions: np.ndarray
    """int64 [S + 1]: the action taken at each of its states."""
    settled_path: np.ndarray
    """int64 [S + 1]: the greedy path the first time it settled (``patience`` episodes unchanged)."""
    settled_actions: np.ndarray
    """int64 [S + 1]: the greedy action at each of its states then (lowest index on ties)."""
    settled: np.ndarray
    """int64 [2]: the episode of the first settled path's last change (-1: never settled) and
    the number of its states."""


@numba.njit(cache=True, inline="always")
def best_and_ties(Q, s, n_actions):
    """(the largest Q[s, .], how many actions have it)."""
    best = Q[s, 0]
    ties = 1
    for a in range(1, n_actions):
        q = Q[s, a]
        if q > best:
            best = q
            ties = 1
        elif q == best:
            ties += 1
    return best, ties


@numba.njit(cache=True, inline="always")
def nth_best(Q, s, n_actions, best, k):
    """The k-th (from 0, in index order) action whose Q[s, .] is ``best``."""
    for a in range(n_actions):
        if Q[s, a] == best:
            if k == 0:
                return a
            k -= 1
    return n_actions - 1  # unreachable


@numba.njit(cache=True, inline="always")
def _egreedy(Q, s, n_actions, eps, rng):
    if rng.random() < eps:
        return int(rng.random() * n_actions)
    best, ties = best_and_ties(Q, s, n_actions)
    return nth_best(Q, s, n_actions, best, 0 if ties == 1 else int(rng.random() * ties))


@numba.njit(cache=True, inline="always")
def _macro_step(s, eps, rng, in_macro, m_pos, m_end, may_start, macros):
    """(True, the running macro's next step, in_macro, m_pos, m_end); else a new macro starting
    at s (one draw, runs when < 1 - epsilon); else (False, -1, ...). m_pos/m_end index the flat
    macro actions."""
    if in_macro:
        return True, macros.actions[m_pos], True, m_pos + 1, m_end
    if may_start and macros.length[s] > 0 and rng.random() < 1.0 - eps:
        m_pos = macros.start[s]
        return True, macros.actions[m_pos], True, m_pos + 1, m_pos + macros.length[s]
    return False, -1, False, m_pos, m_end


@numba.njit(cache=True, inline="always")
def _choose(Q, s, eps, rng, in_macro, m_pos, m_end, may_start, macros):
    """The next action at s: a macro's step (``_macro_step``), else epsilon-greedy. Returns
    (action, in_macro, m_pos, m_end, 1 for a macro step else 0)."""
    found, a, in_macro, m_pos, m_end = _macro_step(s, eps, rng, in_macro, m_pos, m_end, may_start, macros)
    if found:
        return a, in_macro, m_pos, m_end, 1
    return _egreedy(Q, s, Q.shape[1], eps, rng), False, m_pos, m_end, 0


@numba.njit(cache=True, inline="always")
def _choose_guided(Q, s, eps, rng, in_macro, m_pos, m_end, may_start, macros, guided, g, m):
    """``_choose`` with the guide's epsilon-greedy (``guide.choice.egreedy``) in its
    exploration phase (``guided``)."""
    found, a, in_macro, m_pos, m_end = _macro_step(s, eps, rng, in_macro, m_pos, m_end, may_start, macros)
    if found:
        return a, in_macro, m_pos, m_end, 1
    if guided and not _progress.exhausted(g, m.progress):  # every trajectory given up on: Algorithm 1's own
        return _choice.egreedy(Q, s, eps, rng, g, m), False, m_pos, m_end, 0
    return _egreedy(Q, s, Q.shape[1], eps, rng), False, m_pos, m_end, 0


@numba.njit(cache=True)
def _greedy_path(Q, next_state, label, start, goal, stamp, stamp_id, path_out):
    """Follow argmax Q (lowest index on ties, no wind) from start. Returns the number of
    states written to path_out, negated when the goal is not reached (a loop or a cap)."""
    n_actions = next_state.shape[1]
    s = start
    n = 0
    cap = path_out.shape[0]
    while True:
        path_out[n] = s
        n += 1
        if label[s] == goal:
            return n
        if stamp[s] == stamp_id or n >= cap:
            return -n
        stamp[s] = stamp_id
        best = Q[s, 0]
        ba = 0
        for a in range(1, n_actions):
            if Q[s, a] > best:
                best = Q[s, a]
                ba = a
        s = next_state[s, ba]


@numba.njit(cache=True)
def shaping_term(mode, s, s2, terminal, bonus, traj_index, phi, gamma, paid_stamp, episode, best):
    """The shaping term for the move s -> s2; returns (term, the best bonus so far)."""
    if mode == MODE_PSEUDO:
        return bonus[s2], best
    if mode == MODE_FIRST_VISIT:  # once per trial: a bonus paid again every episode is not a reward of the state
        i = traj_index[s2]
        if i > 0 and paid_stamp[i] < 0:
            paid_stamp[i] = episode
            return bonus[s2], best
        return 0.0, best
    if mode == MODE_POTENTIAL:
        phi2 = 0.0 if terminal else phi[s2]
        return gamma * phi2 - phi[s], best
    if mode == MODE_PROGRESS:
        # pay only the part of the bonus beyond the best reached so far this episode
        if bonus[s2] > best:
            return bonus[s2] - best, bonus[s2]
        return 0.0, best
    return 0.0, best


def _make_run_trial(with_guide: bool):
    """The trial kernel, compiled with or without the guide (``with_guide``, a constant to numba).

    Why two: handed the guide's records, even empty and unused, the plain methods ran about
    a third slower (``benchmarks/bench_kernels.py``, BENCHMARKS.md). Compiled without the guide,
    every guide branch (``if with_guide``) is dropped before typing and ``g``/``m`` are
    None. Both come from this one body, so they cannot drift apart; numba caches each (the
    constant is part of its cache key).

    Arguments: ``world`` (:class:`World`), ``rewards`` (:class:`Rewards`), ``macros``
    (:class:`Macros`), ``learning`` (:class:`Learning`), the generator ``rng``, the guide ``g``
    and what robot 2 learns, ``m`` (``guide.Guide``, ``guide.Model``; None without the guide),
    and ``out`` (:class:`Outputs`; ``out.settled`` gets the first settled path). A settled greedy
    path ends the trial only when it is at most ``world.good_len`` long (-1: any); otherwise the
    trial goes on to a cap or until it has run ``learning.run_on`` times the steps it took to settle
    more. Returns (episodes, the converged episode or -1, the length
    of ``out.prev_path``, the length of ``out.fp_states``)."""

    @numba.njit(cache=True, nogil=True)  # nogil: trials run on threads (experiment.trial_threads)
    def _run_trial(world, rewards, macros, learning, rng, g, m, out):
        next_state, wind_state, label = world.next_state, world.wind_state, world.label
        start, goal, wind_p = world.start, world.goal, world.wind
        mode, bonus, traj_index, phi = rewards.mode, rewards.bonus, rewards.traj_index, rewards.phi
        alpha, gamma, eps = learning.alpha, learning.gamma, learning.epsilon
        r_step, r_goal, cutoff = learning.step_reward, learning.goal_reward, learning.trace_cutoff
        max_total_steps, max_episode_steps = learning.max_total_steps, learning.max_episode_steps
        patience = learning.patience
        Q, episode_steps, greedy_len, macro_steps_out = out.Q, out.episode_steps, out.greedy_len, out.macro_steps
        path_buf, prev_path, fp_states, fp_actions = out.path_buf, out.prev_path, out.fp_states, out.fp_actions
        settled_path = out.settled_path
        n_states, n_actions = next_state.shape
        q_flat = Q.reshape(n_states * n_actions)  # a view: the trace loop indexes pairs s * n_actions + a
        # the first episode's path with its loops erased (for the online action sequence mapping):
        # fp_states[0..fp_n-1], fp_actions[i] taken at fp_states[i]; fp_pos: a state's place in it
        fp_pos = np.full(n_states, -1, np.int64)
        fp_n = 0
        n_traj = traj_index.max() + 1 if traj_index.shape[0] > 0 else 1
        paid_stamp = np.full(max(n_traj, 1), -1, np.int64)
        stamp = np.full(n_states, -1, np.int64)
        # sparse traces: tr_sa holds s * n_actions + a, pos maps a pair to its slot
        cap = n_states * n_actions
        tr_sa = np.empty(cap, np.int64)
        tr_e = np.empty(cap, np.float64)
        pos = np.full(cap, -1, np.int64)
        n_tr = 0
        decay = gamma * learning.lam
        run_on_until = max_total_steps  # the run-on budget, set when the greedy path first settles
        total = 0
        prev_n = 0
        stable = 0
        converged_episode = -1
        episodes = 0
        has_macros = macros.actions.shape[0] > 0
        # Every use of the guide sits under ``if with_guide``, a constant: compiled without the
        # guide, numba drops those branches before typing, and g and m may be None.
        has_guide = False
        guide_episodes = 0
        plan = False
        if with_guide:
            has_guide = g.tstart.shape[0] > 1  # the guide has at least one trajectory
            guide_episodes = g.params.episodes
            plan = g.params.plan
        for ep in range(learning.max_episodes):
            guided = has_guide and ep < guide_episodes  # the model chooses in the exploration phase
            use_macros = has_macros and ep < macros.episodes
            # reset traces
            for k in range(n_tr):
                pos[tr_sa[k]] = -1
            n_tr = 0
            s = start
            best = 0.0
            if with_guide and has_guide:
                _model.start_episode(g, m, s, guided)
            # choose the first action (m_pos: position in the running macro, m_end: its end)
            if with_guide:
                a, in_macro, m_pos, m_end, macro_used = _choose_guided(
                    Q, s, eps, rng, False, 0, 0, use_macros, macros, guided, g, m
                )
            else:
                a, in_macro, m_pos, m_end, macro_used = _choose(Q, s, eps, rng, False, 0, 0, use_macros, macros)
            if ep == 0:
                fp_states[0] = s
                fp_pos[s] = 0
                fp_n = 1
            steps = 0
            reached = False
            limit = max_total_steps - total
            if ep > 0 and max_episode_steps < limit:
                limit = max_episode_steps
            while steps < limit:
                s2 = next_state[s, a]
                if wind_p > 0.0 and rng.random() < wind_p:
                    s2 = wind_state[s2]
                blocked = s2 == s  # what the robot observes: it did not move (after wind)
                steps += 1
                if ep == 0:  # loop erasure: back to s2's place if it is on the path, else append it
                    fp_actions[fp_n - 1] = a
                    p2 = fp_pos[s2]
                    if p2 >= 0:
                        for i in range(p2 + 1, fp_n):
                            fp_pos[fp_states[i]] = -1
                        fp_n = p2 + 1
                    else:
                        fp_states[fp_n] = s2
                        fp_pos[s2] = fp_n
                        fp_n += 1
                if with_guide and has_guide:  # robot 2 records what its move did to the label it perceives
                    _model.observe(g, m, s, a, s2, guided)
                terminal = label[s2] == goal
                r = r_step
                if terminal:
                    r += r_goal
                if mode != MODE_NONE:
                    term, best = shaping_term(
                        mode, s, s2, terminal, bonus, traj_index, phi, gamma, paid_stamp, ep, best
                    )
                    r += term
                if terminal:
                    q_next = 0.0
                    a2 = 0
                else:
                    abandoned = False
                    if in_macro and (blocked or m_pos >= m_end):
                        abandoned = blocked
                        in_macro = False
                    # right after an abandoned macro, Algorithm 1 chooses (no immediate retry)
                    if with_guide:
                        a2, in_macro, m_pos, m_end, used = _choose_guided(
                            Q, s2, eps, rng, in_macro, m_pos, m_end, use_macros and not abandoned, macros,
                            guided, g, m,
                        )
                    else:
                        a2, in_macro, m_pos, m_end, used = _choose(
                            Q, s2, eps, rng, in_macro, m_pos, m_end, use_macros and not abandoned, macros,
                        )
                    macro_used += used
                    q_next = Q[s2, a2]
                delta = r + gamma * q_next - Q[s, a]
                n_tr = _traces.mark(tr_sa, tr_e, pos, n_tr, s * n_actions + a, False)
                n_tr = _traces.apply(q_flat, tr_sa, tr_e, pos, n_tr, alpha * delta, decay, cutoff)
                if terminal:
                    reached = True
                    break
                s = s2
                a = a2
            total += steps
            if with_guide and has_guide and plan:  # robot 2 plans over the moves it has tried (guide.planner)
                _planner.plan(g, m.planner, Q, label, goal, gamma, r_step, r_goal)
            episode_steps[ep] = steps if reached else -steps
            macro_steps_out[ep] = macro_used
            episodes = ep + 1
            n = _greedy_path(Q, next_state, label, start, goal, stamp, ep, path_buf)
            greedy_len[ep] = n - 1 if n > 0 else -1
            same = n > 0 and n == prev_n
            if same:
                for i in range(n):
                    if path_buf[i] != prev_path[i]:
                        same = False
                        break
            if same:
                stable += 1
            else:
                stable = 0
                converged_episode = ep if n > 0 else -1
                prev_n = n
                for i in range(abs(n)):
                    prev_path[i] = path_buf[i]
            if n > 0 and stable >= patience:
                if out.settled[0] < 0:  # the first settled path: what the settled clock stops at
                    out.settled[0] = converged_episode
                    out.settled[1] = n
                    run_on_until = total + int(learning.run_on * total)
                    for i in range(n):
                        settled_path[i] = path_buf[i]
                        x = path_buf[i]
                        ba = 0
                        for a3 in range(1, n_actions):
                            if Q[x, a3] > Q[x, ba]:
                                ba = a3
                        out.settled_actions[i] = ba
                if world.good_len < 0 or n - 1 <= world.good_len:  # settled on a good path: the trial ends
                    break
            if total >= max_total_steps or total >= run_on_until:  # a cap, or the run-on budget spent
                break
        if stable < patience:
            converged_episode = -1
        if not (episodes > 0 and episode_steps[0] > 0):
            fp_n = 0  # the first episode did not reach the goal: no path
        return episodes, converged_episode, prev_n, fp_n

    return _run_trial


_run_trial = _make_run_trial(False)
"""The kernel for a run without a guide."""
_run_trial_guided = _make_run_trial(True)
"""The kernel for method ``guided``."""


def learn(
    robot: DiscreteRobot,
    start_state: int,
    goal_cell: int,
    config: LearnerConfig,
    rng: np.random.Generator,
    shaping=None,
    wind: float = 0.0,
    macros=None,
    q_init: np.ndarray | None = None,
    keep_q: bool = False,
    guide_model: _guide.Model | None = None,
    optimal: int | None = None,
) -> TrialResult:
    """Run one trial of SARSA(lambda) on ``robot`` from ``start_state`` to ``goal_cell``.

    ``shaping`` is a :class:`armtransfer.learning.shaping.Shaping` (None: no transfer); ``macros`` a
    :class:`armtransfer.learning.mapping.MacroTable` (None: no action sequence mapping); its attribute
    ``episodes`` (None: all) says in how many first episodes macros are offered. ``rng`` is
    the only source of randomness. ``guide_model``: what robot 2 learns with the guide, to learn
    into (``guide.new_model``) and read afterwards; None: a new one. ``optimal``: the target's
    shortest path from the start, measured by the harness (None: not measured): the trial then
    ends only on a settled greedy path at most ``clock.good_length(config.quality, optimal)``
    steps long (or at a cap), and the good-path clock is recorded; the learner never reads it.
    """
    n = robot.n_states
    sh = shaping if shaping is not None else Shaping.none(n)
    guide = getattr(sh, "guide", None)
    kernel = _run_trial if guide is None else _run_trial_guided
    if guide is not None:
        g, m = guide, _guide.new_model(guide, n, robot.n_actions) if guide_model is None else guide_model
    elif kernel is _run_trial_guided:  # run without a guide (benchmarks/bench_kernels.py, a test)
        g, m = _guide.inactive(robot.n_actions)
    else:  # the plain kernel never reads them
        g, m = None, None
    if macros is None:
        table = Macros(np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(0, np.int64), int(config.max_episodes))
    else:
        m_start, m_len, m_actions = macros.arrays(robot)
        m_episodes = getattr(macros, "episodes", None)
        table = Macros(m_start, m_len, m_actions, int(config.max_episodes if m_episodes is None else m_episodes))
    E = config.max_episodes
    out = Outputs(Q=np.zeros((n, robot.n_actions)) if q_init is None else np.array(q_init, dtype=np.float64),
                  episode_steps=np.zeros(E, np.int64), greedy_len=np.zeros(E, np.int64),
                  macro_steps=np.zeros(E, np.int64), path_buf=np.zeros(n + 1, np.int64),
                  prev_path=np.zeros(n + 1, np.int64), fp_states=np.zeros(n + 1, np.int64),
                  fp_actions=np.zeros(n + 1, np.int64), settled_path=np.zeros(n + 1, np.int64),
                  settled_actions=np.zeros(n + 1, np.int64),
                  settled=np.full(2, -1, np.int64))
    good_len = None if optimal is None else _clock.good_length(config.quality, optimal)
    world = World(robot.next_state, robot.wind_state, robot.label, int(start_state), int(goal_cell), float(wind),
                  -1 if good_len is None else int(good_len))
    rewards = Rewards(int(sh.mode), sh.bonus, sh.traj_index, sh.phi)
    episodes, _, _, fp_n = kernel(world, rewards, table, Learning.of(config), rng, g, m, out)
    Q, fp_states, fp_actions = out.Q, out.fp_states, out.fp_actions
    episode_steps, greedy_len, macro_steps = out.episode_steps, out.greedy_len, out.macro_steps
    episode_steps = episode_steps[:episodes].copy()
    lengths = greedy_len[:episodes].copy()
    first = int(episode_steps[0]) if episodes and episode_steps[0] > 0 else None
    # the settled clock: the first settled path (with no good length, where the trial stopped)
    conv_ep, path_n = int(out.settled[0]), int(out.settled[1])
    converged = conv_ep >= 0
    path: list[tuple[int, int]] = []
    if converged:
        states = out.settled_path[:path_n]
        for i in range(path_n - 1):
            s, t = int(states[i]), int(states[i + 1])
            a = int(out.settled_actions[i])
            assert robot.next_state[s, a] == t
            path.append((s, a))
        path.append((int(states[-1]), -1))
    first_path = [(int(fp_states[i]), int(fp_actions[i])) for i in range(fp_n - 1)]
    if fp_n:
        first_path.append((int(fp_states[fp_n - 1]), -1))
    greedy_steps = path_n - 1 if converged else None
    final = int(lengths[-1]) if episodes and lengths[-1] >= 0 else None
    return TrialResult(
        exploration_steps=first,
        converged=converged,
        total_steps=int(np.abs(episode_steps[: conv_ep + 1]).sum()) if converged else None,
        greedy_steps=greedy_steps,
        episodes=int(episodes),
        episode_steps=episode_steps,
        greedy_lengths=lengths,
        macro_steps=macro_steps[:episodes].copy(),
        greedy_path=path,
        first_path=first_path,
        Q=Q if keep_q else None,
        optimal=None if optimal is None else int(optimal),
        good_len=good_len,
        good_path_steps=None if good_len is None else _clock.good_path_steps(lengths, episode_steps, good_len),
        shortest_path_steps=None if optimal is None else _clock.good_path_steps(lengths, episode_steps, int(optimal)),
        settled_ratio=_clock.ratio(greedy_steps, optimal),
        final_ratio=_clock.ratio(final, optimal),
        steps_run=int(np.abs(episode_steps).sum()),
    )


DEPENDENCIES = [*_guide.FILES, Path(_traces.__file__)]
"""The files whose jitted functions the kernels above call: the guide's and the traces'."""

# numba's cache does not notice an edit to those files alone (``jitcache``), so the kernels'
# cache is emptied when one of them changes.
_jitcache.invalidate_stale(__name__, [best_and_ties, nth_best, _egreedy, _macro_step, _choose, _choose_guided, _greedy_path, shaping_term, _run_trial, _run_trial_guided], DEPENDENCIES)
