"""Who a method is compared with: the baselines that share its learner and are told less.

The benchmark runs them (``experiments.benchmark``) and its report names them
(``experiments.reports.benchmark_report``); both read them here, from the method registry alone.
"""

from __future__ import annotations

from armtransfer.learning import methods
from armtransfer.learning.learner_names import label, parse_label


def baselines_of(name: str) -> tuple[str, ...]:
    """The methods ``name``'s gain is measured against, each sharing its learner and told less:
    the registry's ``Method.baselines`` (the no-transfer one first; empty for a method that is
    itself no transfer), or, from a registry without that field, ``none`` for every method but
    ``none``; then, for a method that reads the trajectory, its goal-only baseline
    (:data:`GOAL_ONLY`). ``name`` may be a record's label ``METHOD@LEARNER``: its baselines are
    labelled so."""
    method, learner = parse_label(name)
    m = methods.get(method)
    if hasattr(m, "baselines"):
        named = tuple(b for b in m.baselines if b in methods.METHODS and b != method)
    else:
        named = () if method == "none" else ("none",)
    goal = GOAL_ONLY.get(named[0]) if named else None
    reads = getattr(m, "shaped", False) and getattr(m, "uses_trajectory", True)
    if goal is not None and goal in methods.METHODS and goal not in named and goal != method and reads:
        named += (goal,)
    return tuple(label(b, learner) for b in named)


GOAL_ONLY = {"none": "goal-dense", "plan": "goal-only"}
"""The goal-only baseline set beside every method that reads the trajectory, by the baseline told
nothing that shares its learner: what the route adds beyond the goal (``goal-dense``: ``dense``'s
potential from the goal alone, on Algorithm 1; ``goal-only``: ``plan``'s learner heading for the
goal)."""


def registered_baseline(name: str) -> bool:
    """Whether the registry itself names ``name``'s baselines (rather than the ``none`` default)."""
    return hasattr(methods.get(parse_label(name)[0]), "baselines")


def baseline_of(name: str) -> str | None:
    """The no-transfer method sharing ``name``'s learner (None: ``name`` is one itself)."""
    named = baselines_of(name)
    return named[0] if named else None
