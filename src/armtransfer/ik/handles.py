"""The compiled moves called from Python at the cost of one argument.

numba checks the type of every argument at every call from Python; a move's state is some forty
arrays and numbers, which costs more than the move. Here the state is written once into one
int64 array, four slots an item (an array: its address and shape; a number: its value, a float's
bits), and a kernel rebuilds the arrays over the same memory (``numba.carray``) and calls the
move: one call costs about what an empty call with one array does. The arrays must outlive the
table (the arm keeps them) and keep their address (MuJoCo's buffers and the arm's own arrays
do). :func:`table` checks each item against the kernel's list of what it reads. (numba keys a
cached kernel on its own file: ``experiments.fastloop`` empties these kernels' caches when a file
they call into changed, as it does ``ik.fastmove``'s.) The kernels that take a table are
``ik.fastmove.planar_move`` and ``ik.fastmove3d.spatial_move``, beside the moves they call.
"""

from __future__ import annotations

import numba
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic


SLOTS = 4
"""int64 slots an item takes in a table."""


@intrinsic
def _void(typingctx, addr):
    """The int64 ``addr`` as a pointer."""
    sig = types.voidptr(types.int64)

    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], ir.IntType(8).as_pointer())

    return sig, codegen


def table(kinds: str, items) -> np.ndarray:
    """The table of ``items``, checked against ``kinds`` (one word per item: ``u64``, ``int``,
    ``float``, ``bool`` for numbers, ``f8:N``, ``i8:N``, ``i4:N``, ``b:N`` for arrays of N
    dimensions)."""
    words = kinds.split()
    if len(words) != len(items):
        raise ValueError(f"a table of {len(words)} items, got {len(items)}")
    out = np.zeros(SLOTS * len(items), np.int64)
    for k, (word, item) in enumerate(zip(words, items)):
        at = SLOTS * k
        if ":" in word:
            code, nd = word.split(":")
            dtype = {"f8": np.float64, "i8": np.int64, "i4": np.int32, "b": np.bool_}[code]
            if not (isinstance(item, np.ndarray) and item.dtype == dtype and item.ndim == int(nd)
                    and item.flags.c_contiguous):
                raise ValueError(f"item {k}: a C-contiguous {word} array expected, got {type(item).__name__} "
                                 f"{getattr(item, 'dtype', '')} {getattr(item, 'shape', '')}")
            out[at] = item.__array_interface__["data"][0]
            out[at + 1:at + 1 + item.ndim] = item.shape
        elif word == "float":
            out[at] = np.float64(item).view(np.int64)
        elif word in ("u64", "int", "bool"):
            out[at] = int(item)
        else:
            raise ValueError(f"unknown item kind {word!r}")
    return out


@numba.njit(cache=True, nogil=True, inline="always")
def _f1(t, k):
    return numba.carray(_void(t[k]), (t[k + 1],), np.float64)


@numba.njit(cache=True, nogil=True, inline="always")
def _f2(t, k):
    return numba.carray(_void(t[k]), (t[k + 1], t[k + 2]), np.float64)


@numba.njit(cache=True, nogil=True, inline="always")
def _f3(t, k):
    return numba.carray(_void(t[k]), (t[k + 1], t[k + 2], t[k + 3]), np.float64)


@numba.njit(cache=True, nogil=True, inline="always")
def _i1(t, k):
    return numba.carray(_void(t[k]), (t[k + 1],), np.int64)


@numba.njit(cache=True, nogil=True, inline="always")
def _i4(t, k):
    return numba.carray(_void(t[k]), (t[k + 1],), np.int32)


@numba.njit(cache=True, nogil=True, inline="always")
def _b1(t, k):
    return numba.carray(_void(t[k]), (t[k + 1],), np.bool_)


@numba.njit(cache=True, nogil=True, inline="always")
def _b2(t, k):
    return numba.carray(_void(t[k]), (t[k + 1], t[k + 2]), np.bool_)


@numba.njit(cache=True, nogil=True, inline="always")
def _float(t, k):
    return t[k:k + 1].view(np.float64)[0]


@numba.njit(cache=True, nogil=True, inline="always")
def _raw(t):
    """``ik.fastmove.layout``'s tuple, from the first 12 items."""
    return (np.uint64(t[0]), np.uint64(t[4]), np.uint64(t[8]), np.uint64(t[12]), _i4(t, 16), _i1(t, 20), t[24],
            _i4(t, 28), t[32], t[36], t[40], _b2(t, 44))


RAW = "u64 u64 u64 u64 i4:1 i8:1 int i4:1 int int int b:2"

def of_state(kinds: str, state: tuple) -> np.ndarray:
    """The table of a move's state tuple (its first item, ``raw``, spread out)."""
    return table(kinds, list(state[0]) + list(state[1:]))
