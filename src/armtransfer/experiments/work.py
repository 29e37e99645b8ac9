"""What an engine learns (``experiments.engines``): one method's trials on one case, as values."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learner_names import SARSA
from armtransfer.learning.mapping import DEFAULT_MAX_SPAN


@dataclass(frozen=True)
class Work:
    """What an engine learns: ``trials`` trials of ``method`` by ``learner`` on robot 2
    (``target``, its spec) from ``start`` to ``goal`` ((x, y) cells), numbered from
    ``first_trial`` (their random streams), seeded by ``seed``; ``noise``: a continuous target's
    actuation noise; ``threads``: the tabular kernel's threads (None: one per CPU); ``beta``: the
    dense potential's scale (None: ``potentials.DENSE_BETA``)."""

    method: str
    target: str
    start: tuple[int, int]
    goal: tuple[int, int]
    trials: int
    seed: int
    config: LearnerConfig
    wind: float = 0.0
    K: float | str | None = "auto"
    beta: float | None = None
    first_trial: int = 0
    learner: str = SARSA
    state: str = "discrete"
    noise: float = 0.0
    threads: int | None = None
    on_trial: Callable[[], None] | None = None
    heartbeat: bool = False
    arm: Any = None
    """A continuous arm made and placed over the start already (``armtransfer.transfer``'s, with
    its arm options); None: the continuous engine makes ``target``'s."""
    control: str | None = None
    """A control kind (``learning.controls.CONTROLS``): each trial is paid for its own draw of
    stand-ins for the trajectories (``experiment.run_control``) instead of the trajectories."""
    source: Any = None
    """The source robot (a ``DiscreteRobot``), which walks a ``random`` control's stand-ins."""
    shaping: Any = None
    """The method's shaping made already for the trajectories (``experiment.method_shaping``; its K
    is then not checked again); None: the engine makes it."""
    mapping: Any = None
    """Method ``mapping``'s action sequence mapping (an ``ActionMapping``), whose macros it is
    given; the result's ``learned_mapping`` is it updated from the converged trials. None: no
    macros."""
    max_span: int = DEFAULT_MAX_SPAN
    """The longest target sequence the updated mapping learns for one source action."""
