"""Method ``corridor``: ``guided`` whose planner keeps its optimism for untried moves along the
trajectory (``guide.corridor_prior``)."""

import numpy as np

from armtransfer.learning import guide, methods, sarsa
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from test_first_exposure import SMALL, assert_kernel_is_reference, small_task

EXACT = LearnerConfig(trace_cutoff=0.0, max_episodes=6, patience=1000)


def test_the_prior_fades_with_the_distance_from_the_route_and_the_route_left():
    lxy = np.array([[0.0, 0.0], [0.0, 1.0], [0.0, 4.0], [3.0, 0.0]])
    tx, ty, trem = np.array([0.0, 3.0]), np.array([0.0, 0.0]), np.array([3.0, 0.0])
    flat = guide.corridor_prior(lxy, tx, ty, trem, radius=1.5, fade=0.0)
    assert (flat == guide.UNTRIED).all()  # plan's and guided's optimism, unchanged
    p = guide.corridor_prior(lxy, tx, ty, trem, radius=1.5, fade=10.0, route=2.0)
    # on the first cell: 3 cells of route left; 1 cell off it: within the radius; 4 off: 2.5 beyond
    assert np.allclose(p, guide.UNTRIED - np.array([6.0, 6.0, 10.0 * 2.5 + 6.0, 0.0]))


def test_corridor_is_guided_told_nothing_more_than_the_trajectory():
    """The same guide as guided's but the planner's prior, which reads the trajectory's cells and
    robot 2's labels only: the task's goal, the map and the robot's table are not arguments."""
    fine, coarse, start, goal = small_task()
    traj = trajectories.shortest(coarse, start, goal)
    g = methods.build_shaping("guided", fine, [traj], "auto", -1.0).guide
    c = methods.build_shaping("corridor", fine, [traj], "auto", -1.0).guide
    for field in ("feat", "lxy", "tx", "ty", "trem", "tstart", "params"):
        assert np.array_equal(getattr(g, field), getattr(c, field)), field
    assert (g.untried == guide.UNTRIED).all() and (c.untried < guide.UNTRIED).any()
    lxy = np.array([SMALL.xy(int(x)) for x in fine.label], float)
    on = np.array([SMALL.xy(int(x)) for x in (*traj.cells, traj.goal)], float)
    d = np.sqrt(((lxy[:, None] - on[None]) ** 2).sum(-1)).min(axis=1)
    assert c.untried[d > 2].max() < c.untried[d == 0].min()  # off the route is valued below anywhere on it
    assert methods.get("corridor").baseline == "plan"


def test_kernel_is_bit_identical_to_the_dense_reference_for_corridor():
    fine, coarse, start, goal = small_task()
    traj = trajectories.shortest(coarse, start, goal)
    sh = methods.build_shaping("corridor", fine, [traj], "auto", -1.0)
    steps = assert_kernel_is_reference(fine, start, goal, EXACT, 11, sh)
    assert len(steps) == EXACT.max_episodes


def test_corridor_tries_fewer_moves_away_from_the_route_than_guided():
    """After the first episode guided's planner leads to every untried move in the world;
    corridor's leads to those along the route first (same trial streams)."""
    fine, coarse, start, goal = small_task()
    traj = trajectories.shortest(coarse, start, goal)
    s0 = fine.start_state(start)
    lxy = np.array([SMALL.xy(int(x)) for x in fine.label], float)
    on = np.array([SMALL.xy(int(x)) for x in (*traj.cells, traj.goal)], float)
    far = np.sqrt(((lxy[:, None] - on[None]) ** 2).sum(-1)).min(axis=1) > methods.CORRIDOR_RADIUS
    tried = {}
    for name in ("guided", "corridor"):
        sh = methods.build_shaping(name, fine, [traj], "auto", -1.0)
        m = guide.new_model(sh.guide, fine.n_states, fine.n_actions)
        sarsa.learn(fine, s0, goal, LearnerConfig(max_episodes=30), np.random.default_rng(3), shaping=sh,
                    guide_model=m)
        tried[name] = int((m.planner.n_succ.reshape(fine.n_states, -1) > 0)[far].sum())
    assert tried["corridor"] < tried["guided"], tried
