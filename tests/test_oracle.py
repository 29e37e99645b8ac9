"""The `oracle` bound: the optimal value of the task as a potential, which passes the farming
check's self-loops where the earlier -2 x distance potential failed."""

from __future__ import annotations

import numpy as np
import pytest

from armtransfer.errors import InvalidParameterError
from armtransfer.learning import farming, potentials
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.shaping import Shaping
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.grid_robots import grid_robot


@pytest.mark.parametrize("robot, task", [("fine", 4), ("coarse", 3), ("fine", 1)])
def test_the_oracle_passes_the_self_loop_check(robot, task):
    r = grid_robot(robot)
    _, goal = table_task(task).cells()
    config = LearnerConfig()
    phi = potentials.oracle(r, goal, config.gamma, config.step_reward)
    farming.check_self_loops("oracle", r, goal, Shaping.potential(phi), config)
    farming.check_self_loops("oracle", r, goal, Shaping.potential(phi), config, wind=0.01)
    d = potentials.goal_distances(r, goal)
    assert phi[d == 0].tolist() == [0.0] * int((d == 0).sum())
    assert np.all(np.diff(phi[np.argsort(d, kind="stable")]) <= 0)  # farther is lower


def test_the_earlier_oracle_failed_it_on_task_4():
    r = grid_robot("fine")
    _, goal = table_task(4).cells()
    old = -2.0 * potentials.goal_distances(r, goal).astype(np.float64)
    with pytest.raises(InvalidParameterError, match="leaves its state unchanged"):
        farming.check_self_loops("oracle", r, goal, Shaping.potential(old), LearnerConfig())


def test_the_oracle_is_the_optimal_value_without_shaping():
    r = grid_robot("fine")
    _, goal = table_task(1).cells()
    start, _ = table_task(1).cells()
    phi = potentials.oracle(r, goal, 0.99, -1.0)
    d = r.distance(r.start_state(start), goal)
    assert phi[r.start_state(start)] == pytest.approx(-(1 - 0.99 ** d) / 0.01)
