"""The rooms layout and the paper's grid robots."""

import numpy as np
import pytest

from armtransfer.tasks import ROOMS, TABLE_I, grid_robot, table_task
from armtransfer.tasks.catalog import TABLE_I_ROOMS, custom_task
from armtransfer.errors import InvalidCellError, InvalidTaskError, UnknownRobotError


def bfs_distance(robot, task):
    start, goal = task.cells()
    path = robot.shortest_path(robot.start_state(start), goal)
    return None if path is None else len(path) - 1


def test_grid_is_51_by_51_with_four_doors():
    assert ROOMS.width == 51 and (ROOMS.lo, ROOMS.hi) == (-25, 25)
    assert len(ROOMS.doors) == 4
    assert ROOMS.wall_mask.sum() > 0


@pytest.mark.parametrize("number", [1, 2, 3, 4])
def test_table_i_distances_for_the_fine_robot_are_the_papers(number):
    task = TABLE_I[number]
    assert bfs_distance(grid_robot("fine"), task) == task.paper_distance


@pytest.mark.parametrize("number", [1, 2, 3, 4])
def test_table_i_start_and_goal_lie_in_the_rooms_the_paper_names(number):
    task = TABLE_I[number]
    assert (ROOMS.room_of(*task.start), ROOMS.room_of(*task.goal)) == TABLE_I_ROOMS[number]


@pytest.mark.parametrize("number", [1, 2, 3, 4])
def test_coarse_robot_solves_every_table_i_task_in_half_the_steps(number):
    task = TABLE_I[number]
    assert bfs_distance(grid_robot("coarse"), task) == task.paper_distance // 2


def test_rooms_are_connected_only_through_doors():
    fine = grid_robot("fine")
    for door in ROOMS.doors:
        x, y = door
        # closing this door makes some cell pairs farther apart or disconnected
        from armtransfer.worlds.layout import Layout

        closed = Layout(ROOMS.lo, ROOMS.hi, ROOMS.walls, tuple(d for d in ROOMS.doors if d != door), ROOMS.rooms)
        robot = grid_robot("fine", closed)
        assert robot.n_states == fine.n_states - 1
    # every free cell is reachable from the start of task 1 in the full layout
    start, _ = TABLE_I[1].cells()
    assert fine.reachable_from(fine.start_state(start)).all()


def _state(robot, x, y):
    return robot.start_state(ROOMS.cell(x, y))


def _xy(robot, state):
    return ROOMS.xy(int(robot.label[state]))


def test_two_cell_move_over_a_wall_is_blocked_even_when_landing_cell_is_free():
    coarse = grid_robot("coarse")
    left = 3
    s = _state(coarse, -2, 0)  # (-3, 0) is wall, (-4, 0) is free
    assert ROOMS.free[ROOMS.cell(-4, 0)] and not ROOMS.free[ROOMS.cell(-3, 0)]
    assert coarse.next_state[s, left] == s
    # through the door at (-3, 10) the same move passes
    s = _state(coarse, -2, 10)
    assert _xy(coarse, coarse.next_state[s, left]) == (-4, 10)


def test_moves_off_the_grid_are_blocked():
    for name in ("fine", "coarse"):
        robot = grid_robot(name)
        s = _state(robot, 24, 24)
        forward, right = 0, 2
        if name == "fine":
            assert _xy(robot, robot.next_state[s, forward]) == (24, 25)
        else:
            assert robot.next_state[s, forward] == s  # would land on y = 26
        assert robot.next_state[_state(robot, 25, 0), right] == _state(robot, 25, 0)


def test_actions_follow_the_papers_example_directions():
    coarse = grid_robot("coarse")
    # {(-4,6),1}, {(-4,8),1}, {(-4,10),4}, {(-6,10),4}, {(-8,10),2}
    s = _state(coarse, -4, 6)
    for action, expect in [(0, (-4, 8)), (0, (-4, 10)), (3, (-6, 10)), (3, (-8, 10)), (1, (-8, 8))]:
        s = coarse.next_state[s, action]
        assert _xy(coarse, s) == expect


def test_wind_pushes_one_cell_right_unless_blocked():
    for name in ("fine", "coarse"):
        robot = grid_robot(name)
        assert _xy(robot, robot.wind_state[_state(robot, 0, 0)]) == (1, 0)
        s = _state(robot, -4, 0)  # the wall at x = -3 blocks the push
        assert robot.wind_state[s] == s
        s = _state(robot, 25, 5)  # the edge of the grid blocks it
        assert robot.wind_state[s] == s


def test_labels_of_grid_robots_are_their_cells():
    robot = grid_robot("fine")
    assert np.array_equal(robot.label, np.flatnonzero(ROOMS.free))
    for s in (0, 100, robot.n_states - 1):
        assert robot.canonical[robot.label[s]] == s


def test_bad_cells_and_tasks_are_refused_with_a_message():
    with pytest.raises(InvalidCellError, match="off the grid"):
        custom_task((0, 0), (30, 0))
    with pytest.raises(InvalidCellError, match="inside a wall"):
        custom_task((-3, 0), (0, 0))
    with pytest.raises(InvalidTaskError, match="same cell"):
        custom_task((0, 0), (0, 0))
    with pytest.raises(InvalidTaskError, match="valid tasks: 1, 2, 3, 4"):
        table_task(5)
    with pytest.raises(UnknownRobotError, match="valid names: coarse, fine"):
        grid_robot("medium")
