"""Gymnasium environments over any discrete robot (rooms-world grid robots and arms).

``import armtransfer`` registers ``armtransfer/Rooms-v0`` (a grid robot) and
``armtransfer/ArmRooms-v0`` (an arm robot); then ``gymnasium.make("armtransfer/Rooms-v0",
task=1, robot="fine")``. ``world=`` names the world (``"rooms11"``, ``"generated:3"``, a layout
file; the paper's rooms by default) and ``task`` one of its tasks. The observation is the robot's own state index, the action an index into its action model; each step costs
``step_reward`` and reaching the goal cell pays ``goal_reward`` and terminates. With
``wind=p`` the robot is pushed one cell towards +x with probability p after its move.
"""

from __future__ import annotations

import numbers
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

import armtransfer.checks as checks
from armtransfer.errors import InvalidParameterError, InvalidTaskError
from armtransfer.ik import offscreen
from armtransfer.registration import register_envs  # noqa: F401  (kept importable from here)
from armtransfer.tasks.arms import arm_robot, parse_robot_spec
from armtransfer.tasks.catalog import Task, as_xy, custom_task, table_task, world_task
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.worlds.resolve import is_default, world as resolve_world


RGB_WITHOUT = "make the environment with render_mode='ansi' or none"
"""How an arm environment goes on where no offscreen OpenGL backend works."""


class RoomsRules:
    """The rules of a start/goal task for one discrete robot, shared by the Gymnasium
    environment and the dm_control task (``armtransfer.dmc.task``): an action moves the robot
    by its own transition table, wind then pushes it one cell towards +x with probability
    ``wind``, every step costs ``step_reward`` and reaching the goal cell pays ``goal_reward``
    and ends the episode."""

    def _set_rules(self, robot: DiscreteRobot, task: Task, wind: float, step_reward: float,
                   goal_reward: float) -> None:
        wind = check_wind(wind)
        step_reward = checks.real(step_reward, "step_reward")
        goal_reward = checks.real(goal_reward, "goal_reward")
        self.robot = robot
        self.task = task
        self.start_state, self.goal_cell = task_states(robot, task)
        self.wind = float(wind)
        self.step_reward = float(step_reward)
        self.goal_reward = float(goal_reward)
        self.state = self.start_state

    def _move(self, action: int, rng: np.random.Generator) -> int:
        """The robot's next state after ``action``, the wind drawn from ``rng``; it becomes the state."""
        s = int(self.robot.next_state[self.state, action])
        if self.wind > 0.0 and rng.random() < self.wind:
            s = int(self.robot.wind_state[s])
        self.state = s
        return s

    def _outcome(self) -> tuple[float, bool]:
        """(the reward of the step that led to the current state, whether it is at the goal)."""
        terminated = int(self.robot.label[self.state]) == self.goal_cell
        return self.step_reward + (self.goal_reward if terminated else 0.0), terminated


class RobotRoomsEnv(RoomsRules, gym.Env):
    """A start/goal task for one discrete robot, in the style of Gymnasium's toy_text."""

    metadata = {"render_modes": ["ansi", "rgb_array"], "render_fps": 4}

    def __init__(
        self,
        robot: DiscreteRobot,
        task: Task,
        wind: float = 0.0,
        step_reward: float = -1.0,
        goal_reward: float = 0.0,
        render_mode: str | None = None,
    ) -> None:
        self._set_rules(robot, task, wind, step_reward, goal_reward)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise InvalidParameterError(
                f"unknown render_mode {render_mode!r}; valid: {', '.join(self.metadata['render_modes'])}")
        self.render_mode = render_mode
        if render_mode == "rgb_array" and robot.arm is not None:  # an arm is drawn by OpenGL: can it be here?
            offscreen.require(RGB_WITHOUT)
        self.observation_space = spaces.Discrete(robot.n_states)
        self.action_space = spaces.Discrete(robot.n_actions)
        self._snapshot = None

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        check_reset_options(options)
        super().reset(seed=seed)
        self.state = self.start_state
        return int(self.state), {"label": int(self.robot.label[self.state])}

    def step(self, action):
        if isinstance(action, (bool, np.bool_)) or not self.action_space.contains(action):  # as Gymnasium's own
            raise InvalidParameterError(
                f"action must be an integer in 0..{self.robot.n_actions - 1} (the action space "
                f"{self.action_space}), got {action!r}")
        s = self._move(int(action), self.np_random)
        reward, terminated = self._outcome()
        return s, reward, terminated, False, {"label": int(self.robot.label[s])}

    def render(self):
        """``ansi``: a text map; ``rgb_array``: for an arm robot the arm drawn by MuJoCo
        offscreen at the current state's configuration with the cell grid, the goal and the
        tip's cell (an ``OffscreenError`` naming what to install where OpenGL cannot draw it);
        for a grid robot the layout drawn cell by cell."""
        label = int(self.robot.label[self.state])
        layout = self.robot.layout
        if self.render_mode == "ansi":
            x, y = layout.xy(label)
            gx, gy = layout.xy(self.goal_cell)
            return layout.ascii({(x, y): "R", (gx, gy): "G"}) + "\n"
        if self.render_mode == "rgb_array":
            if self.robot.arm is None:
                return grid_image(layout, label, self.goal_cell)
            if self._snapshot is None:
                from armtransfer.ik.replay import robot_scene  # MuJoCo: only when a frame is rendered
                from armtransfer.ik.snapshot import ArmSnapshot  # MuJoCo: only when a frame is rendered

                self._snapshot = ArmSnapshot(robot_scene(self.robot), without=RGB_WITHOUT)
            return self._snapshot.render(self.robot.arm.qpos[self.state], self.goal_cell, label)
        return None

    def close(self) -> None:
        if self._snapshot is not None:
            self._snapshot.close()
            self._snapshot = None
        super().close()


CELL_PIXELS = 6
FREE_RGB, WALL_RGB = (235, 225, 205), (90, 75, 70)
ROBOT_RGB, GOAL_RGB = (40, 90, 230), (30, 190, 50)


def grid_image(layout, robot_cell: int, goal_cell: int, cell_pixels: int = CELL_PIXELS) -> np.ndarray:
    """The layout from above (+y up) as uint8 RGB, walls dark, goal green, robot blue."""
    rgb = np.where(layout.wall_mask[..., None], np.array(WALL_RGB, np.uint8), np.array(FREE_RGB, np.uint8))
    for cell, colour in ((goal_cell, GOAL_RGB), (robot_cell, ROBOT_RGB)):
        x, y = layout.xy(int(cell))
        rgb[y - layout.lo, x - layout.lo] = colour
    image = rgb[::-1].repeat(cell_pixels, axis=0).repeat(cell_pixels, axis=1)
    return np.ascontiguousarray(image)


def check_wind(wind: float) -> float:
    return checks.probability(wind, "wind")


def task_states(robot: DiscreteRobot, task: Task) -> tuple[int, int]:
    """(the robot's start state, the goal cell) of ``task``; a cell the robot cannot reach is a
    one-line error."""
    start_cell, goal_cell = task.cells()
    start = robot.start_state(start_cell)
    robot.start_state(goal_cell, what="goal")  # the goal must be reachable by label
    return start, goal_cell


def rooms_task(task: int | str | None = 1, start: tuple[int, int] | None = None,
               goal: tuple[int, int] | None = None, world: Any = None) -> Task:
    """A task of the world (``worlds.resolve.world``; Table I's on the paper's rooms, the
    default), or the custom task from ``start`` to ``goal`` (cells (x, y) or 'X,Y')."""
    layout = resolve_world(world)
    if start is None and goal is None:
        if is_default(layout):
            if isinstance(task, bool) or not isinstance(task, numbers.Integral):
                raise InvalidTaskError(f"a task is a Table I task number (1-4), got {task!r}")
            return table_task(int(task))
        return world_task(layout, task)
    if start is None or goal is None:
        raise InvalidTaskError("start and goal go together")
    return custom_task(as_xy(start, "start"), as_xy(goal, "goal"), layout)


def make_rooms_env(
    task: int | str | None = 1,
    robot: str = "fine",
    start: tuple[int, int] | None = None,
    goal: tuple[int, int] | None = None,
    world: Any = None,
    **kwargs: Any,
) -> RobotRoomsEnv:
    """Entry point of ``armtransfer/Rooms-v0``: a grid robot on a task of ``world`` (Table I's on
    the paper's rooms, the default) or a custom task."""
    check_options(kwargs)
    the_task = rooms_task(task, start, goal, world)
    return RobotRoomsEnv(grid_robot(robot, the_task.layout), the_task, **kwargs)


TASK_OPTIONS = ("wind", "step_reward", "goal_reward", "render_mode")
"""The keywords of an environment that set up its task (beside task, start and goal)."""


def check_reset_options(options: object) -> None:
    """``reset(options=...)`` of every environment here: no reset option exists (the task is
    chosen when the environment is made), so anything but None or ``{}`` is an error, not
    silently ignored."""
    if options is None or (isinstance(options, dict) and not options):
        return
    if not isinstance(options, dict):
        raise InvalidParameterError(f"reset options must be a dict or None, got {type(options).__name__}")
    raise InvalidParameterError(f"unknown reset option {next(iter(options))!r}; these environments take no reset "
                                "options (the task is chosen when the environment is made)")


def check_options(kwargs: dict, extra: tuple[str, ...] = ()) -> None:
    """An unknown keyword is a one-line error listing the valid ones."""
    unknown = sorted(k for k in kwargs if k not in TASK_OPTIONS + extra)
    if unknown:
        raise InvalidParameterError(
            f"unknown environment option {unknown[0]!r}; valid options: {', '.join(TASK_OPTIONS + extra)}")


ARM_OPTIONS = ("cell_size", "xml_path", "tip_site", "tip_body", "tip_offset", "tool", "arm_name", "base_pos", "base_yaw",
               "joint_step", "cache")
"""The keywords of an arm environment that build its robot (the rest set up the task)."""


def rooms_arm(arm: str | None, actions: str, options: dict[str, Any], layout: Any = None) -> DiscreteRobot:
    """The arm robot of an arm environment: a built-in ``arm`` (planar2 by default), or the arm
    file ``xml_path=`` with its options, on the world ``layout`` (the paper's rooms when None);
    the robot's keywords (:data:`ARM_OPTIONS`) are taken out of ``options``, the rest left for
    the task."""
    robot_kwargs = {k: options.pop(k) for k in ARM_OPTIONS if k in options}
    if layout is not None:
        robot_kwargs["layout"] = layout
    if robot_kwargs.get("xml_path") is None:  # a built-in arm, planar2 by default
        if arm is not None and not isinstance(arm, str):
            raise InvalidParameterError(f"arm must be an arm's name, got {arm!r}")
        if not isinstance(actions, str):
            raise InvalidParameterError(f"actions must be an action model's name, got {actions!r}")
        arm, actions = parse_robot_spec(f"{arm or 'planar2'}:{actions}")
    return arm_robot(arm, actions, **robot_kwargs)


def make_arm_rooms_env(arm: str | None = None, actions: str = "joint", task: int | str | None = 1,
                       start: tuple[int, int] | None = None,
                       goal: tuple[int, int] | None = None, world: Any = None, **kwargs: Any) -> RobotRoomsEnv:
    """Entry point of ``armtransfer/ArmRooms-v0``: an arm robot (compiled or loaded from the
    cache) on a task of ``world`` (Table I's on the paper's rooms, the default) or a custom
    task; the table is built from the world. Bring-your-own arms: ``xml_path=`` with
    ``tip_site=`` or ``tip_body=``, ``tip_offset=``, ``tool=`` (a held pen,
    ``"stylus[:LENGTH[:RADIUS]]"``), ``arm_name=``, ``base_pos=``/``base_yaw=`` (automatic
    without)."""
    check_options(kwargs, ARM_OPTIONS)
    the_task = rooms_task(task, start, goal, world)  # a bad world or task fails before any compiling
    return RobotRoomsEnv(rooms_arm(arm, actions, kwargs, the_task.layout), the_task, **kwargs)
