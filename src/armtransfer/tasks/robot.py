"""A discrete robot: the plain arrays every learner in ``src/armtransfer/learning/`` runs on.

A robot is a deterministic MDP over its *own* states (grid cells for the paper's robots,
joint-lattice points or canonical configurations for arms) plus a map from each state to a
*label*, the shared workspace cell it occupies. Robots never see each other's states, only
labels: that is how a trajectory of one robot becomes a reward for another.

    next_state[s, a]  the state reached by action a from s (s itself when the move is blocked)
    wind_state[s]     the state the wind pushes s to (one cell towards +x; s when blocked)
    label[s]          the shared cell id of state s

Start and goal of a task are shared cells; a robot starts in ``start_state(cell)`` and the
goal is reached when ``label[s] == goal``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armtransfer.errors import InvalidCellError
from armtransfer.ik.description import ArmDescription
from armtransfer.worlds.layout import ROOMS, Layout


@dataclass(frozen=True, eq=False)
class DiscreteRobot:
    name: str
    next_state: np.ndarray  # int32 [n_states, n_actions]
    wind_state: np.ndarray  # int32 [n_states]
    label: np.ndarray  # int32 [n_states], shared cell ids
    action_names: tuple[str, ...]
    cell_step: int = 1
    """Nominal cells moved per action, for reports only."""
    canonical: np.ndarray | None = None
    """Optional int32 [n_cells]: the state a robot placed at a cell starts in (-1: none).
    When absent, the first state with that label is used."""
    layout: Layout = ROOMS
    """The layout whose cells the labels number."""
    arm: ArmDescription | None = None
    """For arm robots: the arm, its mount and every state's joint configuration (what a
    physics replay needs); None for grid robots."""

    def __post_init__(self) -> None:
        ns = np.ascontiguousarray(self.next_state, dtype=np.int32)
        ws = np.ascontiguousarray(self.wind_state, dtype=np.int32)
        lb = np.ascontiguousarray(self.label, dtype=np.int32)
        if ns.ndim != 2 or ns.shape[0] == 0 or ns.shape[1] == 0:
            raise ValueError(f"{self.name}: next_state must be a non-empty 2-D table")
        n = ns.shape[0]
        if ws.shape != (n,) or lb.shape != (n,):
            raise ValueError(f"{self.name}: wind_state and label need one entry per state ({n})")
        if ns.min() < 0 or ns.max() >= n or ws.min() < 0 or ws.max() >= n:
            raise ValueError(f"{self.name}: a successor is outside 0..{n - 1}")
        if len(self.action_names) != ns.shape[1]:
            raise ValueError(f"{self.name}: {ns.shape[1]} actions but {len(self.action_names)} names")
        for arr in (ns, ws, lb):
            arr.setflags(write=False)
        object.__setattr__(self, "next_state", ns)
        object.__setattr__(self, "wind_state", ws)
        object.__setattr__(self, "label", lb)
        if self.canonical is not None:
            can = np.ascontiguousarray(self.canonical, dtype=np.int32)
            can.setflags(write=False)
            object.__setattr__(self, "canonical", can)

    @property
    def n_states(self) -> int:
        return int(self.next_state.shape[0])

    @property
    def n_actions(self) -> int:
        return int(self.next_state.shape[1])

    def states_at(self, cell: int) -> np.ndarray:
        """All states whose label is ``cell``."""
        return np.flatnonzero(self.label == cell)

    def start_state(self, cell: int, what: str = "start") -> int:
        """The state this robot starts in when placed at shared ``cell``."""
        if self.canonical is not None and 0 <= cell < len(self.canonical):
            s = int(self.canonical[cell])
            if s >= 0:
                return s
        states = self.states_at(cell)
        if len(states) == 0:
            where = self.layout.xy(cell) if 0 <= cell < self.layout.n_cells else cell
            if self.canonical is not None and len(self.canonical) > self.layout.n_cells:  # voxels: a 3D robot
                raise InvalidCellError(f"robot {self.name} cannot reach the {what} cell {where} with its tool at the "
                                       "table level (level 0 of the 3D workspace); give a finer joint step "
                                       "(joint_step=) or another cell")
            raise InvalidCellError(f"robot {self.name} cannot reach the {what} cell {where}")
        return int(states[0])

    def reachable_from(self, state: int) -> np.ndarray:
        """Boolean mask of the states reachable from ``state`` (ignoring wind)."""
        seen = np.zeros(self.n_states, dtype=bool)
        seen[state] = True
        frontier = np.array([state])
        while len(frontier):
            succ = np.unique(self.next_state[frontier].reshape(-1))
            succ = succ[~seen[succ]]
            seen[succ] = True
            frontier = succ
        return seen

    def distance(self, start: int, goal_cell: int) -> int:
        """The fewest moves from state ``start`` to a state labelled ``goal_cell``."""
        path = self.shortest_path(start, goal_cell)
        if path is None:
            raise InvalidCellError(f"{self.name} cannot reach cell {goal_cell} from state {start}")
        return len(path) - 1

    def shortest_path(self, start: int, goal_cell: int) -> list[tuple[int, int]] | None:
        """Breadth-first shortest path from state ``start`` to any state labelled ``goal_cell``.

        Returns ``[(state, action), ...]`` ending with ``(goal_state, -1)``, or None when the
        goal cannot be reached. Ties go to the lowest action index, so the path is unique.
        """
        parent = np.full(self.n_states, -1, dtype=np.int64)
        parent_action = np.full(self.n_states, -1, dtype=np.int64)
        parent[start] = start
        frontier = [start]
        found = start if self.label[start] == goal_cell else -1
        while frontier and found < 0:
            nxt = []
            for s in frontier:
                for a in range(self.n_actions):
                    t = int(self.next_state[s, a])
                    if parent[t] < 0:
                        parent[t] = s
                        parent_action[t] = a
                        if self.label[t] == goal_cell:
                            found = t
                            break
                        nxt.append(t)
                if found >= 0:
                    break
            frontier = nxt
        if found < 0:
            return None
        path = [(found, -1)]
        s = found
        while s != start:
            path.append((int(parent[s]), int(parent_action[s])))
            s = int(parent[s])
        path.reverse()
        return path


def cell_robot(layout: Layout, levels: int = 1) -> DiscreteRobot:
    """The layout's cells as a robot: each cell a state labelled with itself, one action that
    stays. What a robot known only by its label is paid by (``learning.cells``). ``levels`` > 1:
    the voxels of the 3D workspace (``worlds.voxels``: id = level * n_cells + cell) instead."""
    n = layout.n_cells * max(1, int(levels))
    return DiscreteRobot(name="cells", next_state=np.arange(n, dtype=np.int32)[:, None],
                         wind_state=np.arange(n, dtype=np.int32), label=np.arange(n, dtype=np.int32),
                         action_names=("stay",), layout=layout)
