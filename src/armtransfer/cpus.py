"""How many CPUs one armtransfer process may use for its own parallel work: the trials of a
method, on threads (``armtransfer.experiments.experiment.map_trials``). A sweep's workers set 1: there the
workers are the parallelism. Results never depend on it.

Threads, not processes: with the ``spawn`` start method a process pool re-imports the
caller's ``__main__``, and a user's script without an ``if __name__ == "__main__":`` guard
would then run again in every worker (only a sweep, whose workers are the point, starts
processes)."""

from __future__ import annotations

import os

from armtransfer.errors import InvalidParameterError

ENV = "ARMTRANSFER_CPUS"
"""The environment variable that sets :func:`cpus` (default: the CPUs this process may use)."""

MAX_CPUS = 4096
"""The most threads ``$ARMTRANSFER_CPUS`` may ask for (a larger value is a mistake)."""


def cpus() -> int:
    """``$ARMTRANSFER_CPUS``, else the CPUs this process may use."""
    value = os.environ.get(ENV, "").strip()
    if value:
        try:
            n = int(value) if len(value) <= 12 else 0
        except ValueError:
            n = 0
        if not 1 <= n <= MAX_CPUS:
            raise InvalidParameterError(f"{ENV} must be an integer in 1..{MAX_CPUS:,}, got {value[:40]!r}")
        return n
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
