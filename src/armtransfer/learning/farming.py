"""The exact farming check of the paper's pseudo reward, by value iteration.

The paper's pseudo reward pays i*K every time the robot *is* on the i-th trajectory cell.
``methods.build_shaping`` refuses ``step_reward + n*K >= 0``, where standing still on s_tn pays.
That is necessary but not sufficient under discounting: with gamma = 0.99 a robot that
bumps a wall forever next to s_tn earns (n*K + step_reward)/(1 - gamma), which can beat
the discounted cost of walking on to the goal even when n*K + step_reward < 0.

The experimenter knows the target robot's tables (``next_state``, ``wind_state``) even
though the learner does not, so the shaped task can be solved exactly: value iteration on

    Q(s, a) = sum_{s'} P(s' | s, a) [step_reward + bonus[s'] + goal_reward*[s' goal]
                                     + gamma * V(s') * [s' not goal]]

with P the move followed by the wind with probability ``wind`` (as the kernel draws it).
K is *farmable* when some greedy policy of the optimal Q (any tie-break within a small
tolerance) does not reach the goal with probability 1 from the start, i.e. it can be
trapped in a set of non-goal states. That is what SARSA converges towards, so a farmable
K makes the paper's learner loop instead of finishing.

Only ``pseudo`` and ``mapping`` (pseudo rewards plus macros, which change exploration,
not the optimal Q) can be farmed. ``first-visit`` pays each cell once per trial and ``progress``
each gain once per episode, so the shaping paid in an episode is bounded by n*K and
an endless loop earns only step rewards; ``potential`` and ``dense`` are potential-based
(gamma*phi(s') - phi(s), phi = 0 at the goal), which leaves the optimal policy unchanged
(Ng, Harada and Russell 1999). :func:`check_k` therefore accepts every K for them.

That is about the optimal policy. A learner on its way can be held by less: a move that
leaves its state unchanged (a blocked move, or with wind a push back) and pays, because its Q
then rises above every other action's and the learner repeats it. :func:`check_self_loops`
checks every method's shaping, as the kernel pays it, at every such move of the robot (with
the potentials unbounded, ``dense`` failed it: ``potentials.bounded``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numba
import numpy as np

from armtransfer.errors import InvalidParameterError
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning import methods, rewards
from armtransfer.learning.sarsa import shaping_term as kernel_shaping
from armtransfer.learning.shaping import Shaping
from armtransfer.learning.trajectory import Trajectory

SAFETY_FRACTION = 0.9
"""K='auto' for pseudo/mapping is at most this fraction of the largest safe K found by VI."""
TIE_TOL = 1e-7
"""Actions within this (relative to the value scale) of the best count as greedy."""


@numba.njit(cache=True)
def _value_iteration(nxt, wind_nxt, reward, terminal, gamma, wind, tol, max_iter, V, states):
    """In-place VI on V over ``states`` (closed under successors); returns the number of
    sweeps. ``nxt``/``wind_nxt`` are [S, A]."""
    A = nxt.shape[1]
    for it in range(max_iter):
        diff = 0.0
        for s in states:
            best = -np.inf
            for a in range(A):
                t = nxt[s, a]
                q = reward[t] + (0.0 if terminal[t] else gamma * V[t])
                if wind > 0.0:
                    w = wind_nxt[s, a]
                    qw = reward[w] + (0.0 if terminal[w] else gamma * V[w])
                    q = (1.0 - wind) * q + wind * qw
                if q > best:
                    best = q
            d = abs(best - V[s])
            if d > diff:
                diff = d
            V[s] = best  # Gauss-Seidel: converges to the same fixed point, faster
        if diff < tol:
            return it + 1
    return max_iter


@dataclass(frozen=True)
class FarmingResult:
    farmable: bool
    """True when some greedy policy of the optimal Q can stay away from the goal forever."""
    trap: np.ndarray
    """The states (robot state ids) such a policy can stay in; empty when not farmable."""
    V: np.ndarray
    sweeps: int


def shaped_q(robot: DiscreteRobot, goal_cell: int, bonus: np.ndarray, step_reward: float,
             goal_reward: float, gamma: float, wind: float = 0.0, tol: float = 1e-10,
             max_iter: int = 1_000_000, V0: np.ndarray | None = None,
             start_state: int | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """(Q*, V*, sweeps) of the task shaped by the per-state ``bonus`` (mode PSEUDO).

    With ``start_state``, only the states reachable from it (by any action, with or
    without wind) are solved; Q and V elsewhere are then meaningless."""
    if not 0.0 <= gamma < 1.0:
        raise InvalidParameterError(f"the exact farming check needs gamma in [0, 1), got {gamma}")
    if not 0.0 <= wind <= 1.0:
        raise InvalidParameterError(f"wind must be in [0, 1], got {wind}")
    nxt = np.ascontiguousarray(robot.next_state, dtype=np.int64)
    wnxt = np.ascontiguousarray(robot.wind_state[nxt], dtype=np.int64)
    terminal = robot.label == goal_cell
    reward = step_reward + np.asarray(bonus, dtype=np.float64) + np.where(terminal, goal_reward, 0.0)
    V = np.zeros(robot.n_states) if V0 is None else np.array(V0, dtype=np.float64)
    states = (np.arange(robot.n_states) if start_state is None
              else np.flatnonzero(reachable(robot, start_state, wind))).astype(np.int64)
    sweeps = _value_iteration(nxt, wnxt, reward, terminal, float(gamma), float(wind), tol, max_iter, V, states)
    cont = np.where(terminal, 0.0, gamma * V)
    Q = reward[nxt] + cont[nxt]
    if wind > 0.0:
        Q = (1.0 - wind) * Q + wind * (reward[wnxt] + cont[wnxt])
    return Q, V, sweeps


def reachable(robot: DiscreteRobot, start_state: int, wind: float = 0.0) -> np.ndarray:
    """Boolean mask of the states reachable from ``start_state`` by any actions (and wind)."""
    succ = robot.next_state if wind <= 0.0 else np.hstack([robot.next_state, robot.wind_state[robot.next_state]])
    seen = np.zeros(robot.n_states, bool)
    seen[start_state] = True
    frontier = np.array([start_state])
    while len(frontier):
        nxt = np.unique(succ[frontier].reshape(-1))
        nxt = nxt[~seen[nxt]]
        seen[nxt] = True
        frontier = nxt
    return seen


def trap_states(robot: DiscreteRobot, start_state: int, goal_cell: int, Q: np.ndarray,
                wind: float = 0.0, tie_tol: float = TIE_TOL) -> np.ndarray:
    """The largest set of non-goal states, reachable from the start by greedy actions, in
    which a greedy policy (any tie-break) can stay forever. Empty: every greedy policy
    reaches the goal with probability 1."""
    scale = max(1.0, float(np.abs(Q).max()))
    greedy = Q >= Q.max(axis=1, keepdims=True) - tie_tol * scale  # [S, A]
    succ = [robot.next_state]
    if wind > 0.0:
        succ.append(robot.wind_state[robot.next_state])
    goal = robot.label == goal_cell
    # states reachable from the start under some greedy policy (wind outcomes included)
    seen = np.zeros(robot.n_states, bool)
    seen[start_state] = True
    frontier = np.array([start_state])
    while len(frontier):
        frontier = frontier[~goal[frontier]]
        nxt = np.concatenate([t[frontier][greedy[frontier]] for t in succ]) if len(frontier) else frontier
        nxt = np.unique(nxt)
        nxt = nxt[~seen[nxt]]
        seen[nxt] = True
        frontier = nxt
    # greatest fixpoint: keep states with a greedy action all of whose outcomes stay inside
    inside = seen & ~goal
    while True:
        stays = greedy.copy()
        for t in succ:
            stays &= inside[t]
        keep = inside & stays.any(axis=1)
        if (keep == inside).all():
            break
        inside = keep
    return np.flatnonzero(inside)


def analyse(robot: DiscreteRobot, start_state: int, goal_cell: int, bonus: np.ndarray,
            step_reward: float, goal_reward: float, gamma: float, wind: float = 0.0,
            V0: np.ndarray | None = None) -> FarmingResult:
    """Solve the shaped task and say whether its greedy policy can be trapped."""
    Q, V, sweeps = shaped_q(robot, goal_cell, bonus, step_reward, goal_reward, gamma, wind, V0=V0,
                            start_state=start_state)
    trap = trap_states(robot, start_state, goal_cell, Q, wind)
    return FarmingResult(len(trap) > 0, trap, V, sweeps)


def _bonus_per_k(robot: DiscreteRobot, trajs: Sequence[Trajectory], method: str = "pseudo") -> np.ndarray:
    """The method's bonus per unit of K at every state: the paper's index i, or a plugin's own
    (``Method.bonus_per_k``)."""
    per_k = methods.get(method).bonus_per_k
    if per_k is not None:
        return per_k(robot, list(trajs))
    eff, _ = rewards.union_index(robot, list(trajs))
    return eff


def _old_bound(robot: DiscreteRobot, trajs: Sequence[Trajectory], step_reward: float, method: str) -> float:
    """The K at and above which standing still on the largest bonus pays: -step_reward/n for the
    paper's pseudo reward, -step_reward/(the largest bonus per K) for a plugin's."""
    m = methods.get(method)
    if m.bonus_per_k is not None:
        return methods.bonus_bound(m, robot, trajs, step_reward)
    return rewards.farming_bound(step_reward, trajs)


def is_farmable(robot: DiscreteRobot, start_state: int, goal_cell: int,
                trajs: Trajectory | Sequence[Trajectory], K: float, config, wind: float = 0.0,
                method: str = "pseudo") -> bool:
    """Exact: does ``method``'s state bonus (the pseudo reward) with this K make some optimal
    greedy policy loop?"""
    trajs = rewards.as_list(trajs)
    if config.gamma >= 1.0:
        # undiscounted: every step pays step_reward + bonus < 0 below the old bound, so any
        # loop costs and the old bound is exact
        if methods.get(method).bonus_per_k is not None:
            return K >= _old_bound(robot, trajs, config.step_reward, method)
        return config.step_reward + rewards.longest_n(trajs) * K >= 0
    res = analyse(robot, start_state, goal_cell, K * _bonus_per_k(robot, trajs, method),
                  config.step_reward, config.goal_reward, config.gamma, wind)
    return res.farmable


@dataclass(frozen=True)
class SafeK:
    k: float
    """The largest K found safe (every K checked in [0, k] was not farmable)."""
    old_bound: float
    """-step_reward / n, at and above which the old check refuses."""
    monotone: bool
    """False when a K below an accepted one was found farmable (then ``k`` was lowered)."""
    evaluations: int


def largest_safe_k(robot: DiscreteRobot, start_state: int, goal_cell: int,
                   trajs: Trajectory | Sequence[Trajectory], config, wind: float = 0.0,
                   rel_tol: float = 1e-3, grid: int = 8, method: str = "pseudo") -> SafeK:
    """The largest safe K below the old bound, by bisection, then checked on a grid.

    Farmability need not be monotone in K (a larger K changes which detour pays), so after
    bisection ``grid`` evenly spaced Ks in (0, k] are checked too; if one is farmable, the
    search restarts below it and ``monotone`` is False. Raises when even K = 0 does not
    lead to the goal (the goal cannot be reached: not a farming problem).
    """
    trajs = rewards.as_list(trajs)
    old = _old_bound(robot, trajs, config.step_reward, method)
    per_k = _bonus_per_k(robot, trajs, method)
    evals = 0
    V = None

    def farmable(k: float) -> bool:
        nonlocal evals, V
        evals += 1
        if config.gamma >= 1.0:
            if methods.get(method).bonus_per_k is not None:
                return k >= old
            return config.step_reward + rewards.longest_n(trajs) * k >= 0
        res = analyse(robot, start_state, goal_cell, k * per_k, config.step_reward,
                      config.goal_reward, config.gamma, wind, V0=V)
        V = res.V
        return res.farmable

    if farmable(0.0):
        raise InvalidParameterError(
            f"robot {robot.name} cannot reach the goal with probability 1 even without pseudo rewards"
        )
    monotone = True
    hi = old  # the old check refuses K >= old bound regardless
    while True:
        lo = 0.0
        if not farmable(hi * (1 - 1e-12)):
            lo = hi * (1 - 1e-12)
        else:
            while hi - lo > rel_tol * old:
                mid = 0.5 * (lo + hi)
                if farmable(mid):
                    hi = mid
                else:
                    lo = mid
        bad = [k for k in np.linspace(0.0, lo, grid + 1)[1:-1] if farmable(float(k))]
        if not bad:
            return SafeK(lo, old, monotone, evals)
        monotone = False
        hi = float(bad[0])


def auto_k(robot: DiscreteRobot, start_state: int, goal_cell: int,
           trajs: Trajectory | Sequence[Trajectory], config, wind: float = 0.0, method: str = "pseudo") -> float:
    """K='auto' for pseudo/mapping, verified safe by VI: half the old bound when value
    iteration finds it safe (one solve, the usual case); otherwise min(half the old bound,
    SAFETY_FRACTION x the largest safe K), halved until VI accepts it (when not monotone)."""
    trajs = rewards.as_list(trajs)
    old = _old_bound(robot, trajs, config.step_reward, method)
    if not np.isfinite(old):  # a plugin's bonus that pays nowhere: nothing to farm, nothing to gain
        return 0.0
    half = methods.HALF_BOUND * old
    if not is_farmable(robot, start_state, goal_cell, trajs, half, config, wind, method):
        return half
    safe = largest_safe_k(robot, start_state, goal_cell, trajs, config, wind, method=method)
    k = min(half, SAFETY_FRACTION * safe.k)
    for _ in range(60):
        if not is_farmable(robot, start_state, goal_cell, trajs, k, config, wind, method):
            return k
        k *= 0.5
    return 0.0


def check_k(method: str, robot: DiscreteRobot, start_state: int, goal_cell: int,
            trajs: Trajectory | Sequence[Trajectory], K: float | str | None, config,
            wind: float = 0.0) -> float:
    """The K to use for ``method``; raises ``InvalidParameterError`` (one line, naming the
    largest safe K) when the pseudo reward with this K can be farmed on this task.

    ``K='auto'`` (or None) for a farmable method (the registry's ``farmable``: pseudo,
    mapping) returns :func:`auto_k`. The others are never farmable (see the module
    docstring) and get their own ``Method.resolve_k``.
    """
    m = methods.get(method)
    trajs = rewards.as_list(trajs) if m.uses_trajectory else []
    k = m.resolve_k(K, config.step_reward, trajs)  # the same input checks for every method
    if not m.farmable:
        return k
    if K is None or K == "auto":
        return auto_k(robot, start_state, goal_cell, trajs, config, wind, m.name)
    old = _old_bound(robot, trajs, config.step_reward, m.name)
    if k >= old or is_farmable(robot, start_state, goal_cell, trajs, k, config, wind, m.name):
        safe = largest_safe_k(robot, start_state, goal_cell, trajs, config, wind, method=m.name)
        raise InvalidParameterError(
            f"K={k:g} can be farmed on this task (gamma={config.gamma:g}, wind={wind:g}): "
            f"the largest safe K is {safe.k:.6g} (old bound -step_reward/n = {old:.6g})"
        )
    return k


def self_loops(robot: DiscreteRobot, goal_cell: int, wind: float = 0.0) -> np.ndarray:
    """The states (not labelled the goal) at which some move leaves the state unchanged: a
    blocked move, next_state[s, a] == s, or with wind a move the push brings back."""
    nxt = robot.next_state
    same = nxt == np.arange(robot.n_states)[:, None]
    if wind > 0.0:
        same |= robot.wind_state[nxt] == np.arange(robot.n_states)[:, None]
    return np.flatnonzero(same.any(axis=1) & (robot.label != goal_cell))


def self_loop_shaping(shaping: Shaping, states: np.ndarray, gamma: float) -> np.ndarray:
    """The shaping term the kernel (``sarsa.shaping_term``) pays for repeating a self-loop at each of
    ``states``, after the learner arrived there: a once-per-episode bonus already paid, the best
    bonus of the episode at least the state's own."""
    sh = shaping
    n_ids = int(sh.traj_index.max()) + 1 if len(sh.traj_index) else 1
    paid = np.zeros(max(n_ids, 1), np.int64)  # episode 0: every cell counts as paid this episode
    out = np.empty(len(states))
    for k, s in enumerate(states):
        s = int(s)
        out[k], _ = kernel_shaping(sh.mode, s, s, False, sh.bonus, sh.traj_index, sh.phi, float(gamma), paid, 0,
                                   float(sh.bonus[s]))
    return out


def check_self_loops(method: str, robot: DiscreteRobot, goal_cell: int, shaping: Shaping | None, config,
                     wind: float = 0.0) -> None:
    """Raise ``InvalidParameterError`` when ``method``'s shaping pays a learner for a move that
    leaves its state unchanged: a positive shaping term with which the step costs nothing or
    earns (step_reward + term >= 0). Every method is checked, as the kernel pays it; a learner
    whose Q starts at 0 would repeat such a move for ever."""
    if shaping is None:
        return
    states = self_loops(robot, goal_cell, wind)
    if not len(states):
        return
    term = self_loop_shaping(shaping, states, config.gamma)
    bad = (term > 0.0) & (config.step_reward + term >= 0.0)
    if bad.any():
        k = int(np.argmax(np.where(bad, term, -np.inf)))
        x, y = robot.layout.xy(int(robot.label[states[k]]) % robot.layout.n_cells)
        raise InvalidParameterError(
            f"method {method!r} pays a learner for a move that leaves its state unchanged at {int(bad.sum())} "
            f"states (at cell ({x},{y}): step reward {config.step_reward:g} + shaping {term[k]:.4g} >= 0); "
            f"bound its potential (potentials.bounded) or lower K"
        )
