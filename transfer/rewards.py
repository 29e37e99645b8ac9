"""Pseudo rewards from a transferred trajectory, and the shaping methods beside them.

``pseudo`` is the paper's (section III.B): r'(s') = i*K when the robot reaches a state
labelled with the i-th trajectory cell s_ti (i = 1..n; when a cell occurs more than once
in the trajectory the largest i counts, so a loop is bypassed towards the goal).

A plain state bonus can be farmed: if ``step_reward + n*K >= 0``, standing on s_tn (for
instance by bumping a wall) pays at least as much as moving on, and an agent can loop
there forever. :func:`build` refuses that configuration for ``pseudo``.

The other methods (``first-visit``, ``potential``, ``progress``) are new here, not the
paper's; see ``transfer.methods`` for what each does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tasks.errors import InvalidParameterError
from tasks.robot import DiscreteRobot
from transfer import sarsa
from transfer.trajectory import Trajectory

K_FRACTION = 0.5
"""With ``K='auto'``, K is this fraction of the farming bound -step_reward / n."""


@dataclass(frozen=True)
class Shaping:
    """Per-state arrays the learner's kernel reads."""

    mode: int
    bonus: np.ndarray  # float64 [S]: i*K on states labelled s_ti
    traj_index: np.ndarray  # int64 [S]: i for states labelled s_ti, -1 elsewhere
    phi: np.ndarray  # float64 [S]: potential, for potential-based methods
    K: float = 0.0

    @staticmethod
    def potential(phi: np.ndarray, K: float = 0.0) -> "Shaping":
        """Potential-based shaping F = gamma * phi(s') - phi(s) with the given potential."""
        n = len(phi)
        return Shaping(sarsa.MODE_POTENTIAL, np.zeros(n), np.full(n, -1, np.int64),
                       np.asarray(phi, dtype=np.float64), K)

    @staticmethod
    def none(n_states: int) -> "Shaping":
        return Shaping(
            sarsa.MODE_NONE, np.zeros(n_states), np.full(n_states, -1, np.int64), np.zeros(n_states)
        )


def farming_bound(step_reward: float, traj: Trajectory) -> float:
    """The K at and above which ``pseudo`` can be farmed: -step_reward / n."""
    n = max(traj.n, 1)
    return -step_reward / n


def resolve_k(K: float | str | None, step_reward: float, traj: Trajectory) -> float:
    if K is None or K == "auto":
        if step_reward >= 0:
            raise InvalidParameterError(
                "K='auto' needs a negative step reward (it is a fraction of -step_reward/n)"
            )
        return K_FRACTION * farming_bound(step_reward, traj)
    K = float(K)
    if not np.isfinite(K) or K < 0:
        raise InvalidParameterError(f"K must be a non-negative number, got {K}")
    return K


def trajectory_index(robot: DiscreteRobot, traj: Trajectory) -> np.ndarray:
    """For every robot state, the largest i >= 1 with label == s_ti (-1 when none)."""
    index_of_cell: dict[int, int] = {}
    for i, cell in enumerate(traj.cells):
        if i >= 1:
            index_of_cell[cell] = i  # later occurrences overwrite earlier ones
    index = np.full(robot.n_states, -1, np.int64)
    for cell, i in index_of_cell.items():
        index[robot.label == cell] = i
    return index


def build(
    method: str,
    robot: DiscreteRobot,
    traj: Trajectory,
    K: float | str | None,
    step_reward: float,
    gamma: float,
) -> Shaping:
    """The shaping arrays of ``method`` for ``robot`` from trajectory ``traj``."""
    k = resolve_k(K, step_reward, traj)
    index = trajectory_index(robot, traj)
    bonus = np.where(index > 0, index * k, 0.0).astype(np.float64)
    zeros = np.zeros(robot.n_states)
    if method in ("pseudo", "mapping"):
        if step_reward + traj.n * k >= 0:
            raise InvalidParameterError(
                f"K={k:g} can be farmed: step reward {step_reward:g} + largest pseudo reward "
                f"n*K = {traj.n}*{k:g} >= 0; use K < {farming_bound(step_reward, traj):.6g} "
                f"(-step_reward/n) or the method 'first-visit'"
            )
        return Shaping(sarsa.MODE_PSEUDO, bonus, index, zeros, k)
    if method == "first-visit":
        return Shaping(sarsa.MODE_FIRST_VISIT, bonus, index, zeros, k)
    if method == "progress":
        return Shaping(sarsa.MODE_PROGRESS, bonus, index, zeros, k)
    if method == "potential":
        return Shaping(sarsa.MODE_POTENTIAL, zeros, index, bonus.copy(), k)
    raise InvalidParameterError(f"no shaping for method {method!r}")
