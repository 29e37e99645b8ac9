"""Tile coding of a box of real vectors (Sutton and Barto, 2018, section 9.5.4).

``tilings`` grids of tiles of the same ``width`` cover the box, each shifted by a fraction of
a tile; a point lies in exactly one tile of each grid, so it has ``tilings`` active features.
Tiling t is shifted by ``(t * (2d + 1) / tilings) mod 1`` tile widths along dimension d (the
asymmetric offsets S&B recommend; a uniform shift would put every tiling's boundaries on the
same diagonal). One tiling with ``shift`` 0.5 and a point set on a lattice of pitch ``width``
through ``lower`` gives every lattice point a tile of its own: one-hot features.

Features are dense: tiling t's tile (c_0, ..., c_{D-1}) is feature
``t * per_tiling + sum_d c_d * stride_d``; a coordinate outside the box falls in the nearest
border tile.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from armtransfer.errors import InvalidParameterError

MAX_FEATURES = 20_000_000
"""The most features (tiles over all tilings) a coding may have (its weights grow with them)."""


@dataclass(frozen=True)
class TileCoding:
    lower: np.ndarray
    """float64 [D]: the box's lowest corner."""
    width: np.ndarray
    """float64 [D]: a tile's width along each dimension."""
    offsets: np.ndarray
    """float64 [tilings, D]: each tiling's shift, in tile widths."""
    dims: np.ndarray
    """int64 [D]: tiles per dimension in one tiling."""
    strides: np.ndarray
    """int64 [D]: a tile coordinate's stride in a tiling's feature numbers."""
    per_tiling: int

    @property
    def tilings(self) -> int:
        return int(self.offsets.shape[0])

    @property
    def size(self) -> int:
        """The number of features."""
        return self.tilings * self.per_tiling

    @staticmethod
    def over(lower, upper, width, tilings: int, shift: float | None = None) -> "TileCoding":
        """Tilings of tiles ``width`` wide (a number or one per dimension) over the box
        [lower, upper]; ``shift`` (one tiling only): its shift in tile widths."""
        lower = np.asarray(lower, dtype=np.float64).reshape(-1)
        upper = np.asarray(upper, dtype=np.float64).reshape(-1)
        d = len(lower)
        width = np.broadcast_to(np.asarray(width, dtype=np.float64), (d,)).copy()
        if isinstance(tilings, bool) or not isinstance(tilings, (int, np.integer)) or tilings < 1:
            raise InvalidParameterError(f"tilings must be a positive integer, got {tilings!r}")
        if upper.shape != (d,) or not (np.all(np.isfinite(lower)) and np.all(np.isfinite(upper))):
            raise InvalidParameterError("a tile coding's box needs finite lower and upper corners of one length")
        if np.any(upper < lower) or not np.all(np.isfinite(width)) or np.any(width <= 0):
            raise InvalidParameterError("a tile coding needs upper >= lower and positive finite tile widths")
        if shift is not None:
            if tilings != 1 or not (math.isfinite(shift) and 0.0 <= shift < 1.0):
                raise InvalidParameterError("a shift in [0, 1) goes with one tiling")
            offsets = np.full((1, d), float(shift))
        else:
            offsets = (np.arange(tilings)[:, None] * (2 * np.arange(d)[None, :] + 1) / tilings) % 1.0
        dims = (np.floor((upper - lower) / width).astype(np.int64) + 2)  # a shifted tiling needs one more
        strides = np.ones(d, dtype=np.int64)
        for k in range(d - 2, -1, -1):
            strides[k] = strides[k + 1] * dims[k + 1]
        per = int(np.prod(dims.astype(float)))
        if per * tilings > MAX_FEATURES:
            raise InvalidParameterError(
                f"the tile coding would have {per * tilings:.3g} features (at most {MAX_FEATURES:,}); use wider "
                "tiles or fewer tilings")
        return TileCoding(lower, width, offsets.astype(np.float64), dims, strides, int(per))

    def active(self, q: np.ndarray) -> np.ndarray:
        """The active features of the point ``q`` (one per tiling, in tiling order)."""
        out = np.empty(self.tilings, dtype=np.int64)
        active(np.asarray(q, dtype=np.float64), self.lower, self.width, self.offsets, self.dims, self.strides,
               self.per_tiling, out)
        return out


@numba.njit(cache=True, nogil=True)
def active(q, lower, width, offsets, dims, strides, per_tiling, out):
    """Write the active feature of each tiling for the point ``q`` into ``out``."""
    n_tilings, d = offsets.shape
    for t in range(n_tilings):
        f = t * per_tiling
        for k in range(d):
            c = int(math.floor((q[k] - lower[k]) / width[k] + offsets[t, k]))
            if c < 0:
                c = 0
            elif c >= dims[k]:
                c = dims[k] - 1
            f += c * strides[k]
        out[t] = f
