"""Names of a method run by a learner: ``pseudo`` by the built-in learner, ``pseudo@dqn`` by an
outside one, as the benchmark's records, a sweep's summary and the matrix label them (a method's
baseline is then the ``none`` the same learner ran, ``none@dqn``). Kept apart from
``learners`` so that reading a store's labels imports no Gymnasium."""

from __future__ import annotations

SARSA = "sarsa"
"""The built-in learner's name."""

AT = "@"
"""What joins a method and an outside learner in a label."""


def label(method: str, learner: str = SARSA) -> str:
    """The name ``method`` run by ``learner`` goes by: the method alone for the built-in learner."""
    return method if learner == SARSA else f"{method}{AT}{learner}"


def parse_label(name: str) -> tuple[str, str]:
    """(method, learner) of a name made by :func:`label`."""
    method, _, learner = name.partition(AT)
    return method, learner or SARSA
