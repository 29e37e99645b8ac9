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

**Hashed** (``table=2**k``): the same tiles, but tile (t, c_0, ..., c_{D-1}) is feature
``hash(t, c) & (table - 1)`` in one table of ``table`` features shared by every tiling, so the
weights no longer grow with the box (a 6- or 7-joint arm's lattice). The hash, on unsigned
64-bit integers with wrap-around: ``h = mix((t + 1) * G)``, then for each d in order
``h = mix(h + c_d + G)``, with G = 0x9E3779B97F4A7C15 and ``mix`` splitmix64's finaliser
(``z ^= z >> 30; z *= 0xBF58476D1CE4E5B9; z ^= z >> 27; z *= 0x94D049BB133111EB; z ^= z >> 31``).
Distinct tiles may share a feature (a collision): :meth:`TileCoding.collisions` counts them
over a set of points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from armtransfer.errors import InvalidParameterError

MAX_FEATURES = 20_000_000
"""The most features (tiles over all tilings) a coding may have (its weights grow with them)."""
MAX_TABLE_BITS = 24
"""A hashed coding's table has at most 2**24 features."""
_G = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31 = np.uint64(30), np.uint64(27), np.uint64(31)


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
    table: int = 0
    """0: dense features; else the size of the hashed table (a power of 2)."""

    @property
    def tilings(self) -> int:
        return int(self.offsets.shape[0])

    @property
    def size(self) -> int:
        """The number of features (a hashed coding: its table's size)."""
        return self.table if self.table else self.tilings * self.per_tiling

    @staticmethod
    def over(lower, upper, width, tilings: int, shift: float | None = None, table_bits: int = 0) -> "TileCoding":
        """Tilings of tiles ``width`` wide (a number or one per dimension) over the box
        [lower, upper]; ``shift`` (one tiling only): its shift in tile widths; ``table_bits``
        k > 0: hashed into 2**k features (see the module docstring)."""
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
        if isinstance(table_bits, bool) or not isinstance(table_bits, (int, np.integer)) \
                or not 0 <= table_bits <= MAX_TABLE_BITS:
            raise InvalidParameterError(f"table_bits must be an integer in 0..{MAX_TABLE_BITS} (0: dense), "
                                        f"got {table_bits!r}")
        dims = (np.floor((upper - lower) / width).astype(np.int64) + 2)  # a shifted tiling needs one more
        if table_bits:
            return TileCoding(lower, width, offsets.astype(np.float64), dims, np.zeros(d, np.int64), 0,
                              1 << int(table_bits))
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
        features(np.asarray(q, dtype=np.float64), self.lower, self.width, self.offsets, self.dims, self.strides,
                 self.per_tiling, self.table, out)
        return out

    def kernel_args(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, int]:
        """The arguments :func:`features` takes after q, before ``out``."""
        return (self.lower, self.width, self.offsets, self.dims, self.strides, int(self.per_tiling), int(self.table))

    def tiles(self, q: np.ndarray) -> np.ndarray:
        """int64 [tilings, D]: the tile coordinates of ``q`` in each tiling (what is hashed)."""
        q = np.asarray(q, dtype=np.float64).reshape(-1)
        c = np.floor((q[None, :] - self.lower[None, :]) / self.width[None, :] + self.offsets).astype(np.int64)
        return np.clip(c, 0, self.dims[None, :] - 1)

    def collisions(self, points) -> dict:
        """Over the configurations ``points`` [n, D]: the distinct tiles they touch (tiling and
        coordinates), the distinct features those map to, and the tiles that share their
        feature with another of them (0 for a dense coding)."""
        keys: dict[tuple, int] = {}
        for q in np.asarray(points, dtype=np.float64).reshape(-1, len(self.lower)):
            f = self.active(q)
            for t, c in enumerate(self.tiles(q)):
                keys[(t, *c.tolist())] = int(f[t])
        owners: dict[int, int] = {}
        for feature in keys.values():
            owners[feature] = owners.get(feature, 0) + 1
        return {"tiles": len(keys), "features": len(owners),
                "tiles_sharing": sum(n for n in owners.values() if n > 1)}


@numba.njit(cache=True, nogil=True, inline="always")
def _mix(z):
    """splitmix64's finaliser on an unsigned 64-bit integer."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@numba.njit(cache=True, nogil=True)
def active_hashed(q, lower, width, offsets, dims, table, out):
    """Write the hashed feature of each tiling for the point ``q`` into ``out`` (module docstring)."""
    n_tilings, d = offsets.shape
    mask = np.uint64(table - 1)
    for t in range(n_tilings):
        h = _mix(np.uint64(t + 1) * _G)
        for k in range(d):
            c = int(math.floor((q[k] - lower[k]) / width[k] + offsets[t, k]))
            if c < 0:
                c = 0
            elif c >= dims[k]:
                c = dims[k] - 1
            h = _mix(h + np.uint64(c) + _G)
        out[t] = np.int64(h & mask)


@numba.njit(cache=True, nogil=True)
def features(q, lower, width, offsets, dims, strides, per_tiling, table, out):
    """The active features of ``q`` into ``out``: dense (``table`` 0, :func:`active`) or hashed."""
    if table == 0:
        active(q, lower, width, offsets, dims, strides, per_tiling, out)
    else:
        active_hashed(q, lower, width, offsets, dims, table, out)


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
