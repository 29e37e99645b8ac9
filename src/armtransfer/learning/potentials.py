"""State potentials for potential-based shaping (Ng, Harada and Russell, 1999).

With a potential Phi over the robot's states, the shaping term of a move s -> s' is
F = gamma * Phi(s') - Phi(s) (Phi of a terminal state is 0). Summed over an episode it
telescopes to -Phi(s_0), so the optimal policy is unchanged; learning with it is the same
as starting from Q(s, a) = Phi(s) (Wiewiora, 2003).

``dense`` (new here): a potential over the shared workspace the robot perceives,

    Phi(s) = K * (P * (i*(s) / n - 1) - beta * d(s)),   P = 20

where d(s) is the Euclidean distance, in cells, between the robot's label and the nearest
trajectory cell, i*(s) the largest index among the trajectory cells at that distance, and n
the index of the last trajectory state, so i*/n is the fraction of the trajectory done. Two
parameters: ``K``, the scale, and ``beta``, the progress units lost per cell of distance
from the trajectory. P fixes the range of the progress term whatever the trajectory's
length: with K per *index* instead, a long wandering trajectory (an arm's learned path of a
hundred steps) makes the potential so steep that a cell across a wall from the end of the
trajectory becomes a trap the learner needs millions of steps to leave. Phi <= 0 and rises
towards the goal. It uses distances between labels only, never the map's walls or
connectivity, which the robot does not know; so across a wall it can still point the wrong
way, only less steeply.

A bounded potential (:func:`bounded`, what every potential-based method runs on): with
Phi(s) < 0 a move that does not raise the potential still earns the discount's leak,
gamma * Phi(s') - Phi(s) = (Phi(s') - Phi(s)) + (1 - gamma) |Phi(s')|, so once |Phi| exceeds
-step_reward / (1 - gamma) (100 cells' worth of step cost with gamma = 0.99) a blocked move, a
self-loop, pays more than its step costs and a learner bumps the wall for ever. The negative
part of Phi is therefore squashed, monotonically, into (-B, 0] with
B = LOOP_MARGIN * -step_reward / (1 - gamma), so a self-loop, or any move between two states
of equal potential, costs at least (1 - LOOP_MARGIN) of a step.

``oracle`` (a bound, not a transfer method): Phi = V*, the optimal value of the unshaped task,
step_reward * (1 - gamma^d) / (1 - gamma) with d the robot's true shortest-path distance to the
goal in moves. Ng, Harada and Russell's best potential: it uses the map, which no robot has,
and bounds what any state potential can do for this learner. Unlike -K * d (the earlier oracle,
whose self-loops paid once d > -step_reward / ((1 - gamma) K): 185 states of fine task 4 failed
``farming.check_self_loops``), |V*| < -step_reward / (1 - gamma), so a self-loop always costs.
"""

from __future__ import annotations

import numpy as np

from armtransfer.worlds.layout import Layout
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning.trajectory import Trajectory

DENSE_K = 4.0
DENSE_BETA = 1.5
PROGRESS_RANGE = 20.0
"""P: the progress term of ``dense`` spans P * K whatever the trajectory's length."""
LOOP_MARGIN = 0.35
"""The bound B of :func:`bounded` as a fraction of -step_reward / (1 - gamma): a self-loop costs
at least (1 - LOOP_MARGIN) of a step. Chosen on held-out start/goal pairs of five robot pairs
(``research/select_defaults.py --method dense-bound --pairs 8 --trials 10``: the smallest mean
first exposure of the worst pair, 133x the optimal distance against 2,352x unbounded; 0.5 gave
148x, 0.25 146x, 0.75 435x), never on Table I. It costs ``dense`` on the grid robots, where it
did not loop: coarse -> fine 57x against 21x unbounded."""


def bounded(phi: np.ndarray, gamma: float, step_reward: float, margin: float = LOOP_MARGIN) -> np.ndarray:
    """``phi`` with its negative part squashed into (-B, 0], B = margin * -step_reward / (1 - gamma):
    -B * tanh(-phi / B), which keeps the order of the states and phi's slope near 0, so that no
    move that leaves the state unchanged can pay (see the module docstring).

    The potential is bounded rather than the shaping of self-loops dropped, because a self-loop
    is not the only move that earns the discount's leak (a move between two states of equal
    potential earns it too) and a bounded potential is still a potential, so Ng, Harada and
    Russell's guarantee (the optimal policy is unchanged) holds as before, with wind too.
    Non-negative potentials are left as they are (their leak is a cost); with gamma = 1 there is
    no leak and nothing to bound."""
    phi = np.asarray(phi, dtype=np.float64)
    if gamma >= 1.0:
        return phi.copy()
    b = margin * -step_reward / (1.0 - gamma)
    if b <= 0.0:
        return np.maximum(phi, 0.0)
    return np.where(phi < 0.0, -b * np.tanh(-np.minimum(phi, 0.0) / b), phi)


SQUASH_SHARE = 0.25
"""A potential of one's own below -B on more than this share of the states is said to be
squashed (:func:`notes`): the bound flattens its differences there."""


def bound(gamma: float, step_reward: float, margin: float = LOOP_MARGIN) -> float:
    """B of :func:`bounded`: 35 with the default step reward -1 and discount 0.99 (inf with gamma 1)."""
    return float("inf") if gamma >= 1.0 else margin * -step_reward / (1.0 - gamma)


def notes(name: str, phi: np.ndarray, at_goal: np.ndarray, gamma: float, step_reward: float,
          share: float = SQUASH_SHARE) -> list[str]:
    """What happened to method ``name``'s potential ``phi`` (before :func:`bounded`), one line
    each: below -B on more than ``share`` of the states (squashed); the same on every state
    (it shapes nothing); not 0 on the goal's states ``at_goal`` (a bool mask; the kernel counts
    the goal as 0, so entering it pays -phi(s) on top of the step)."""
    phi = np.asarray(phi, dtype=np.float64)
    out = []
    b = bound(gamma, step_reward)
    if len(phi) and float(np.ptp(phi)) == 0.0:
        out.append(f"method {name!r}: its potential is {phi[0]:g} on every one of the {len(phi)} states, so it shapes "
                   "nothing (it learns as none)")
    elif np.isfinite(b) and (low := float(np.mean(phi < -b))) > share:
        out.append(f"method {name!r}: its potential is below -B = -{b:g} on {low:.0%} of the {len(phi)} states, "
                   f"where every potential is squashed into (-B, 0] by -B*tanh(-phi/B), flattening its differences; "
                   "scale it down (docs/extending.md)")
    if at_goal.any() and float(np.max(np.abs(phi[at_goal]))) > 1e-9:
        value = float(phi[at_goal][np.argmax(np.abs(phi[at_goal]))])
        out.append(f"method {name!r}: its potential is {value:g}, not 0, at the goal, which the kernel counts as 0: "
                   f"every move into the goal is shaped by about {-value:g}; subtract the goal's value "
                   "(docs/extending.md)")
    return out


def _label_xy(robot: DiscreteRobot, layout: Layout) -> np.ndarray:
    return layout.xy_of(robot.label % layout.n_cells).astype(np.float64)  # a voxel label: the cell under it


def dense(
    robot: DiscreteRobot,
    traj: Trajectory,
    K: float = DENSE_K,
    beta: float = DENSE_BETA,
    layout: Layout | None = None,
) -> np.ndarray:
    """The ``dense`` potential of every robot state (float64 [n_states])."""
    layout = layout or robot.layout
    p = _label_xy(robot, layout)
    t = np.array([layout.xy(c % layout.n_cells) for c in traj.cells], dtype=np.float64)
    n = len(t) - 1
    best_d = np.full(len(p), np.inf)
    best_i = np.zeros(len(p))
    for i in range(len(t)):  # one pass per trajectory cell keeps memory at O(states)
        d = np.sqrt(((p - t[i]) ** 2).sum(axis=1))
        closer = d < best_d - 1e-9
        tie = np.abs(d - best_d) <= 1e-9
        best_i = np.where(closer | tie, i, best_i)
        best_d = np.where(closer, d, best_d)
    return K * (PROGRESS_RANGE * (best_i / max(n, 1) - 1.0) - beta * best_d)


def oracle(robot: DiscreteRobot, goal_cell: int, gamma: float, step_reward: float) -> np.ndarray:
    """The optimal value of each state without shaping, step_reward * (1 - gamma^d) / (1 - gamma)
    (d: its breadth-first distance to the goal in moves; unreachable: one more than the largest);
    with gamma = 1, step_reward * d."""
    d = goal_distances(robot, goal_cell).astype(np.float64)
    if gamma >= 1.0:
        return step_reward * d
    return step_reward * (1.0 - gamma ** d) / (1.0 - gamma)


def goal_distances(robot: DiscreteRobot, goal_cell: int) -> np.ndarray:
    """Each state's breadth-first distance to the goal in moves (unreachable: the largest + 1)."""
    n = robot.n_states
    dist = np.full(n, -1, dtype=np.int64)
    # reverse edges once, then breadth-first search from every goal state
    src = np.repeat(np.arange(n), robot.n_actions)
    dst = robot.next_state.reshape(-1).astype(np.int64)
    order = np.argsort(dst, kind="stable")
    src, dst = src[order], dst[order]
    starts = np.searchsorted(dst, np.arange(n + 1))
    frontier = np.flatnonzero(robot.label == goal_cell)
    dist[frontier] = 0
    level = 0
    while len(frontier):
        level += 1
        preds = np.concatenate([src[starts[t]:starts[t + 1]] for t in frontier])
        preds = np.unique(preds[dist[preds] < 0])
        dist[preds] = level
        frontier = preds
    dist[dist < 0] = level
    return dist
