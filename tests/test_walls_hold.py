"""No move of an arm robot goes through a wall or into the table, by a checker written apart
from the compile (``wallcheck``: 0.5 mm of tool travel between checks, ``mj_forward`` at each,
arm-scenery contacts deeper than 0.1 mm counted).

The checker is first shown not to be blind: it finds penetration in moves that are not the
robot's own (two states across a wall, random pairs of states). The default set checks a small
sample of a few robots' moves; the slow set every door-crossing move of every built-in robot,
the 12 mm pen file and a spatial ``joint`` robot, on the rooms and on rooms11, with a random
sample of the rest.
"""

import numpy as np
import pytest

import menagerie_like as ml
import wallcheck as wc
from armtransfer.ik.replay import PENETRATION_TOLERANCE, replay, robot_scene
from armtransfer.ik.sweep import TOLERANCE, SweepChecker
from armtransfer.tasks.arms import arm_robot, robot, robot_specs, spatial_joint_specs, tasks_solvable, walls_cause
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.worlds.resolve import world

LIMIT = 5e-4
"""Deepest penetration (m) a robot's move may show to the checker."""


def _across_a_wall(r):
    """Pairs of canonical states two cells either side of a wall cell, along x or y."""
    lay = r.layout
    pairs = []
    for c in np.flatnonzero(lay.wall_mask.reshape(-1)):
        x, y = lay.xy(int(c))
        for dx, dy in ((1, 0), (0, 1)):
            a, b = (x - 2 * dx, y - 2 * dy), (x + 2 * dx, y + 2 * dy)
            if lay.in_grid(*a) and lay.in_grid(*b):
                sa, sb = r.canonical[lay.cell(*a)], r.canonical[lay.cell(*b)]
                if sa >= 0 and sb >= 0:
                    pairs.append((int(sa), int(sb)))
    return pairs


@pytest.fixture(scope="module")
def planar2():
    return robot("planar2:joint")


def test_the_checker_finds_the_stylus_in_a_wall_on_a_move_across_it(planar2):
    pairs = _across_a_wall(planar2)[:5]
    checker = wc.checker_for(planar2)
    depths = [checker.move(planar2.arm.qpos[a], planar2.arm.qpos[b])[0] for a, b in pairs]
    assert len(pairs) == 5 and min(depths) > 1e-3, depths


def test_the_sweep_blocks_what_the_checker_finds_and_passes_only_what_it_clears(planar2):
    """Random pairs of states, not the robot's moves: the swept check and the checker agree
    that a move it passes keeps out of the walls."""
    rng = np.random.default_rng(3)
    q = planar2.arm.qpos
    scene = robot_scene(planar2)
    sweep = SweepChecker(scene)
    checker = wc.WallChecker(scene.model, scene.tip)
    n = len(q)
    found = passed = 0
    for _ in range(60):
        a, b = rng.integers(n, size=2)
        qb = q[a] + (q[b] - q[a]) * 0.15  # a short move, so that some are clear
        depth = checker.move(q[a], qb)[0]
        clear = sweep.clear(q[a], qb)
        found += depth > LIMIT
        passed += clear
        if clear:
            assert depth <= TOLERANCE + wc.DEPTH, (a, b, depth)
        if depth > LIMIT:
            assert not clear
    assert found >= 3 and passed >= 10, (found, passed)


@pytest.mark.parametrize("spec", ["planar3:joint", "planar2:cartesian"])
def test_a_sample_of_door_crossings_keeps_out_of_the_walls(spec):
    r = robot(spec)
    chosen = wc.sample(r, 10, np.random.default_rng(0), max_doors=25)
    assert wc.door_crossing(r, chosen).sum() >= 5
    worst = max(wc.check(r, chosen), key=lambda m: m.depth)
    assert worst.depth <= LIMIT, worst


def test_a_replay_through_a_wall_is_not_reached_and_says_how_deep(planar2):
    """Two states either side of a wall, replayed as if they were one move: the stylus is
    pushed through the wall and ends over the goal, but the replay does not call that reached."""
    for a, b in _across_a_wall(planar2):
        rp = replay(planar2, [a, b], servos="scene")
        if rp.ended_on_goal:
            break
    report = rp.report()
    assert rp.ended_on_goal and not rp.reached_goal
    assert report["max_penetration_mm"] > 1000 * PENETRATION_TOLERANCE and "wall wall_" in report["penetration_contact"]
    assert "mm into a wall" in report["shortfall"]


def test_a_replay_of_a_shortest_path_keeps_out_of_the_walls(planar2):
    lay = planar2.layout
    path = planar2.shortest_path(planar2.start_state(lay.free_cell(0, 0)), lay.free_cell(4, 5))
    rp = replay(planar2, [s for s, _ in path])
    assert rp.reached_goal and rp.report()["max_penetration_mm"] <= 1000 * PENETRATION_TOLERANCE


# --------------------------------------------------------------------------- slow: all door crossings


def _wide_pen(tmp_path_factory):
    return ml.ALL["planar5_wide_pen"](tmp_path_factory.mktemp("pen"))


def _all_doors(r, n_random=300):
    chosen = wc.sample(r, n_random, np.random.default_rng(0))
    results = wc.check(r, chosen)
    bad = [m for m in results if m.depth > LIMIT]
    return len(results), bad


@pytest.mark.slow
@pytest.mark.parametrize("where", ["rooms", "rooms11"])
@pytest.mark.parametrize("spec", robot_specs() + spatial_joint_specs())
def test_every_door_crossing_of_every_built_in_robot_keeps_out_of_the_walls(spec, where):
    r = robot(spec, layout=world(where))
    checked, bad = _all_doors(r)
    assert checked > 0 and not bad, (len(bad), bad[:3])


@pytest.mark.slow
@pytest.mark.parametrize("actions", ["joint", "cartesian"])
def test_the_wide_pen_keeps_out_of_the_walls_and_names_why_it_reaches_little(tmp_path_factory, actions):
    path = _wide_pen(tmp_path_factory)
    r = arm_robot(None, actions, xml_path=path, tip_site="pen_tip", base_pos=(-0.2, -0.1, 0.009), base_yaw=0.0)
    checked, bad = _all_doors(r)
    assert checked > 0 and not bad, (len(bad), bad[:3])
    # a 12 mm pen passes no 1 cm door: it reaches about the room it starts in, and says why
    assert 0.1 < r.arm.reach < 0.35 and tasks_solvable(r) < len(TABLE_I)
    cause = walls_cause(r)
    assert cause.startswith("a geom of pen, 12.0 mm across at the walls' height") and "--cell-size 0.016" in cause
