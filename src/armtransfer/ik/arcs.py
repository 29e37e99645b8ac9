"""The cells under a planar arm's tool point along a move (``ik.continuous``'s checks, in numba,
without MuJoCo: ``ik.fastmove`` compiles them into its move too)."""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def _cell(x, y, cell_size, lo, width):
    """The cell id under (x, y) (metres), -1 off the grid: ``ik.labels.cells_of_xy``'s rule."""
    cx = int(np.rint(x / cell_size)) - lo
    cy = int(np.rint(y / cell_size)) - lo
    if cx < 0 or cy < 0 or cx >= width or cy >= width:
        return -1
    return cy * width + cx


@numba.njit(cache=True)
def _sweep_turn(tx, ty, ax, ay, back, m, cell_size, lo, width, free, near):
    """``_sweep`` for a move of any turn: the k-th of the ``m`` points of the arc (k = 1..m) is
    the tip turned back about the anchor by (1 - k / (m + 1)) * ``back`` radians."""
    end = _cell(tx, ty, cell_size, lo, width)
    if end < 0 or not free[end]:
        return -1, False
    close = near[end]
    dx = tx - ax
    dy = ty - ay
    for k in range(1, m + 1):
        angle = (1.0 - k / (m + 1)) * back
        c = math.cos(angle)
        s = math.sin(angle)
        cell = _cell(ax + c * dx - s * dy, ay + s * dx + c * dy, cell_size, lo, width)
        if cell < 0 or not free[cell]:
            return -1, False
        if near[cell]:
            close = True
    return end, close


@numba.njit(cache=True)
def _sweep(tx, ty, ax, ay, cos_back, sin_back, m, cell_size, lo, width, free, near):
    """(the end's cell or -1 when the move is blocked by a wall or the table's edge, whether any
    point of the move is near a wall). (tx, ty): the tip at the end of the move; (ax, ay): the
    moved joint's anchor; the k-th point of the arc is the tip turned back about the anchor by
    the angle whose cosine and sine are cos_back[k], sin_back[k]."""
    end = _cell(tx, ty, cell_size, lo, width)
    if end < 0 or not free[end]:
        return -1, False
    close = near[end]
    dx = tx - ax
    dy = ty - ay
    for k in range(m):
        c = cos_back[k]
        s = sin_back[k]
        cell = _cell(ax + c * dx - s * dy, ay + s * dx + c * dy, cell_size, lo, width)
        if cell < 0 or not free[cell]:
            return -1, False
        if near[cell]:
            close = True
    return end, close
