"""The continuous arms' moves, checked by an independent checker (``tests/sweepcheck.py``: the
tool point at most 0.5 mm between checked points, ``mj_forward`` at each, arm contacts with the
table or a wall deeper than 0.1 mm counted), written apart from the swept check it checks."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from armtransfer.ik.continuous import BLOCKED
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.continuous import continuous_arm
from armtransfer.worlds.resolve import world

sys.path.insert(0, str(Path(__file__).parent))
from sweepcheck import SweepChecker  # noqa: E402

SMALL = world("rooms11")
LIMIT = 5e-4
"""Metres: the deepest penetration an accepted move may have."""


def _walk(arm, moves: int, seed: int, box: bool = False):
    """(whole configuration before, after, accepted) of ``moves`` random moves from the start."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(moves):
        before = arm.data.qpos.copy()
        if box:
            v = arm.move_by(rng.uniform(-1.0, 1.0, arm.dof) * arm.step)
        else:
            v = arm.move(int(rng.integers(arm.n_actions)))
        out.append((before, arm.data.qpos.copy(), v != BLOCKED))
        if rng.random() < 0.002:
            arm.reset()
    return out


def _depths(arm, walk) -> tuple[list[float], int]:
    chk = SweepChecker(arm.scene.model, arm.scene.tip)
    accepted = [chk.move_depth(a, b) for a, b, ok in walk if ok]
    return accepted, sum(ok for _, _, ok in walk)


def test_no_accepted_spatial_move_penetrates_and_the_checker_sees_blocked_ones():
    arm = continuous_arm("ur5e_like", layout=SMALL)
    arm.place(SMALL.cell(0, 2))  # two cells from a wall, over the table
    walk = _walk(arm, 300, 0)
    depths, n = _depths(arm, walk)
    assert n > 200 and max(depths) <= LIMIT
    # the same checker on the moves the arm refused, taken anyway: some of them penetrate
    chk = SweepChecker(arm.scene.model, arm.scene.tip)
    refused = []
    for before, _, ok in walk:
        if ok:
            continue
        for a in range(arm.n_actions):
            q = before.copy()
            q[arm.moved[a // 2]] += (1 - 2 * (a % 2)) * arm.step
            refused.append(chk.move_depth(before, q))
    assert max(refused) > 1e-3
    # box moves (several joints at once, the Box environment's): none accepted penetrates either
    arm.reset()
    depths, n = _depths(arm, _walk(arm, 150, 2, box=True))
    assert n > 50 and max(depths) <= LIMIT


@pytest.mark.parametrize("spec", ["planar3", "ur5e_like"])
def test_the_environments_compiled_move_is_the_arms_python_move(spec):
    """``fast_step`` (the compiled move, called by address, that ``ContinuousArmRooms-v0`` steps
    by) walks the configurations, labels, tool points and move counts of ``move``, resets and
    Python moves in between."""
    arms = [continuous_arm(spec, layout=SMALL) if spec.endswith("like") else continuous_arm(spec) for _ in range(2)]
    start = SMALL.cell(0, 2) if spec.endswith("like") else TABLE_I[1].cells(arms[0].layout)[0]
    for a in arms:
        a.place(start)
    slow, fast = arms
    blocked = 0
    for k, a in enumerate(np.random.default_rng(4).integers(slow.n_actions, size=1500).tolist()):
        if k % 400 == 399:
            slow.reset(), fast.reset()
        if k % 300 == 0:
            slow.move(1), fast.move(1)
        v = slow.move(a)
        assert v == fast.fast_step(a)
        assert slow.q.tobytes() == fast.q.tobytes() and slow.tip() == fast.tip() and slow.key() == fast.key()
        assert slow.moves == fast.moves and slow.label == fast.label
        blocked += v == BLOCKED
    assert 0 < blocked < 1500


@pytest.mark.slow
@pytest.mark.parametrize("spec", ["ur5e_like", "panda_like", "planar3", "planar4"])
@pytest.mark.parametrize("box", [False, True])
def test_no_accepted_move_of_a_continuous_arm_penetrates(spec, box):
    arm = continuous_arm(spec, layout=SMALL) if spec.endswith("like") else continuous_arm(spec)
    layout = arm.layout
    arm.place(layout.cell(0, 2) if spec.endswith("like") else TABLE_I[1].cells(layout)[0])
    depths, n = _depths(arm, _walk(arm, 3000, 1, box))
    assert n > 500 and max(depths) <= LIMIT, (n, sorted(depths)[-5:])
