"""Which engine learns a run: the one place that chooses it from the learner and the target's state.

Three engines learn on robot 2: ``tabular``, the compiled SARSA(lambda) kernel on the target's
table of states (``learning.sarsa``); ``continuous``, the linear SARSA(lambda) learner over tile
coding on the arm's joint configuration (``learning.linear``); and ``outside``, a learner of the
registry from outside the package, on the target's Gymnasium environment through the harness
(``experiments.learner_trial``). ``armtransfer.transfer``, the benchmark and sweeps ask
:func:`engine_of` and run what it names; a pairing no engine runs is refused here, in one line.
"""

from __future__ import annotations

from armtransfer.errors import InvalidParameterError
from armtransfer.learning.learner_names import SARSA

TABULAR = "tabular"
CONTINUOUS = "continuous"
OUTSIDE = "outside"
ENGINES = (TABULAR, CONTINUOUS, OUTSIDE)

STATES = ("discrete", "continuous")
"""How the target robot's state is known: its table of states, or its joint configuration."""


def engine_of(learner: str, state: str = "discrete", subject: str = "the target is") -> str:
    """The engine that runs ``learner`` on a target whose state is ``state`` (:data:`STATES`).
    The built-in learner runs on either; an outside learner learns on a discrete target only,
    and on a continuous one is refused in one line (``subject`` says what has that target)."""
    if state not in STATES:
        raise InvalidParameterError(f"unknown state {state!r}; valid states: {', '.join(STATES)}")
    if learner == SARSA:
        return CONTINUOUS if state == "continuous" else TABULAR
    if state == "continuous":
        raise InvalidParameterError(f"learner {learner!r} learns on a discrete target; {subject} a continuous one; "
                                    f"valid learners for it: {SARSA}")
    return OUTSIDE
