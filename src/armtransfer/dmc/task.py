"""The rooms-on-a-table task of an arm robot as a dm_control Control Suite ``Task``.

The discrete robot (``armtransfer.tasks.robot.DiscreteRobot``) is the task's state: the
action is an index into the robot's action model, each step costs ``step_reward`` and
reaching the goal cell pays ``goal_reward`` and ends the episode (discount 0), and with
``wind=p`` the robot is pushed one cell towards +x with probability p after its move: the
rules of the Gymnasium environment ``armtransfer/ArmRooms-v0``, draw for draw (a task given
the seed that a Gymnasium env is reset with makes the same wind). After every step the
physics (:class:`armtransfer.ik.physics.ArmPhysics`) is put at the new state's joint
configuration, so the observation's joints and tool point, and ``physics.render()``, show it.
"""

from __future__ import annotations

import collections

import numpy as np
from dm_control.suite import base
from dm_env import specs

from armtransfer.errors import InvalidActionError, InvalidParameterError, UnknownRobotError
from armtransfer.ik.physics import ArmPhysics
from armtransfer.tasks.catalog import Task
from armtransfer.tasks.envs import RoomsRules
from armtransfer.tasks.robot import DiscreteRobot


class RoomsTask(RoomsRules, base.Task):
    """Reach ``task``'s goal cell with ``robot`` (an arm robot) from its start cell.

    ``random``: the one ``numpy.random.Generator`` the wind draws from, or a seed for one
    (``np.random.default_rng(seed)``, which draws as a Gymnasium env reset with that seed
    does); None for fresh entropy. (dm_control's own tasks keep a ``RandomState``; this one
    keeps a ``Generator``, as the rest of the project does.)
    """

    def __init__(self, robot: DiscreteRobot, task: Task, *, wind: float = 0.0, step_reward: float = -1.0,
                 goal_reward: float = 0.0, random: int | np.random.Generator | None = None) -> None:
        if robot.arm is None:
            raise UnknownRobotError(f"robot {robot.name} is not an arm robot; a dm_control task needs ARM:ACTIONS")
        self._arm = robot.arm
        super().__init__(random=0)  # base state (reward colours); the RandomState is replaced below
        self._set_rules(robot, task, wind, step_reward, goal_reward)
        if not (random is None or isinstance(random, np.random.Generator)
                or (isinstance(random, (int, np.integer)) and not isinstance(random, bool) and random >= 0)):
            raise InvalidParameterError(f"random must be a numpy Generator, a seed (an integer >= 0) or None, "
                                        f"got {random!r}")
        self._random = random if isinstance(random, np.random.Generator) else np.random.default_rng(random)

    @property
    def random(self) -> np.random.Generator:
        return self._random

    @property
    def start_cell(self) -> int:
        """The shared cell the robot starts in."""
        return int(self.robot.label[self.start_state])

    @property
    def label(self) -> int:
        """The shared cell the robot is in."""
        return int(self.robot.label[self.state])

    def action_spec(self, physics: ArmPhysics) -> specs.DiscreteArray:
        return specs.DiscreteArray(num_values=self.robot.n_actions, name="action")

    def observation_spec(self, physics: ArmPhysics) -> collections.OrderedDict:
        dof = len(physics.joint_names())
        return collections.OrderedDict(
            state=specs.BoundedArray((), np.int64, 0, self.robot.n_states - 1, name="state"),
            cell=specs.BoundedArray((), np.int64, 0, self.robot.layout.n_cells - 1, name="cell"),
            joints=specs.Array((dof,), np.float64, name="joints"),
            tool=specs.Array((3,), np.float64, name="tool"),
        )

    def initialize_episode(self, physics: ArmPhysics) -> None:
        self.state = self.start_state
        super().initialize_episode(physics)  # runs after_step: the arm at the start state

    def before_step(self, action, physics: ArmPhysics) -> None:
        self._move(self._action(action), self._random)

    def after_step(self, physics: ArmPhysics) -> None:
        physics.set_configuration(self._arm.qpos[self.state])

    def get_observation(self, physics: ArmPhysics) -> collections.OrderedDict:
        return collections.OrderedDict(
            state=np.int64(self.state),
            cell=np.int64(self.label),
            joints=physics.joint_angles(),
            tool=physics.tool_point(),
        )

    def get_reward(self, physics: ArmPhysics) -> float:
        return self._outcome()[0]

    def get_termination(self, physics: ArmPhysics) -> float | None:
        return 0.0 if self._outcome()[1] else None

    def _action(self, action) -> int:
        """The action as an index into the robot's action model; anything else is refused."""
        n = self.robot.n_actions
        a = np.asarray(action)
        if a.shape == () and (a.dtype.kind in "iu") and 0 <= int(a) < n:
            return int(a)
        shown = repr(action) if a.size <= 4 else f"an array of shape {a.shape}"
        raise InvalidActionError(
            f"action {' '.join(shown.split())} is outside the action spec: an integer in 0..{n - 1} "
            f"({', '.join(self.robot.action_names)})")


__all__ = ["RoomsTask"]
