"""The shaping arrays the learner's kernel reads, and the kernel's shaping modes.

A transfer method (``armtransfer.learning.methods``) turns a robot and its transferred
trajectories into one :class:`Shaping`; the kernel (``armtransfer.learning.sarsa``) adds its
term to every reward. This module is the contract between the two and imports neither.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MODE_NONE = 0
MODE_PSEUDO = 1
"""r'(s') = bonus[s']: the paper's pseudo reward i*K on reaching the i-th trajectory cell."""
MODE_FIRST_VISIT = 2
"""bonus[s'] once per trajectory cell per trial: the first time the cell is reached."""
MODE_POTENTIAL = 3
"""gamma * phi(s') - phi(s), with phi = 0 at the goal."""
MODE_PROGRESS = 4
"""bonus[s'] minus the best bonus reached so far in the episode, when positive."""


@dataclass(frozen=True)
class Shaping:
    """Per-state arrays the learner's kernel reads."""

    mode: int
    bonus: np.ndarray  # float64 [S]: i*K on states labelled s_ti
    traj_index: np.ndarray  # int64 [S]: an id of the trajectory cell a state is on, -1 elsewhere
    phi: np.ndarray  # float64 [S]: potential, for potential-based methods
    K: float = 0.0
    guide: object | None = None
    """Optional ``armtransfer.learning.guide.Guide``: a model of robot 2's own actions that
    breaks the ties of epsilon-greedy (method ``guided``); None: ties are broken at random."""
    notes: tuple[str, ...] = ()
    """What happened to a potential of one's own as it was built (``potentials.notes``: squashed,
    constant, not 0 at the goal), one line each; empty for the built-in methods."""

    @staticmethod
    def potential(phi: np.ndarray, K: float = 0.0) -> "Shaping":
        """Potential-based shaping F = gamma * phi(s') - phi(s) with the given potential."""
        n = len(phi)
        return Shaping(MODE_POTENTIAL, np.zeros(n), np.full(n, -1, np.int64),
                       np.asarray(phi, dtype=np.float64), K)

    @staticmethod
    def none(n_states: int) -> "Shaping":
        return Shaping(MODE_NONE, np.zeros(n_states), np.full(n_states, -1, np.int64), np.zeros(n_states))
