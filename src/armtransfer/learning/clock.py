"""The good-path clock: how long a trial took to hold a greedy path close to the shortest.

A greedy path that stopped changing may be a long one: a learner that explores less settles
sooner on a worse path. The good-path clock counts the steps until the greedy path is *good*,
at most ``ceil(quality x shortest)`` steps long, and stays good to the end of the trial. It is
the harness's measuring instrument: the target's shortest path is read from its table by the
harness, never by the learner (the kernel's stopping rule reads the good length; no choice of
the learner does).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

DEFAULT_QUALITY = 1.05
"""A greedy path is good at most ``ceil(1.05 x shortest)`` steps long (within 5%)."""

EXACT = 1.0
"""The quality reported beside the chosen one: the shortest path itself."""


def good_length(quality: float, optimal: int) -> int:
    """The longest good path: ``ceil(quality x optimal)``, computed so that 1.05 x 20 is 21
    (not 22 from the float's last bit)."""
    return int(math.ceil(round(float(quality) * int(optimal), 9)))


def good_path_steps(greedy_lengths: Sequence[int] | np.ndarray, episode_steps: Sequence[int] | np.ndarray,
                    good_len: int) -> int | None:
    """The steps until the greedy path was at most ``good_len`` long and stayed so to the end of
    the trial: the steps through the first episode after which it was good and after which it
    never stopped being good (a greedy path that misses the goal, length -1, is not good).
    None: not good at the trial's end (censored at the steps the trial ran)."""
    lengths = np.asarray(greedy_lengths, dtype=np.int64)
    steps = np.abs(np.asarray(episode_steps, dtype=np.int64))
    good = (lengths >= 0) & (lengths <= int(good_len))
    if len(good) == 0 or not good[-1]:
        return None
    bad = np.flatnonzero(~good)
    first = int(bad[-1]) + 1 if len(bad) else 0
    return int(steps[: first + 1].sum())


def ratio(length: int | None, optimal: int | None) -> float | None:
    """A greedy path's length over the shortest (None when either is unknown)."""
    if length is None or optimal is None or optimal <= 0:
        return None
    return float(length) / float(optimal)
