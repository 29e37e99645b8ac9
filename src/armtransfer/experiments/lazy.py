"""Heavy third-party modules, imported on first use.

A command that stops on bad input, or only prints its help, should not pay for what it never
runs: scipy.stats takes most of a second to import, matplotlib a third of one."""

from __future__ import annotations


def scipy_stats():
    """``scipy.stats``."""
    from scipy import stats  # start-up (the module docstring)

    return stats


def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (files only, no window)."""
    import matplotlib  # start-up (the module docstring)

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # start-up (the module docstring)

    return plt
