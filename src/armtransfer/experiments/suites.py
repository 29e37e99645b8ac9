"""The benchmark's suites: the built-in ones, shipped as suite files
(``armtransfer/experiments/suite_data/``, read by ``experiments.suite_files``), and a user's
suite file named on the command line. What a suite is: ``experiments.suite_model``."""

from __future__ import annotations

from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import suite_files
from armtransfer.experiments.suite_files import builtin
from armtransfer.experiments.suite_model import (
    BUDGET_FACTOR as BUDGET_FACTOR, CELLS as CELLS, DEFAULT_LEARNERS as DEFAULT_LEARNERS,
    DEFAULT_WORLD as DEFAULT_WORLD, METHODS as METHODS, MIN_SEEDS_FOR_CLAIM as MIN_SEEDS_FOR_CLAIM,
    STATES as STATES, Case as Case, Section as Section, Suite as Suite)


def _load() -> dict[str, Suite]:
    return builtin()


SUITES: dict[str, Suite] = _load()
"""Every built-in suite by name: the suite files of ``armtransfer/experiments/suite_data/``."""

DEV = SUITES["dev"].sections[0]
FAST = SUITES["fast"].sections[0]
SMALL = SUITES["small"].sections[0]
VOXELS, VOXELS_CONTINUOUS = SUITES["voxels"].sections
SMALL_LEARNERS = SMALL.learners


def get(name: str) -> Suite:
    """The suite called ``name``; an unknown name is a one-line error listing the valid ones."""
    try:
        return SUITES[name]
    except (KeyError, TypeError):
        raise InvalidParameterError(f"unknown suite {name!r}; valid suites: {', '.join(SUITES)}, or a suite file "
                                    "PATH.toml or PATH.json (docs/benchmark.md)") from None


def named(text: str) -> Suite:
    """The suite ``--suite TEXT`` names: a built-in one, or a suite file (``.toml``, ``.json``)."""
    return suite_files.load(text, SUITES) if suite_files.is_file_name(text) else get(text)


def is_builtin(suite: Suite) -> bool:
    """Whether ``suite`` is one of the suites shipped with the package, as it ships."""
    return suite.name in SUITES and SUITES[suite.name].to_dict() == suite.to_dict()
