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

from collections.abc import Sequence
import numpy as np

from armtransfer.errors import InvalidParameterError
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning import potentials
from armtransfer.learning import shaping as modes
from armtransfer.learning.shaping import Shaping
from armtransfer.learning.trajectory import Trajectory

K_FRACTION = 0.5
"""With ``K='auto'``, K is this fraction of the farming bound -step_reward / n."""


# K='auto', per method, in units of -step_reward. Chosen on held-out start/goal pairs, not on
# the Table I tasks (scripts/select_defaults.py prints the comparison).
AUTO_K = {"first-visit": 10.0, "progress": 30.0, "potential": 3.0, "dense": potentials.DENSE_K}


def _as_list(trajs: Trajectory | Sequence[Trajectory]) -> list[Trajectory]:
    out = [trajs] if isinstance(trajs, Trajectory) else list(trajs)
    if not out:
        raise InvalidParameterError("a transfer method needs at least one trajectory")
    return out


def longest_n(trajs: Trajectory | Sequence[Trajectory]) -> int:
    """N, the largest index n over the trajectories: pseudo rewards go up to N*K."""
    return max(max(t.n, 1) for t in _as_list(trajs))


def farming_bound(step_reward: float, trajs: Trajectory | Sequence[Trajectory]) -> float:
    """The K at and above which ``pseudo`` can be farmed: -step_reward / N."""
    return -step_reward / longest_n(trajs)


def resolve_k(
    K: float | str | None, step_reward: float, trajs: Trajectory | Sequence[Trajectory], method: str = "pseudo"
) -> float:
    if K is None or K == "auto":
        if step_reward >= 0:
            raise InvalidParameterError(
                "K='auto' needs a negative step reward (it is scaled by -step_reward)"
            )
        if method in AUTO_K:
            return AUTO_K[method] * -step_reward
        return K_FRACTION * farming_bound(step_reward, trajs)
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


def union_index(robot: DiscreteRobot, trajs: Sequence[Trajectory]) -> tuple[np.ndarray, np.ndarray]:
    """(effective index, cell id) of every state over several trajectories.

    Each trajectory's index is taken as a fraction of its length, i/n, and scaled by the
    longest N, so one trajectory gives exactly its own i. A state on several trajectories
    takes the largest. The id numbers the distinct trajectory cells 1, 2, ... (-1: none),
    for methods that pay each cell once."""
    N = longest_n(trajs)
    eff = np.zeros(robot.n_states)
    for traj in trajs:
        idx = trajectory_index(robot, traj)
        eff = np.maximum(eff, np.where(idx > 0, idx * (N / max(traj.n, 1)), 0.0))
    on = eff > 0
    ids = np.full(robot.n_states, -1, np.int64)
    _, inverse = np.unique(robot.label[on], return_inverse=True)
    ids[on] = inverse + 1
    return eff, ids


def build(
    method: str,
    robot: DiscreteRobot,
    traj: Trajectory | Sequence[Trajectory],
    K: float | str | None,
    step_reward: float,
    gamma: float,
    beta: float = potentials.DENSE_BETA,
) -> Shaping:
    """The shaping arrays of ``method`` for ``robot`` from one or several trajectories."""
    trajs = _as_list(traj)
    k = resolve_k(K, step_reward, trajs, method)
    eff, ids = union_index(robot, trajs)
    bonus = (eff * k).astype(np.float64)
    zeros = np.zeros(robot.n_states)
    if method in ("pseudo", "mapping"):
        N = longest_n(trajs)
        if step_reward + N * k >= 0:
            raise InvalidParameterError(
                f"K={k:g} can be farmed: step reward {step_reward:g} + largest pseudo reward "
                f"n*K = {N}*{k:g} >= 0; use K < {farming_bound(step_reward, trajs):.6g} "
                f"(-step_reward/n) or the method 'first-visit'"
            )
        return Shaping(modes.MODE_PSEUDO, bonus, ids, zeros, k)
    if method == "first-visit":
        return Shaping(modes.MODE_FIRST_VISIT, bonus, ids, zeros, k)
    if method == "progress":
        return Shaping(modes.MODE_PROGRESS, bonus, ids, zeros, k)
    if method == "potential":
        return Shaping(modes.MODE_POTENTIAL, zeros, ids, bonus.copy(), k)
    if method == "dense":
        if not (np.isfinite(beta) and beta >= 0):
            raise InvalidParameterError(f"beta must be a non-negative number, got {beta}")
        phi = np.max([potentials.dense(robot, t, k, beta) for t in trajs], axis=0)
        return Shaping(modes.MODE_POTENTIAL, zeros, ids, phi, k)
    raise InvalidParameterError(f"no shaping for method {method!r}")
