"""Sparse eligibility traces, shared by the tabular and the linear learner's kernels.

Only pairs with a non-zero trace are stored: ``tr_sa[:n]`` holds the pairs (a flat index into
the values: ``s * n_actions + a`` for a table, ``feature * n_actions + a`` for weights),
``tr_e[:n]`` their traces, and ``pos[pair]`` a pair's slot (-1: no trace).
"""

from __future__ import annotations

import numba


@numba.njit(cache=True, nogil=True, inline="always")
def mark(tr_sa, tr_e, pos, n_tr, pair, replacing):
    """The pair's trace set to 1 (``replacing``) or increased by 1; returns the new count."""
    slot = pos[pair]
    if slot < 0:
        pos[pair] = n_tr
        tr_sa[n_tr] = pair
        tr_e[n_tr] = 1.0
        return n_tr + 1
    if replacing:
        tr_e[slot] = 1.0
    else:
        tr_e[slot] += 1.0
    return n_tr


@numba.njit(cache=True, nogil=True, inline="always")
def apply(values, tr_sa, tr_e, pos, n_tr, step, decay, cutoff):
    """values[pair] += step * e for every trace, then e *= decay; a trace that falls below
    ``cutoff`` (or to 0) is dropped, the last one moved into its slot. Returns the new count."""
    k = 0
    while k < n_tr:
        pair = tr_sa[k]
        e = tr_e[k]
        values[pair] += step * e
        e *= decay
        if e < cutoff or e == 0.0:
            pos[pair] = -1
            n_tr -= 1
            if k < n_tr:
                tr_sa[k] = tr_sa[n_tr]
                tr_e[k] = tr_e[n_tr]
                pos[tr_sa[k]] = k
            continue
        tr_e[k] = e
        k += 1
    return n_tr
