"""The continuous arm's move (``ik.continuous.ContinuousArm.move``) compiled with numba, calling
MuJoCo's C library directly, so that a learner's whole episode can run without Python per step.

``mj_kinematics`` and ``mj_collision`` are called by address (found with ``ctypes``; the call is
an LLVM intrinsic, so the kernels are cached like the project's others) on the addresses of the
Python bindings' own ``MjModel`` and ``MjData`` (the same library file the bindings load). The
compiled move reads what the Python move reads through the bindings, from the same memory:
``qpos``, ``site_xpos`` and ``xanchor`` are the bindings' numpy views, and two things that have no
view are read from ``mjData`` itself:

- ``ncon``: the int right after the ``timer`` array (``mjdata.h``: ``timer[mjNTIMER]`` then
  ``ncon``), located from the address of the bindings' ``data.timer.duration`` view;
- the contacts' geom ids: the contact array starts where ``data.contact`` puts it, which the
  bindings' ``data.contact.geom1`` view gives, with its stride; ``mjData.contact`` (the pointer,
  found in the struct by its value) is read at every check and compared with that start.

:func:`layout` checks both against the bindings on configurations with and without contacts and
returns None when anything differs (another MuJoCo's layout): the arm then keeps its Python
move. A compiled move that meets anything it cannot read (the contact array moved, more contacts
than the view holds, a flex contact) undoes itself and returns :data:`PYTHON`, and the caller
takes that move in Python. The result is the Python move's, bit for bit (the same MuJoCo calls
on the same memory in the same order, the same arithmetic: ``tests/test_continuous_more.py``).
"""

from __future__ import annotations

import ctypes
import glob
import os
from typing import Any

import numba
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

from armtransfer.ik import handles, swept
from armtransfer.ik.arcs import _sweep

PYTHON = -3
"""What the compiled move returns when the move must be taken in Python (nothing has changed)."""
BLOCKED = -2
CONTACTS = 64
"""The most contacts the compiled move reads (more: :data:`PYTHON`)."""

_KIN: Any = None
_COL: Any = None


def _library():
    """``mj_kinematics`` and ``mj_collision`` of the bindings' own library, as ctypes functions."""
    import mujoco  # here: experiments.fastloop imports this module and loads no MuJoCo

    global _KIN, _COL
    if _KIN is None:
        files = sorted(glob.glob(os.path.join(os.path.dirname(mujoco.__file__), "libmujoco.so*")))
        if not files:
            return None
        lib = ctypes.CDLL(files[0])
        kin, col = lib.mj_kinematics, lib.mj_collision
        for f in (kin, col):
            f.argtypes = [ctypes.c_uint64, ctypes.c_uint64]
            f.restype = None
        _KIN, _COL = kin, col
    return _KIN, _COL


def _int32_at(address: int, n: int) -> np.ndarray:
    return np.ctypeslib.as_array((ctypes.c_int32 * n).from_address(address))


def layout(model, data, counts: np.ndarray, configurations: np.ndarray) -> tuple | None:
    """The raw views the compiled move reads, checked against the bindings at ``configurations``
    (some with contacts), or None. Leaves ``data.qpos`` as it found it."""
    import mujoco  # here: experiments.fastloop imports this module and loads no MuJoCo

    if _library() is None or not hasattr(data, "_address") or not hasattr(model, "_address"):
        return None
    q0 = data.qpos.copy()
    try:
        timer = data.timer.duration
        at = timer.__array_interface__["data"][0] + timer.strides[0] * len(timer)
        ncon = _int32_at(at, 1)
        base = stride = g1 = g2 = -1
        for q in configurations:
            data.qpos[:] = q
            mujoco.mj_kinematics(model, data)
            mujoco.mj_collision(model, data)
            if int(ncon[0]) != data.ncon:
                return None
            if data.ncon:
                c = data.contact
                addr = (c.dist.__array_interface__["data"][0], c.geom1.__array_interface__["data"][0],
                        c.geom2.__array_interface__["data"][0])
                s = c.geom1.strides[0] if data.ncon > 1 else -1
                if base < 0:
                    base, g1, g2 = addr[0], addr[1] - addr[0], addr[2] - addr[0]
                if (addr[0], addr[1] - addr[0], addr[2] - addr[0]) != (base, g1, g2):
                    return None
                if s > 0:
                    if stride not in (-1, s):
                        return None
                    stride = s
        if base < 0 or stride <= 0 or stride % 4 or g1 % 4 or g2 % 4:
            return None
        # the pointer mjData.contact, found in the struct by its value
        struct = np.ctypeslib.as_array((ctypes.c_int64 * ((at - data._address) // 8 + 64)).from_address(data._address))
        where = np.flatnonzero(struct == base)
        if len(where) != 1:
            return None
        pointer = np.ctypeslib.as_array((ctypes.c_int64 * 1).from_address(data._address + 8 * int(where[0])))
        contacts = _int32_at(base, CONTACTS * stride // 4)
        for q in configurations:  # the geom ids read raw are the bindings'
            data.qpos[:] = q
            mujoco.mj_kinematics(model, data)
            mujoco.mj_collision(model, data)
            n = data.ncon
            raw1 = [int(contacts[k * stride // 4 + g1 // 4]) for k in range(min(n, CONTACTS))]
            raw2 = [int(contacts[k * stride // 4 + g2 // 4]) for k in range(min(n, CONTACTS))]
            if raw1 != data.contact.geom1[:len(raw1)].tolist() or raw2 != data.contact.geom2[:len(raw2)].tolist():
                return None
    finally:
        data.qpos[:] = q0
        mujoco.mj_kinematics(model, data)
    kin, col = _library()
    return (np.uint64(ctypes.cast(kin, ctypes.c_void_p).value or 0),
            np.uint64(ctypes.cast(col, ctypes.c_void_p).value or 0),
            np.uint64(model._address), np.uint64(data._address), ncon, pointer, np.int64(base), contacts,
            stride // 4, g1 // 4, g2 // 4, np.ascontiguousarray(counts, dtype=np.bool_))


@intrinsic
def _call(typingctx, fn, m, d):
    """Call the C function at address ``fn`` with the two pointers ``m``, ``d`` (uint64s)."""
    sig = types.void(types.uint64, types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.VoidType(), [ir.IntType(64), ir.IntType(64)])
        builder.call(builder.inttoptr(args[0], fnty.as_pointer()), [args[1], args[2]])
        return context.get_dummy_value()

    return sig, codegen


@numba.njit(cache=True, nogil=True)
def _touches_now(raw):
    """1 when a contact of the last collision detection counts, 0 when none does, -1: unreadable."""
    ncon, pointer, base, contacts, stride, g1o, g2o, counts = raw[4:]
    n = ncon[0]
    if n == 0:
        return 0
    if n > CONTACTS or pointer[0] != base:
        return -1
    for k in range(n):
        g1 = contacts[k * stride + g1o]
        g2 = contacts[k * stride + g2o]
        if g1 < 0 or g2 < 0:
            return -1
        if counts[g1, g2]:
            return 1
    return 0


@numba.njit(cache=True, nogil=True)
def _touches(raw, qpos, q):
    """``ContactChecker.touches(q)``: q set, kinematics and collision run, contacts counted."""
    qpos[:] = q
    _call(raw[0], raw[2], raw[3])
    _call(raw[1], raw[2], raw[3])
    return _touches_now(raw)


@numba.njit(cache=True, nogil=True)
def move(a, arm):
    """``ContinuousArm.move(a)`` on the arm's arrays ``arm`` (``ContinuousArm.fast_state``):
    the cell reached, :data:`BLOCKED`, or :data:`PYTHON` (nothing changed)."""
    (raw, qpos, site_xpos, xanchor, tip_id, jnt, q0, nn, nlo, nhi, step, cell_size, lo, width, free, near, clear,
     clear_needed, cosb, sinb, m_arr, probe, n_probe, always_probe, tip, label, moves, geom_xpos, geom_xmat, xaxis,
     sw_geoms, sw_offset, sw_sizes, sw_kinds, sw_carried, sw_boxes, sw_pairs, sw_frames, sw_anchor, sw_axis, sw_stack,
     sw_work) = arm
    j = a >> 1
    n = nn[j] + 1 - 2 * (a & 1)
    moves[0] += 1
    if n < nlo[j] or n > nhi[j]:
        return BLOCKED
    old = qpos[j]
    qpos[j] = q0[j] + n * step
    _call(raw[0], raw[2], raw[3])
    _call(raw[1], raw[2], raw[3])
    t = _touches_now(raw)
    if t != 0:
        qpos[j] = old
        if t < 0:
            moves[0] -= 1
            return PYTHON
        return BLOCKED
    swept.capture(geom_xpos, geom_xmat, sw_geoms, sw_offset, xanchor, xaxis, jnt[j:j + 1], sw_frames, sw_anchor,
                  sw_axis)
    if not swept.rotation_clear(sw_frames, sw_sizes, sw_kinds, sw_carried[j], sw_anchor[0], sw_axis[0],
                                -(qpos[j] - old), sw_boxes, sw_pairs, sw_stack, sw_work):
        qpos[j] = old
        return BLOCKED
    x = site_xpos[tip_id, 0]
    y = site_xpos[tip_id, 1]
    z = site_xpos[tip_id, 2]
    cx = int(np.rint(x / cell_size)) - lo
    cy = int(np.rint(y / cell_size)) - lo
    cell = cy * width + cx if 0 <= cx < width and 0 <= cy < width else -1
    probe_now = False
    if cell < 0 or clear[cell] < clear_needed[a]:
        jj = jnt[j]
        cell, close = _sweep(x, y, xanchor[jj, 0], xanchor[jj, 1], cosb[a], sinb[a], m_arr[a], cell_size, lo, width,
                            free, near)
        if cell < 0:
            qpos[j] = old
            return BLOCKED
        probe_now = always_probe  # the swept check has covered the table and walls
    else:
        probe_now = always_probe
    if probe_now:
        end = qpos[j]
        q = qpos.copy()
        hit = 0
        for k in range(n_probe[a]):
            q[j] = old + probe[a, k] * (end - old)
            hit = _touches(raw, qpos, q)
            if hit != 0:
                break
        q[j] = end
        qpos[:] = q
        if hit != 0:
            qpos[j] = old
            if hit < 0:
                moves[0] -= 1
                return PYTHON
            return BLOCKED
    nn[j] = n
    tip[0] = x
    tip[1] = y
    tip[2] = z
    label[0] = cell
    return cell


PLANAR = handles.RAW + (" f8:1 f8:2 f8:2 int i8:1 f8:1 i8:1 i8:1 i8:1 float float int int b:1 b:1 i8:1 i8:1 f8:2 f8:2 i8:1"
                " f8:2 i8:1 bool f8:1 i8:1 i8:1 f8:2 f8:2 f8:2 i8:1 f8:2 f8:2 i8:1 b:2 f8:2 b:2 f8:3 f8:2 f8:2 f8:2"
                " f8:2")
"""What :func:`planar_move` reads: ``ContinuousArm.fast``'s tuple, ``raw`` spread out."""


@numba.njit(cache=True, nogil=True)
def planar_move(a, t):
    """``ik.fastmove.move(a, arm)`` on the arm of the table ``t`` (:data:`PLANAR`)."""
    k = 48
    arm = (handles._raw(t), handles._f1(t, k), handles._f2(t, k + 4), handles._f2(t, k + 8), t[k + 12], handles._i1(t, k + 16), handles._f1(t, k + 20),
           handles._i1(t, k + 24), handles._i1(t, k + 28), handles._i1(t, k + 32), handles._float(t, k + 36), handles._float(t, k + 40), t[k + 44],
           t[k + 48], handles._b1(t, k + 52), handles._b1(t, k + 56), handles._i1(t, k + 60), handles._i1(t, k + 64), handles._f2(t, k + 68),
           handles._f2(t, k + 72), handles._i1(t, k + 76), handles._f2(t, k + 80), handles._i1(t, k + 84), t[k + 88] != 0, handles._f1(t, k + 92),
           handles._i1(t, k + 96), handles._i1(t, k + 100), handles._f2(t, k + 104), handles._f2(t, k + 108), handles._f2(t, k + 112), handles._i1(t, k + 116),
           handles._f2(t, k + 120), handles._f2(t, k + 124), handles._i1(t, k + 128), handles._b2(t, k + 132), handles._f2(t, k + 136), handles._b2(t, k + 140),
           handles._f3(t, k + 144), handles._f2(t, k + 148), handles._f2(t, k + 152), handles._f2(t, k + 156), handles._f2(t, k + 160))
    return move(a, arm)
