"""What a transfer method is: one :class:`Method`, the entry of the registry
``armtransfer.learning.methods`` (the built-in methods and those of installed plugins,
``armtransfer.learning.plugins``).
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from armtransfer.errors import InvalidParameterError
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.rewards import farming_bound
from armtransfer.learning.shaping import Shaping
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.robot import DiscreteRobot

HALF_BOUND = 0.5
"""K='auto' of a method without its own ``auto_k`` starts at this fraction of the farming
bound -step_reward/n (a farmable method's is then verified by value iteration, see
``armtransfer.learning.farming``)."""

DEFAULT_GAMMA = LearnerConfig().gamma
"""The discount :func:`build_shaping` bounds potentials for unless told the learner's."""

MAX_K = 1e6
"""The largest K a run takes, in units of reward (the step reward is -1 by default): far past
any useful shaping, and small enough that K times any bounded potential stays finite."""


def check_k(K: object) -> float | str:
    """``K`` as a run takes it: 'auto', or a real number (numpy's too) in [0, :data:`MAX_K`];
    anything else is one line."""
    if isinstance(K, str) and K == "auto":
        return K
    if isinstance(K, (bool, np.bool_)) or not isinstance(K, numbers.Real) or not np.isfinite(float(K)) \
            or not 0 <= float(K) <= MAX_K:
        raise InvalidParameterError(f"K must be 'auto' or a number in [0, {MAX_K:g}], got {K!r}")
    return float(K)


Builder = Callable[[DiscreteRobot, list[Trajectory], float, float], Shaping]
"""(robot, trajectories, K, beta) -> the shaping arrays."""


@dataclass(frozen=True)
class Method:
    name: str
    description: str
    """One line, for --help and reports."""
    paper: bool
    """The paper's own method (section III), not one added here."""
    build: Builder | None = None
    """The shaping arrays; None for a method without shaping (``none``)."""
    auto_k: float | None = None
    """K for ``K='auto'`` in units of -step_reward; None: half the farming bound -step_reward/n.
    Chosen on held-out start/goal pairs by research/select_defaults.py, never on Table I."""
    farmable: bool = False
    """A state bonus that a loop could collect forever: K is checked against farming."""
    macros: bool = False
    """Runs the action sequence mapping's macros (needs exactly one trajectory)."""
    chooses: bool = False
    """Changes how the learner chooses actions, not only its rewards (so no reward wrapper can
    give it to another learner)."""
    baselines: tuple[str, ...] = ()
    """The methods this one's gain is measured against: each shares its learner (the same
    updates, the same way of choosing actions) and is told less; the first is told nothing
    (no transfer). Empty for a method that is itself no transfer (``none``, ``plan``)."""
    is_baseline: bool = False
    """Exists to be compared against (run beside the methods naming it in ``baselines``), not a
    transfer method of its own: the controls (shuffled and random trajectories) and the paper's
    tables leave it out."""
    uses_trajectory: bool = True
    """Reads the transferred trajectories; False for a shaped method that transfers nothing
    (``plan``), which is then built without them."""
    bonus_per_k: Callable[[DiscreteRobot, list[Trajectory]], np.ndarray] | None = None
    """A farmable method's bonus of every state per unit of K, for the farming checks; None: the
    paper's index i of the trajectory cell a state is on (``rewards.union_index``)."""
    origin: str = "armtransfer"
    """Where the method comes from: ``armtransfer`` for a built-in one, else the plugin (its
    distribution and entry point) or ``registered at run time``."""

    @property
    def shaped(self) -> bool:
        return self.build is not None

    @property
    def baseline(self) -> str | None:
        """The no-transfer method that shares this one's learner (None: it is one itself)."""
        return self.baselines[0] if self.baselines else None

    def resolve_k(self, K: float | str | None, step_reward: float, trajs: Sequence[Trajectory]) -> float:
        """The K this method uses: ``K`` itself, or its automatic K for 'auto'/None."""
        if K is None or K == "auto":
            if step_reward >= 0:
                raise InvalidParameterError("K='auto' needs a negative step reward (it is scaled by -step_reward)")
            if self.auto_k is not None:
                return self.auto_k * -step_reward
            return HALF_BOUND * farming_bound(step_reward, trajs)
        k = check_k(K)
        assert isinstance(k, float)
        return k
