"""Named sets of learner settings: ``--preset NAME`` on every command, ``preset=`` in the API,
the ``preset`` key of a sweep file.

A preset fills the :class:`LearnerConfig` fields it names; a field given explicitly (a flag,
a keyword, a sweep key) still wins over it. ``default`` is the config's own defaults.
``paper-calibrated`` was fitted to the paper's no-transfer columns (Table II A, Table V A)
and nothing else, by ``research/calibrate.py`` (its results are in ``research/calibration/``,
its values and fit in docs/methods.md).
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Mapping

from armtransfer.errors import InvalidParameterError
from armtransfer.learning.config import LearnerConfig

DEFAULT = "default"
PAPER_CALIBRATED = "paper-calibrated"

PRESETS: Mapping[str, Mapping[str, float | int]] = MappingProxyType({
    DEFAULT: MappingProxyType({}),
    PAPER_CALIBRATED: MappingProxyType({
        # research/calibrate.py's fit: 6 of 8 no-transfer cells within 20% of the paper's, RMS log
        # error 0.318 (200 trials a cell), among the settings whose robot 1 converges on every task
        "alpha": 1.0,
        "gamma": 0.99,
        "lam": 0.3,
        "epsilon": 0.0,
        "step_reward": -1.0,
        "goal_reward": 0.0,
    }),
})
"""Each preset's settings (the fields it changes from ``LearnerConfig``'s defaults)."""


def names() -> tuple[str, ...]:
    return tuple(PRESETS)


def check(name: object) -> str:
    """``name`` if it is a preset's; otherwise a one-line error listing the valid names."""
    if not isinstance(name, str) or name not in PRESETS:
        raise InvalidParameterError(f"unknown preset {name!r}; valid presets: {', '.join(PRESETS)}")
    return name


def values(name: str) -> dict[str, float | int]:
    """The preset's settings, every LearnerConfig field included (its defaults where it names none)."""
    return {**LearnerConfig().to_dict(), **PRESETS[check(name)]}


def config(name: str = DEFAULT, options: Mapping[str, object] | None = None) -> LearnerConfig:
    """The learner config of preset ``name`` with ``options`` (LearnerConfig fields) over it."""
    base: dict[str, object] = dict(PRESETS[check(name)])
    base.update(options or {})
    return LearnerConfig.from_options(base)
