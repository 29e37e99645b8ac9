"""The continuous-state arm as a Gymnasium environment: ``armtransfer/ContinuousArmRooms-v0``.

    env = gymnasium.make("armtransfer/ContinuousArmRooms-v0", arm="planar3", task=1)

The observation is a ``Box``: the joint configuration q followed by the tool point (x, y, z)
in metres; the action is ``Discrete(2 * dof)``: joint j turned by +delta (``2j``) or -delta
(``2j+1``), as the ``joint`` action model. Every step runs MuJoCo at most once (``ik.continuous``,
``ik.continuous3d``, by the arm's compiled move, ``fast_step``, when it has one: the same
result; the tool point observed is that of the move's own kinematics, ``ContinuousArm.tip``): a
move that is blocked leaves the arm where it was (``info["blocked"]``). Each step costs
``step_reward``; reaching the goal cell pays ``goal_reward`` and ends the episode.
``info["label"]`` is the cell under the tool point, which is what a transferred trajectory's
reward is paid on (``armtransfer.wrappers.TransferReward`` works on this environment).
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

import armtransfer.checks as checks
from armtransfer.errors import InvalidActionError, InvalidParameterError
from armtransfer.tasks.catalog import Task
from armtransfer.tasks.continuous import ARM_KEYWORDS, continuous_arm
from armtransfer.tasks.envs import check_options, check_reset_options, rooms_task
from armtransfer.tasks.robot import cell_robot
from armtransfer.worlds.voxels import cell_of_label

ACTIONS = ("discrete", "box")
"""The action spaces: ``Discrete(2 * dof)`` (one joint by +-delta) or ``Box(-1, 1, (dof,))``
(every joint at once by a_j * delta)."""
ARM_OPTIONS = ("xml_path", *ARM_KEYWORDS)
"""The keywords that build the arm (``tasks.continuous.continuous_arm``)."""
REACH = 2.0
"""The observation's bound on the tool point's coordinates (metres): the scene is smaller."""


class ContinuousArmRoomsEnv(gym.Env):
    """A start/goal task for a continuous-state arm (``ik.continuous.ContinuousArm``)."""

    metadata = {"render_modes": ["ansi"], "render_fps": 4}

    def __init__(self, arm, task: Task, step_reward: float = -1.0, goal_reward: float = 0.0,
                 render_mode: str | None = None, actions: str = "discrete") -> None:
        if not isinstance(actions, str) or actions not in ACTIONS:
            raise InvalidParameterError(f"unknown actions {actions!r}; valid actions: {', '.join(ACTIONS)}")
        self.actions = actions
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise InvalidParameterError(
                f"unknown render_mode {render_mode!r}; valid: {', '.join(self.metadata['render_modes'])}")
        self.render_mode = render_mode
        self.arm = arm
        self.task = task
        self.step_reward = float(checks.real(step_reward, "step_reward"))
        self.goal_reward = float(checks.real(goal_reward, "goal_reward"))
        layout = arm.layout
        self.start_cell, self.goal_cell = task.cells(layout)
        arm.place(self.start_cell)  # the start configuration: IK over the start cell
        self.start_q = arm.q.copy()
        lo, hi = arm.bounds if actions == "discrete" else arm.box
        self.observation_space = spaces.Box(np.concatenate([lo, [-REACH] * 3]), np.concatenate([hi, [REACH] * 3]),
                                            dtype=np.float64)
        self.action_space: spaces.Space = (spaces.Discrete(arm.n_actions) if actions == "discrete" else
                                           spaces.Box(-1.0, 1.0, (arm.dof,), dtype=np.float32))
        self._obs_size = arm.dof + 3
        self._move = getattr(arm, "fast_step", arm.move)  # the compiled move, the same result, when the arm has one
        self._n_actions = int(arm.n_actions)
        self._turn = np.zeros(arm.dof)  # a box action's joint turns (radians)
        self.robot = cell_robot(layout, int(getattr(arm, "levels", 1)))
        """The cells as a robot (states = cells; a spatial arm's: the voxels): what
        ``TransferReward`` pays transfer by."""
        self.start_state = self.start_cell

    def _obs(self) -> np.ndarray:
        obs = np.empty(self._obs_size)  # q, then the tool point of the move's own kinematics (no second call)
        dof = self.arm.dof
        obs[:dof] = self.arm.q
        obs[dof:] = self.arm.tip()
        return obs

    def state_of(self, obs: np.ndarray, info: dict) -> int:
        """The state ``TransferReward`` pays by: the cell under the tool point."""
        return int(info["label"])

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        check_reset_options(options)
        super().reset(seed=seed)
        if self.arm.noise > 0.0:  # the actuation noise draws from the environment's generator
            self.arm.seed_noise(self.np_random)
        label = self.arm.reset()
        return self._obs(), {"label": label}

    def step(self, action):
        if self.actions == "box":
            return self._step_box(action)
        kind = type(action)
        if not ((kind is int or kind is np.int64 or (isinstance(action, (int, np.integer))
                                                   and not isinstance(action, (bool, np.bool_))))
                and 0 <= action < self._n_actions):
            if isinstance(action, (bool, np.bool_)) or not self.action_space.contains(action):
                raise InvalidActionError(
                    f"action must be an integer in 0..{self.arm.n_actions - 1} (the action space "
                    f"{self.action_space}), got {action!r}")
        moved = self._move(int(action))
        arm = self.arm
        label = arm.label
        terminated = label == self.goal_cell
        reward = self.step_reward + (self.goal_reward if terminated else 0.0)
        obs = np.empty(self._obs_size)  # q, then the tool point of the move's own kinematics
        dof = arm.dof
        obs[:dof] = arm.q
        obs[dof:] = arm.tip()
        return obs, reward, terminated, False, {"label": label, "blocked": moved < 0}

    def _step_box(self, action):
        arm = self.arm
        dof = arm.dof
        try:
            values = np.asarray(action, dtype=np.float64).tolist()
        except (TypeError, ValueError):
            values = [math.nan]
        if not (isinstance(values, list) and len(values) == dof
                and all(isinstance(v, float) and -1.0 <= v <= 1.0 for v in values)):  # NaN fails too
            raise InvalidActionError(f"action must be {dof} finite numbers in [-1, 1] (the action space "
                                     f"{self.action_space}: joint turns in steps of {arm.step:g} rad), "
                                     f"got {action!r}")
        turn = self._turn
        turn[:] = values
        turn *= arm.step
        if arm.noise > 0.0:
            moved = arm.move_by(turn)
        else:
            moved = arm._move_by(turn)  # move_by without checking the turn again
        label = arm.label
        terminated = label == self.goal_cell
        reward = self.step_reward + (self.goal_reward if terminated else 0.0)
        obs = np.empty(self._obs_size)
        obs[:dof] = arm.q
        obs[dof:] = arm.tip()
        return obs, reward, terminated, False, {"label": label, "blocked": moved < 0}

    def render(self):
        if self.render_mode == "ansi":
            layout = self.arm.layout
            here = cell_of_label(self.arm.label, layout)  # a spatial arm's voxel: the cell under it
            return layout.ascii({layout.xy(here): "R", layout.xy(self.goal_cell): "G"}) + "\n"
        return None


def make_continuous_arm_rooms_env(arm: str | None = "planar3", task: int | str | None = 1,
                                  start: tuple[int, int] | None = None, goal: tuple[int, int] | None = None,
                                  world: Any = None, **kwargs: Any) -> ContinuousArmRoomsEnv:
    """Entry point of ``armtransfer/ContinuousArmRooms-v0``: a built-in arm (``arm``, e.g.
    ``"planar3"``, ``"planar3:joint"`` or, over the 3D workspace, ``"ur5e_like"``) or an arm file
    (``xml_path=``) on a Table I or
    custom task; ``world=`` as the other environments'."""
    check_options(kwargs, ARM_OPTIONS + ("actions",))
    the_task = rooms_task(task, start, goal, world)
    arm_kwargs = {k: kwargs.pop(k) for k in ARM_OPTIONS if k in kwargs}
    if kwargs.pop("wind", 0.0) != 0.0:
        raise InvalidParameterError("the continuous arm has no wind (its counterpart is noise=SIGMA); valid wind: 0")
    spec = None if arm_kwargs.get("xml_path") is not None else arm
    return ContinuousArmRoomsEnv(continuous_arm(spec, layout=the_task.layout, **arm_kwargs), the_task, **kwargs)


def make_continuous_arm_rooms_box_env(arm: str | None = "planar3", task: int | str | None = 1,
                                      start: tuple[int, int] | None = None, goal: tuple[int, int] | None = None,
                                      world: Any = None, **kwargs: Any) -> ContinuousArmRoomsEnv:
    """Entry point of ``armtransfer/ContinuousArmRoomsBox-v0``: ``ContinuousArmRooms-v0`` with
    ``actions="box"``, a ``Box(-1, 1, (dof,))`` of joint turns in steps of delta."""
    if kwargs.get("actions", "box") != "box":
        raise InvalidParameterError("ContinuousArmRoomsBox-v0 has box actions; valid actions: box")
    kwargs["actions"] = "box"
    return make_continuous_arm_rooms_env(arm, task, start, goal, world, **kwargs)
