"""SARSA(lambda) with linear function approximation: Algorithm 1 where no table of states exists.

Q(s, a) = sum of the weights w[f, a] of the active features f of s (``tiles.TileCoding`` over
the robot's configuration q). Everything else is :mod:`armtransfer.learning.sarsa`'s, in
the same order, so that with one-hot features (one tile per state) the two learners take
the same steps, bit for bit:

  * w = 0 and traces e = 0 at the start; traces are reset at every episode start.
  * epsilon-greedy on the Q values of the active features (``sarsa._egreedy``: the same
    draws, ties broken the same way).
  * delta = r + r'(s') + gamma Q(s', a') - Q(s, a), Q(terminal, .) = 0; the shaping term r'
    is ``sarsa.shaping_term``'s, paid on the *label* (the cell under the tool point): the
    paper's pseudo reward i*K on reaching the i-th trajectory cell, or another method's.
  * traces on (feature, action) pairs: accumulating (e += 1 for each active feature) or
    replacing (e = 1); then for every pair with a trace: w += alpha / tilings * delta * e
    and e *= gamma lambda; a trace below ``trace_cutoff`` is dropped (0: kept until it
    underflows, as the tabular learner's exact mode).
  * The first episode runs until the goal or the step cap; the rest are capped at
    ``max_episode_steps``. After every episode the greedy path (argmax Q, lowest index on
    ties, from the start) is rolled out on the robot; it ends at the goal, at a state it has
    visited before (a loop), or after ``greedy_cap`` states. Training stops when the path
    has reached the goal and stayed the same for ``patience`` episodes.

The robot is any object with the :class:`Mover` interface: ``reset()`` puts it at the
start and returns its label, ``move(a)`` returns the label reached or a negative number when
the move is blocked (the robot stays), ``q`` is its configuration (float64, read after every
move), ``key()`` a hashable name of its state (equal keys: the same configuration). A robot
whose moves are noisy may have ``noiseless()``, a context in which they are not: the greedy
path is rolled out inside it (as the tabular learner's greedy path has no wind).

The random stream is drawn in the tabular learner's order: one draw for epsilon-greedy and
one more for a random action or a tie (``sarsa``'s docstring, point 2). The robot draws
nothing.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from dataclasses import dataclass
from typing import Protocol

import numba
import numpy as np

from armtransfer.errors import InvalidParameterError
from armtransfer.learning import jitcache as _jitcache
from armtransfer.learning import sarsa as _sarsa
from armtransfer.learning import tiles as _tiles
from armtransfer.learning import traces as _traces
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.trial_result import TrialResult
from armtransfer.learning.sarsa import best_and_ties, nth_best, shaping_term
from armtransfer.learning.shaping import MODE_NONE, Shaping
from armtransfer.learning.tiles import TileCoding

TRACES = ("accumulating", "replacing")


class Mover(Protocol):
    """What the linear learner needs of a robot (see the module docstring)."""

    n_actions: int

    @property
    def q(self) -> np.ndarray: ...

    def reset(self) -> int: ...

    def move(self, a: int) -> int: ...

    def key(self) -> Hashable: ...


# index of each parameter in the float vector and each counter in the int vector the kernel reads
P_EPS, P_GAMMA, P_ALPHA, P_DECAY, P_CUTOFF, P_STEP, P_GOAL = range(7)
I_REPLACING, I_MODE, I_NTR, I_EPISODE, I_U = range(5)
UNIFORMS = 4096
"""Uniform draws taken from the trial's generator at a time (passing a Generator to numba at
every step would cost more than the step)."""
DRAWS_PER_STEP = 2
"""The most draws one step makes (epsilon-greedy: one, and one for the action or a tie)."""


@numba.njit(cache=True, nogil=True, inline="always")
def _draw(u, c):
    """The next uniform of the trial's stream (``u`` refilled by :class:`Learner` as it runs low)."""
    i = c[I_U]
    c[I_U] = i + 1
    return u[i]


@numba.njit(cache=True, nogil=True, inline="always")
def _egreedy(qrow, n_actions, eps, u, c):
    """``sarsa._egreedy`` on the row ``qrow[0]``, drawing from the buffered stream: the same
    draws in the same order, the same choice (the one-hot test checks it)."""
    if _draw(u, c) < eps:
        return int(_draw(u, c) * n_actions)
    best, ties = best_and_ties(qrow, 0, n_actions)
    return nth_best(qrow, 0, n_actions, best, 0 if ties == 1 else int(_draw(u, c) * ties))


@numba.njit(cache=True, nogil=True, inline="always")
def _values(w, feat, n_actions, qrow):
    """Q(s, .) of the state whose active features are ``feat`` into ``qrow`` [1, n_actions]."""
    for a in range(n_actions):
        v = w[feat[0] * n_actions + a]
        for k in range(1, feat.shape[0]):
            v += w[feat[k] * n_actions + a]
        qrow[0, a] = v


@numba.njit(cache=True, nogil=True)
def _begin(w, q, lower, width, offsets, dims, strides, per_tiling, table, feats, qrow, tr_sa, pos, p, c, u):
    """Start an episode at the configuration ``q``: traces dropped, the features of q in
    ``feats[0]``, the first action chosen (epsilon-greedy) and returned."""
    for k in range(c[I_NTR]):
        pos[tr_sa[k]] = -1
    c[I_NTR] = 0
    _tiles.features(q, lower, width, offsets, dims, strides, per_tiling, table, feats[0])
    n_actions = qrow.shape[1]
    _values(w, feats[0], n_actions, qrow)
    return _egreedy(qrow, n_actions, p[P_EPS], u, c)


@numba.njit(cache=True, nogil=True)
def _greedy(w, q, lower, width, offsets, dims, strides, per_tiling, table, feats, qrow):
    """argmax Q at the configuration ``q`` (lowest index on ties), as ``sarsa._greedy_path``."""
    _tiles.features(q, lower, width, offsets, dims, strides, per_tiling, table, feats[1])
    n_actions = qrow.shape[1]
    _values(w, feats[1], n_actions, qrow)
    best = qrow[0, 0]
    ba = 0
    for a in range(1, n_actions):
        if qrow[0, a] > best:
            best = qrow[0, a]
            ba = a
    return ba


@numba.njit(cache=True, nogil=True)
def td_step(w, q, lower, width, offsets, dims, strides, per_tiling, table, feats, qrow, tr_sa, tr_e, pos, p, c, u,
            bonus, traj_index, phi, paid_stamp, a, label, label2, goal, best):
    """One step of Algorithm 1 after action ``a`` took the robot from a state labelled
    ``label`` (features ``feats[0]``) to one labelled ``label2`` at configuration ``q``: the
    next action a' (0 at the goal), the reward's shaping term, the TD update over every trace.
    Returns (a', the best bonus so far, for ``progress``); ``feats[0]`` becomes the features of q."""
    mode = c[I_MODE]
    n_actions = qrow.shape[1]
    gamma = p[P_GAMMA]
    terminal = label2 == goal
    r = p[P_STEP]
    if terminal:
        r += p[P_GOAL]
    if mode != MODE_NONE:
        term, best = shaping_term(mode, label, label2, terminal, bonus, traj_index, phi, gamma, paid_stamp,
                              c[I_EPISODE], best)
        r += term
    feat, feat2 = feats[0], feats[1]
    if terminal:
        q_next = 0.0
        a2 = 0
    else:
        _tiles.features(q, lower, width, offsets, dims, strides, per_tiling, table, feat2)
        _values(w, feat2, n_actions, qrow)
        a2 = _egreedy(qrow, n_actions, p[P_EPS], u, c)
        q_next = qrow[0, a2]
    q_sa = w[feat[0] * n_actions + a]
    for k in range(1, feat.shape[0]):
        q_sa += w[feat[k] * n_actions + a]
    delta = r + gamma * q_next - q_sa
    n_tr = c[I_NTR]
    for k in range(feat.shape[0]):
        n_tr = _traces.mark(tr_sa, tr_e, pos, n_tr, feat[k] * n_actions + a, c[I_REPLACING] != 0)
    n_tr = _traces.apply(w, tr_sa, tr_e, pos, n_tr, p[P_ALPHA] * delta, p[P_DECAY], p[P_CUTOFF])
    c[I_NTR] = n_tr
    if not terminal:
        for k in range(feat.shape[0]):
            feat[k] = feat2[k]
    return a2, best


@dataclass(frozen=True)
class LinearConfig:
    """The function approximation's own settings (the rest is ``LearnerConfig``'s)."""

    traces: str = "accumulating"
    """``accumulating`` (e += 1, Algorithm 1's) or ``replacing`` (e = 1)."""
    greedy_cap: int = 5000
    """The longest greedy path rolled out after an episode (states); longer counts as missing the goal."""

    def __post_init__(self) -> None:
        if self.traces not in TRACES:
            raise InvalidParameterError(f"unknown traces {self.traces!r}; valid traces: {', '.join(TRACES)}")
        if isinstance(self.greedy_cap, bool) or not isinstance(self.greedy_cap, (int, np.integer)) \
                or self.greedy_cap < 2:
            raise InvalidParameterError(f"greedy_cap must be an integer of at least 2, got {self.greedy_cap!r}")


class Learner:
    """The arrays of one trial, and the kernel calls on them (the arguments in the kernels' order)."""

    def __init__(self, coding: TileCoding, n_actions: int, config: LearnerConfig, linear: LinearConfig,
                 shaping: Shaping, rng: np.random.Generator) -> None:
        pairs = coding.size * n_actions
        self.w = np.zeros(pairs)
        self.coding = coding.kernel_args()
        self.feats = np.zeros((2, coding.tilings), np.int64)
        self.qrow = np.zeros((1, n_actions))
        self.tr_sa, self.tr_e, self.pos = np.empty(pairs, np.int64), np.empty(pairs), np.full(pairs, -1, np.int64)
        self.p = np.array([config.epsilon, config.gamma, config.alpha / coding.tilings, config.gamma * config.lam,
                           config.trace_cutoff, config.step_reward, config.goal_reward])
        self.c = np.array([linear.traces == "replacing", shaping.mode, 0, 0, 0], np.int64)
        n_traj = int(shaping.traj_index.max()) + 1 if len(shaping.traj_index) else 1
        self.rewards = (np.asarray(shaping.bonus, np.float64), np.asarray(shaping.traj_index, np.int64),
                        np.asarray(shaping.phi, np.float64), np.full(max(n_traj, 1), -1, np.int64))
        self.rng = rng
        self.u = rng.random(UNIFORMS)
        self.low = UNIFORMS - DRAWS_PER_STEP

    def refill(self) -> None:
        """Keep the draws not yet used, first, and fill the rest from the generator: the stream
        the kernel reads is the generator's, in order."""
        i = int(self.c[I_U])
        left = UNIFORMS - i
        self.u[:left] = self.u[i:]
        self.u[left:] = self.rng.random(i)
        self.c[I_U] = 0

    def begin(self, q: np.ndarray) -> int:
        self.refill()
        return _begin(self.w, q, *self.coding, self.feats, self.qrow, self.tr_sa, self.pos, self.p, self.c, self.u)

    def greedy(self, q: np.ndarray) -> int:
        return _greedy(self.w, q, *self.coding, self.feats, self.qrow)


EpisodeSteps = Callable[["Learner", int, int, float, int, int], tuple[int, int, float, bool]]
"""Runs an episode's steps: (learner, a, label, best, limit, goal) -> (steps, a, best, reached),
exactly as :func:`learn`'s own loop (``experiments.fastloop``: compiled, with the arm's move)."""


def learn(mover: Mover, goal: int, coding: TileCoding, config: LearnerConfig, rng: np.random.Generator,
          shaping: Shaping | None = None, linear: LinearConfig = LinearConfig(),
          steps_by: EpisodeSteps | None = None) -> TrialResult:
    """One trial of linear SARSA(lambda) on ``mover`` towards the goal cell ``goal``.

    ``shaping`` holds per-*cell* arrays (``cells.cell_shaping``; None: no transfer). ``rng``
    is the only source of randomness. The result is ``trial_result.TrialResult``'s, with the paths
    empty (a continuous robot has no state numbers to name them by). ``steps_by``: what runs
    each episode's steps (the same steps, faster; None: the loop here)."""
    sh = shaping if shaping is not None else Shaping.none(1)
    if sh.guide is not None:
        raise InvalidParameterError("the linear learner has no guide: its methods are reward terms only")
    L = Learner(coding, mover.n_actions, config, linear, sh, rng)
    w, (lower, width, offsets, dims, strides, per_tiling, table), feats, qrow = L.w, L.coding, L.feats, L.qrow
    tr_sa, tr_e, pos, p, c, u, low = L.tr_sa, L.tr_e, L.pos, L.p, L.c, L.u, L.low
    bonus, traj_index, phi, paid = L.rewards
    q = mover.q
    E = config.max_episodes
    episode_steps = np.zeros(E, np.int64)
    greedy_len = np.zeros(E, np.int64)
    total = 0
    prev: list | None = None
    stable = 0
    converged_episode = -1
    episodes = 0
    move = mover.move
    for ep in range(E):
        c[I_EPISODE] = ep
        label = mover.reset()
        a = L.begin(q)
        best = 0.0
        steps = 0
        reached = False
        limit = config.max_total_steps - total
        if ep > 0 and config.max_episode_steps < limit:
            limit = config.max_episode_steps
        if steps_by is not None:
            steps, a, best, reached = steps_by(L, a, label, best, limit, goal)
        while steps_by is None and steps < limit:
            label2 = move(a)
            if label2 < 0:
                label2 = label
            steps += 1
            if c[I_U] > low:
                L.refill()
            a, best = td_step(w, q, lower, width, offsets, dims, strides, per_tiling, table, feats, qrow, tr_sa, tr_e, pos,
                              p, c, u, bonus, traj_index, phi, paid, a, label, label2, goal, best)
            if label2 == goal:
                reached = True
                break
            label = label2
        total += steps
        episode_steps[ep] = steps if reached else -steps
        episodes = ep + 1
        path, at_goal = _greedy_path(mover, L, goal, linear.greedy_cap)
        greedy_len[ep] = len(path) - 1 if at_goal else -1
        n = len(path) if at_goal else -len(path)
        if at_goal and prev is not None and prev[0] == n and prev[1] == path:
            stable += 1
        else:
            stable = 0
            converged_episode = ep if at_goal else -1
            prev = [n, path]
        if at_goal and stable >= config.patience:
            break
        if total >= config.max_total_steps:
            break
    if stable < config.patience:
        converged_episode = -1
    episode_steps = episode_steps[:episodes].copy()
    converged = converged_episode >= 0
    return TrialResult(
        exploration_steps=int(episode_steps[0]) if episodes and episode_steps[0] > 0 else None,
        converged=converged,
        total_steps=int(np.abs(episode_steps[: converged_episode + 1]).sum()) if converged else None,
        greedy_steps=int(greedy_len[converged_episode]) if converged else None,
        episodes=int(episodes),
        episode_steps=episode_steps,
        greedy_lengths=greedy_len[:episodes].copy(),
        macro_steps=np.zeros(episodes, np.int64),
    )


def _greedy_path(mover: Mover, learner: Learner, goal: int, cap: int) -> tuple[list, bool]:
    """The greedy path from the start: (the states' keys, whether it reached the goal). It
    stops at the goal, at a state visited before, or after ``cap`` states (without noise, when
    the robot has ``noiseless()``)."""
    quiet = getattr(mover, "noiseless", None)
    if quiet is not None:
        with quiet():
            return _greedy_path_of(mover, learner, goal, cap)
    return _greedy_path_of(mover, learner, goal, cap)


def _greedy_path_of(mover: Mover, learner: Learner, goal: int, cap: int) -> tuple[list, bool]:
    move = getattr(mover, "fast_step", mover.move)  # an arm's compiled move: the same moves, faster
    label = mover.reset()
    key = mover.key()
    path = [key]
    seen = {key}
    while True:
        if label == goal:
            return path, True
        if len(path) >= cap:
            return path, False
        moved = move(learner.greedy(mover.q))
        if moved >= 0:
            label = moved
        key = mover.key()
        path.append(key)
        if key in seen:
            return path, False
        seen.add(key)


_jitcache.invalidate_stale(__name__, [_draw, _egreedy, _values, _begin, _greedy, td_step],
                           [_tiles.__file__, _traces.__file__, _sarsa.__file__])
