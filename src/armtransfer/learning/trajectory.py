"""The knowledge one robot hands another: a trajectory of (cell, action index) pairs.

As in the paper, a trajectory is ``{(s_t0, a_t0), ..., (s_tn, a_tn), s_tg}``: the shared
cells the source robot visited in order, the index of the action it took in each, and the
goal cell. The receiving robot does not know what the indices mean; it only uses the cells
(for pseudo rewards) and the index sequence (for action sequence mapping).

JSON form (``--trajectory PATH``)::

    {"format": "armtransfer-trajectory/1", "source": "coarse",
     "goal": [-8, 12],
     "steps": [{"cell": [0, 0], "action": 0}, {"cell": [0, 2], "action": 3}, ...]}

Action indices are 0-based (the paper's coarse actions 1-4 are 0-3 here).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path


from armtransfer.errors import InvalidTrajectoryError
from armtransfer.io import read_json, write_json_atomic
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.worlds.layout import ROOMS, Layout
from armtransfer.worlds.voxels import LEVELS

FORMAT = "armtransfer-trajectory/1"


@dataclass(frozen=True)
class Trajectory:
    cells: tuple[int, ...]
    """s_t0 .. s_tn: shared cell ids, the start first, the goal not included."""
    actions: tuple[int, ...]
    """a_t0 .. a_tn: the source robot's action index taken in each of ``cells``."""
    goal: int
    """s_tg, the goal cell."""
    source: str = "unknown"

    def __post_init__(self) -> None:
        if len(self.cells) != len(self.actions):
            raise InvalidTrajectoryError(
                f"a trajectory needs one action per cell, got {len(self.cells)} cells "
                f"and {len(self.actions)} actions"
            )
        if not self.cells:
            raise InvalidTrajectoryError("a trajectory needs at least one (cell, action) step")

    def __len__(self) -> int:
        return len(self.cells)

    @property
    def n(self) -> int:
        """The index n of the last trajectory state s_tn (pseudo rewards go up to n*K)."""
        return len(self.cells) - 1

    @property
    def start(self) -> int:
        return self.cells[0]

    def xy(self, layout: Layout = ROOMS) -> list[tuple[int, int]]:
        return [layout.xy(c) for c in self.cells]

    def to_json(self, layout: Layout = ROOMS) -> dict:
        """Cells as [x, y]; a voxel above the table (a spatial ``joint`` robot's) as [x, y, level]."""
        return {
            "format": FORMAT,
            "source": self.source,
            "goal": _cell_json(self.goal, layout),
            "steps": [
                {"cell": _cell_json(c, layout), "action": int(a)}
                for c, a in zip(self.cells, self.actions)
            ],
        }

    def save(self, path: str | os.PathLike, layout: Layout = ROOMS) -> None:
        write_json_atomic(path, self.to_json(layout))


def _cell_json(label: int, layout: Layout) -> list[int]:
    level, cell = divmod(int(label), layout.n_cells)
    return [*layout.xy(cell), level] if level else list(layout.xy(cell))


def from_path(robot: DiscreteRobot, path: list[tuple[int, int]]) -> Trajectory:
    """Turn a robot's own path ``[(state, action), ..., (goal_state, -1)]`` into a trajectory."""
    if len(path) < 2:
        raise InvalidTrajectoryError("a path needs at least one move to make a trajectory")
    cells = tuple(int(robot.label[s]) for s, _ in path[:-1])
    actions = tuple(int(a) for _, a in path[:-1])
    return Trajectory(cells, actions, int(robot.label[path[-1][0]]), source=robot.name)


def shortest(robot: DiscreteRobot, start_cell: int, goal_cell: int) -> Trajectory:
    """The source robot's breadth-first shortest path as a trajectory."""
    path = robot.shortest_path(robot.start_state(start_cell), goal_cell)
    if path is None:
        raise InvalidTrajectoryError(
            f"robot {robot.name} cannot reach the goal cell {robot.layout.xy(goal_cell)} "
            f"from {robot.layout.xy(start_cell)}"
        )
    return from_path(robot, path)


def via(robot: DiscreteRobot, start_cell: int, goal_cell: int, waypoints: list[int]) -> Trajectory:
    """A longer trajectory: the source robot's shortest paths start -> waypoints... -> goal.

    Used for Table IV's sub-optimal trajectories (detours, and loops when a waypoint lies
    behind the robot)."""
    state = robot.start_state(start_cell)
    full: list[tuple[int, int]] = []
    for cell in [*waypoints, goal_cell]:
        leg = robot.shortest_path(state, cell)
        if leg is None:
            raise InvalidTrajectoryError(f"robot {robot.name} cannot reach waypoint {robot.layout.xy(cell)}")
        full.extend(leg[:-1])
        state = leg[-1][0]
    full.append((state, -1))
    return from_path(robot, full)


def parse(data: object, layout: Layout = ROOMS, where: str = "trajectory") -> Trajectory:
    """Validate and convert the JSON form; every problem is a one-line error."""
    if not isinstance(data, dict):
        raise InvalidTrajectoryError(f"{where}: expected a JSON object with 'steps' and 'goal'")
    for key in ("steps", "goal"):
        if key not in data:
            raise InvalidTrajectoryError(f"{where}: missing key {key!r}")

    def cell_of(value: object, what: str) -> int:
        if (
            not isinstance(value, (list, tuple))
            or len(value) not in (2, 3)
            or not all(isinstance(v, int) and not isinstance(v, bool) for v in value)
        ):
            raise InvalidTrajectoryError(f"{where}: {what} must be [x, y] (or [x, y, level]) integers, got {value!r}")
        x, y = value[0], value[1]
        if len(value) == 3:  # a voxel of the 3D workspace: whether it is in a wall is the robot's to say
            level = value[2]
            if not 0 <= level < LEVELS:
                raise InvalidTrajectoryError(f"{where}: {what} level {level} is outside 0..{LEVELS - 1}")
            if not layout.in_grid(x, y):
                raise InvalidTrajectoryError(f"{where}: {what} ({x},{y}) is off the grid [{layout.lo}, {layout.hi}]")
            if level:
                return level * layout.n_cells + layout.cell(x, y)
        if not layout.in_grid(x, y):
            raise InvalidTrajectoryError(
                f"{where}: {what} ({x},{y}) is off the grid [{layout.lo}, {layout.hi}]"
            )
        if not layout.free[layout.cell(x, y)]:
            raise InvalidTrajectoryError(f"{where}: {what} ({x},{y}) is inside a wall")
        return layout.cell(x, y)

    steps = data["steps"]
    if not isinstance(steps, list) or not steps:
        raise InvalidTrajectoryError(f"{where}: 'steps' must be a non-empty list")
    cells, actions = [], []
    for i, step in enumerate(steps):
        if not isinstance(step, dict) or "cell" not in step or "action" not in step:
            raise InvalidTrajectoryError(f"{where}: step {i} must be an object with 'cell' and 'action'")
        cells.append(cell_of(step["cell"], f"step {i} cell"))
        a = step["action"]
        if not isinstance(a, int) or isinstance(a, bool) or a < 0:
            raise InvalidTrajectoryError(f"{where}: step {i} action must be an index >= 0, got {a!r}")
        actions.append(a)
    goal = cell_of(data["goal"], "goal")
    source = data.get("source", "unknown")
    return Trajectory(tuple(cells), tuple(actions), goal, source=str(source))


def load(path: str | os.PathLike, layout: Layout = ROOMS) -> Trajectory:
    data = read_json(path, "trajectory file", InvalidTrajectoryError)
    return parse(data, layout, where=f"trajectory file {str(Path(path))!r}")


def check_source(traj: Trajectory, robot: DiscreteRobot) -> None:
    """The trajectory is one the robot said to have made it can make: its action indices are
    the robot's, and each step's action takes it from the step's cell to the next one (the
    last to the goal), as :func:`states_along` retraces it."""
    bad = [a for a in traj.actions if not 0 <= a < robot.n_actions]
    if bad:
        raise InvalidTrajectoryError(
            f"the trajectory has action index {bad[0]} but the source robot {robot.name} has "
            f"{robot.n_actions} actions (0..{robot.n_actions - 1})")
    states_along(robot, traj)


def states_along(robot: DiscreteRobot, traj: Trajectory) -> list[int]:
    """The robot's states along the trajectory, from its start state: the robot is
    deterministic, so the trajectory's actions give its states back. A step whose cell is not
    where the robot is, or an end that is not the goal, is an error naming the step."""
    layout = robot.layout
    s = robot.start_state(traj.start)
    states = [s]
    for k, (cell, a) in enumerate(zip(traj.cells, traj.actions)):
        if int(robot.label[s]) != cell or not 0 <= a < robot.n_actions:
            raise InvalidTrajectoryError(
                f"the trajectory's step {k} at {layout.xy(cell)} is not where {robot.name} is after step "
                f"{k - 1} ({layout.xy(int(robot.label[s]))}): the trajectory is not a path of {robot.name}")
        s = int(robot.next_state[s, a])
        states.append(s)
    if int(robot.label[s]) != traj.goal:
        raise InvalidTrajectoryError(
            f"the trajectory's last step takes {robot.name} to {layout.xy(int(robot.label[s]))}, not to its goal "
            f"{layout.xy(traj.goal)}")
    return states


def check_task(traj: Trajectory, start_cell: int, goal_cell: int, layout: Layout = ROOMS) -> None:
    """A transferred trajectory must be for this task: same start and goal cells."""
    if traj.start != start_cell or traj.goal != goal_cell:
        raise InvalidTrajectoryError(
            f"the trajectory goes {layout.xy(traj.start)} -> {layout.xy(traj.goal)} but the task is "
            f"{layout.xy(start_cell)} -> {layout.xy(goal_cell)}"
        )
