"""Holm's step-down correction of a report's p-values for multiplicity.

A report that reads 50 intervals at 5% each will call some difference real by chance alone.
Holm (1979) controls the chance of any false verdict across all of them at 5%: sort the m
p-values, multiply the k-th smallest by (m - k + 1), and keep the adjusted values monotone.
Every verdict of a benchmark report (each method against each baseline, on each metric, in
each section) is one of the m.
"""

from __future__ import annotations

from collections.abc import Sequence

ALPHA = 0.05


def holm(p_values: Sequence[float]) -> list[float]:
    """Holm-adjusted p-values, in the order given (each at most 1)."""
    m = len(p_values)
    order = sorted(range(m), key=lambda i: (p_values[i], i))
    out = [1.0] * m
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * float(p_values[i])))
        out[i] = running
    return out
