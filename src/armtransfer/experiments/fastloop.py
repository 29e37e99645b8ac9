"""An episode of the linear learner on the continuous arm, compiled whole: the arm's move
(``ik.fastmove.move``, MuJoCo called from numba) and the learner's update
(``learning.linear.td_step``) in one loop, with no Python per step.

:func:`episode_steps` gives ``learning.linear.learn`` its ``steps_by``: the same steps as
``learn``'s own loop, in the same order, with the same draws (the uniforms are refilled from the
trial's generator where the loop would refill them), so a trial's result is the same bytes
(``tests/test_continuous_more.py``). The loop leaves to Python what it cannot do: a refill of
the uniforms, and a move the compiled move hands back (``ik.fastmove.PYTHON``), which is taken
by ``ContinuousArm.move``. An arm with actuation noise has no compiled move: None.
"""

from __future__ import annotations

from pathlib import Path

import numba

from armtransfer.ik import fastline, fastmove, fastmove3d
from armtransfer.learning import jitcache, linear, sarsa, tiles, traces

REACHED, LIMIT, REFILL, PYTHON = range(4)


@numba.njit(cache=True, nogil=True)
def _run(arm, w, q, lower, width, offsets, dims, strides, per_tiling, table, feats, qrow, tr_sa, tr_e, pos, p, c, u,
         bonus, traj_index, phi, paid, low, a, label, best, steps, limit, goal):
    """``learn``'s loop from ``steps`` until the goal, ``limit`` steps, a refill or a move for
    Python: (why it stopped, a, label, best, steps)."""
    while steps < limit:
        if c[linear.I_U] > low:
            return REFILL, a, label, best, steps
        label2 = fastmove.move(a, arm)
        if label2 == fastmove.PYTHON:
            return PYTHON, a, label, best, steps
        if label2 < 0:
            label2 = label
        steps += 1
        a, best = linear.td_step(w, q, lower, width, offsets, dims, strides, per_tiling, table, feats, qrow, tr_sa,
                                 tr_e, pos, p, c, u, bonus, traj_index, phi, paid, a, label, label2, goal, best)
        if label2 == goal:
            return REACHED, a, label2, best, steps
        label = label2
    return LIMIT, a, label, best, steps


@numba.njit(cache=True, nogil=True)
def _run3d(arm, w, q, lower, width, offsets, dims, strides, per_tiling, table, feats, qrow, tr_sa, tr_e, pos, p, c, u,
           bonus, traj_index, phi, paid, low, a, label, best, steps, limit, goal):
    """:func:`_run` with the spatial arm's move (``ik.fastmove3d.move``)."""
    while steps < limit:
        if c[linear.I_U] > low:
            return REFILL, a, label, best, steps
        label2 = fastmove3d.move(a, arm)
        if label2 == fastmove.PYTHON:
            return PYTHON, a, label, best, steps
        if label2 < 0:
            label2 = label
        steps += 1
        a, best = linear.td_step(w, q, lower, width, offsets, dims, strides, per_tiling, table, feats, qrow, tr_sa,
                                 tr_e, pos, p, c, u, bonus, traj_index, phi, paid, a, label, label2, goal, best)
        if label2 == goal:
            return REACHED, a, label2, best, steps
        label = label2
    return LIMIT, a, label, best, steps


def episode_steps(arm) -> linear.EpisodeSteps | None:
    """``learn``'s ``steps_by`` for ``arm`` (an ``ik.continuous.ContinuousArm`` or an
    ``ik.continuous3d.SpatialContinuousArm``), or None when the arm has no compiled move."""
    if not hasattr(arm, "fast") or arm.fast() is None:
        return None
    kernel = _run3d if hasattr(arm, "vox") else _run

    def run(L: linear.Learner, a: int, label: int, best: float, limit: int, goal: int) -> tuple[int, int, float, bool]:
        steps = 0
        bonus, traj_index, phi, paid = L.rewards
        while True:
            state = arm.fast()
            why, a, label, best, steps = kernel(state, L.w, arm.q, *L.coding, L.feats, L.qrow, L.tr_sa, L.tr_e, L.pos,
                                              L.p, L.c, L.u, bonus, traj_index, phi, paid, L.low, a, label, best,
                                              steps, limit, goal)
            arm.fast_done()
            if why == REACHED:
                return steps, a, best, True
            if why == LIMIT:
                return steps, a, best, False
            if why == REFILL:
                L.refill()
                continue
            label2 = arm.move(a)  # the move the compiled one handed back, in Python, then learn's step
            if label2 < 0:
                label2 = label
            steps += 1
            if L.c[linear.I_U] > L.low:
                L.refill()
            a, best = linear.td_step(L.w, arm.q, *L.coding, L.feats, L.qrow, L.tr_sa, L.tr_e, L.pos, L.p, L.c, L.u,
                                     bonus, traj_index, phi, paid, a, label, label2, goal, best)
            if label2 == goal:
                return steps, a, best, True
            label = label2
            if steps >= limit:
                return steps, a, best, False

    return run


def _stale_caches() -> None:
    """numba keys a cached kernel on its own file only: empty these kernels' caches when a file
    they call into changed (``learning.jitcache``)."""
    arcs = Path(fastmove.__file__).with_name("arcs.py")
    jitcache.invalidate_stale(fastmove.__name__, [fastmove._touches_now, fastmove._touches, fastmove.move,
                                                  fastmove.planar_move],
                              [arcs, Path(fastmove.__file__).with_name("swept.py"),
                               Path(fastmove.__file__).with_name("handles.py")])
    swept = Path(fastmove3d.__file__).with_name("swept.py")
    handles = Path(fastmove3d.__file__).with_name("handles.py")
    jitcache.invalidate_stale(fastmove3d.__name__, [fastmove3d.move, fastmove3d.spatial_move],
                              [swept, handles, fastmove.__file__])
    jitcache.invalidate_stale(fastline.__name__, [fastline.line_move], [swept, handles, fastmove.__file__])
    jitcache.invalidate_stale(__name__, [_run, _run3d], [fastmove.__file__, fastmove3d.__file__, swept, handles, arcs,
                                                         linear.__file__, tiles.__file__, traces.__file__,
                                                         sarsa.__file__])


_stale_caches()
