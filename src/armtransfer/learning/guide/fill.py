"""The fill, with the tip model: learning real-time search (Korf's LRTA*) on the guide's score.

A joint-space robot has many states per cell, so where the trajectory's next cells cannot be
reached straight on (the arm must first move away from them) the score has wide local minima.
Robot 2 keeps, per state and only until a trajectory's progress next moves (the progress
epoch), an increment h(s) in cells: a move's score is its predicted score plus h of the state
that move led to when tried at s (``ahead``); choosing at s raises h(s) to (the smallest of its
moves' scores) + the fill - (the score at s) (``raise_at``), so a basin fills as it is visited,
a fill per visit at most, instead of one SARSA(lambda) update at a time."""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np


class Fill(NamedTuple):
    """The fill's increments (``new``; empty without it)."""

    h: np.ndarray
    """float64 [S]: the increment of each state, valid in the epoch it was set in."""
    h_epoch: np.ndarray
    """int64 [S]: the progress epoch each h was set in (-1: never)."""
    last: np.ndarray
    """int64 [S, A]: the state last observed after each pair (-1: none)."""


def new(n_states: int, n_actions: int, on: bool) -> Fill:
    """The fill's arrays for ``n_states`` states (none when it is off)."""
    n = n_states if on else 0
    return Fill(np.zeros(n), np.full(n, -1, np.int64), np.full((n, n_actions), -1, np.int64))


@numba.njit(cache=True)
def observe(f, s, a, s2):
    """Remember s2 as the state last observed after (s, a)."""
    f.last[s, a] = s2


@numba.njit(cache=True)
def visit(f, epoch, s):
    """h(s) as of this epoch: 0 when it was set in an earlier one."""
    if f.h_epoch[s] != epoch:
        f.h_epoch[s] = epoch
        f.h[s] = 0.0


@numba.njit(cache=True)
def ahead(f, epoch, s, a):
    """(known, h): h of the state (s, a) last led to, when it was set in this epoch."""
    u = f.last[s, a]
    if f.h_epoch[u] == epoch:
        return True, f.h[u]
    return False, 0.0


@numba.njit(cache=True)
def raise_at(f, s, low, cost, here):
    """Raise h(s) to low + cost - here (the best move's score, the fill, the score at s)."""
    raise_to = low + cost - here
    if raise_to > f.h[s]:
        f.h[s] = raise_to
