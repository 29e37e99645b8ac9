"""The linear SARSA(lambda) learner: with one-hot features it is the tabular learner, bit for bit."""

import numpy as np
import pytest

from armtransfer.errors import InvalidParameterError
from armtransfer.learning import cells, linear, methods, sarsa, tiles
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.worlds.layout import ROOMS, Layout

SMALL = Layout(lo=-3, hi=3, walls=(((0, -3), (0, 3)),), doors=((0, 2),))


class TableMover:
    """A discrete robot seen as a continuous one: q is its cell's (x, y), no state numbers."""

    def __init__(self, robot, start_state):
        self.robot, self.start, self.n_actions = robot, int(start_state), robot.n_actions
        self._q = np.zeros(2)
        self.reset()

    @property
    def q(self):
        return self._q

    def reset(self):
        self.s = self.start
        self._q[:] = self.robot.layout.xy(int(self.robot.label[self.s]))
        return int(self.robot.label[self.s])

    def move(self, a):
        s2 = int(self.robot.next_state[self.s, a])
        if s2 == self.s:
            return -1
        self.s = s2
        self._q[:] = self.robot.layout.xy(int(self.robot.label[s2]))
        return int(self.robot.label[s2])

    def key(self):
        return self.s


def one_hot(layout):
    """One tile per cell: width 1, shifted half a tile, over the grid."""
    return tiles.TileCoding.over([layout.lo] * 2, [layout.hi] * 2, 1.0, 1, shift=0.5)


def test_one_hot_tiles_give_every_cell_its_own_feature():
    coding = one_hot(SMALL)
    feats = {int(coding.active(np.array(SMALL.xy(c), float))[0]) for c in range(SMALL.n_cells)}
    assert len(feats) == SMALL.n_cells and max(feats) < coding.size


def test_tilings_are_offset_and_each_point_has_one_feature_per_tiling():
    coding = tiles.TileCoding.over([0.0, 0.0], [1.0, 1.0], 0.25, 4)
    f = coding.active(np.array([0.3, 0.6]))
    assert len(f) == 4 and len(set(f.tolist())) == 4
    assert all(t * coding.per_tiling <= f[t] < (t + 1) * coding.per_tiling for t in range(4))
    near = coding.active(np.array([0.31, 0.6]))
    far = coding.active(np.array([0.9, 0.1]))
    assert (f == near).sum() >= 3 and (f == far).sum() == 0  # generalisation is local


@pytest.mark.parametrize("layout,task,method,cutoff", [
    (SMALL, None, "none", 0.0), (SMALL, None, "pseudo", 0.0), (SMALL, None, "first-visit", 1e-3),
    (SMALL, None, "progress", 1e-3), (SMALL, None, "potential", 1e-3), (ROOMS, 1, "none", 1e-3),
    (ROOMS, 1, "pseudo", 1e-3)])
def test_one_hot_linear_learner_takes_the_tabular_learners_steps_bit_for_bit(layout, task, method, cutoff):
    robot = grid_robot("fine", layout)
    if task is None:
        start, goal = layout.cell(-2, -2), layout.cell(2, -2)
    else:
        start, goal = TABLE_I[task].cells(layout)
    s0 = robot.start_state(start)
    config = LearnerConfig(trace_cutoff=cutoff, max_episodes=25, patience=5, max_total_steps=400_000)
    traj = trajectories.shortest(grid_robot("coarse", layout), start, goal)
    tab_shaping = None if method == "none" else methods.build_shaping(
        method, robot, traj, "auto", config.step_reward, gamma=config.gamma)
    tab = sarsa.learn(robot, s0, goal, config, np.random.default_rng(11), shaping=tab_shaping)
    lin = linear.learn(TableMover(robot, s0), goal, one_hot(layout), config, np.random.default_rng(11),
                       shaping=cells.cell_shaping(method, layout, traj, "auto", config),
                       linear=linear.LinearConfig(greedy_cap=robot.n_states + 1))
    assert lin.episode_steps.tolist() == tab.episode_steps.tolist()
    assert lin.greedy_lengths.tolist() == tab.greedy_lengths.tolist()
    assert (lin.exploration_steps, lin.converged, lin.total_steps, lin.greedy_steps) == (
        tab.exploration_steps, tab.converged, tab.total_steps, tab.greedy_steps)
    assert tab.episodes > 5  # more than a first episode was compared


def test_replacing_traces_differ_from_accumulating_ones_and_still_learn():
    robot = grid_robot("fine", SMALL)
    s0, goal = robot.start_state(SMALL.cell(-2, -2)), SMALL.cell(2, -2)
    config = LearnerConfig(max_episodes=60, patience=5)
    runs = {t: linear.learn(TableMover(robot, s0), goal, one_hot(SMALL), config, np.random.default_rng(2),
                            linear=linear.LinearConfig(traces=t)) for t in linear.TRACES}
    assert runs["replacing"].converged
    assert runs["replacing"].episode_steps.tolist() != runs["accumulating"].episode_steps.tolist()


def test_linear_learner_is_deterministic_for_a_seed():
    robot = grid_robot("fine", SMALL)
    s0, goal = robot.start_state(SMALL.cell(-2, -2)), SMALL.cell(2, -2)
    coding = tiles.TileCoding.over([-3, -3], [3, 3], 1.5, 4)
    config = LearnerConfig(max_episodes=20)
    a, b = (linear.learn(TableMover(robot, s0), goal, coding, config, np.random.default_rng(4)) for _ in range(2))
    assert a.episode_steps.tobytes() == b.episode_steps.tobytes()


def test_bad_settings_are_one_line_errors():
    with pytest.raises(InvalidParameterError, match="valid traces: accumulating, replacing"):
        linear.LinearConfig(traces="dutch")
    with pytest.raises(InvalidParameterError, match="valid methods: none, pseudo"):
        cells.check_method("guided")
    with pytest.raises(InvalidParameterError, match="tilings must be a positive integer"):
        tiles.TileCoding.over([0], [1], 0.1, 0)
    with pytest.raises(InvalidParameterError, match="at most"):
        tiles.TileCoding.over([0] * 6, [1] * 6, 0.01, 8)
