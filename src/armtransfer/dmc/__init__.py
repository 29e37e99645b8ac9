"""The arm tasks as dm_control environments, for dm_env learners (Acme, the Control Suite's agents).

    from armtransfer import dmc

    env = dmc.load(arm="planar2", actions="joint", task=1)
    timestep = env.reset()
    while not timestep.last():
        timestep = env.step(agent(timestep.observation))
    frame = env.physics.render()

Physics and task apart, in the Control Suite's style: ``env.physics`` is an
:class:`armtransfer.ik.physics.ArmPhysics` (named accessors ``joint_angles()`` and
``tool_point()``), ``env.task`` a :class:`armtransfer.dmc.task.RoomsTask` (the rules and
rewards of the Gymnasium environment ``armtransfer/ArmRooms-v0``). The action is an index into
the arm robot's action model; the observation holds the robot's ``state`` index, its ``cell``,
its ``joints`` and the ``tool`` point. With ``trajectory=`` the transfer shaping of
``method`` is added to every reward (:class:`armtransfer.dmc.shaping.TransferShaping`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import dm_env
from dm_control.rl import control

from armtransfer.dmc.shaping import TransferShaping
from armtransfer.dmc.task import RoomsTask
from armtransfer.errors import InvalidParameterError
from armtransfer.ik.physics import ArmPhysics
from armtransfer.ik.replay import robot_scene
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.reward_term import TrajectoryLike
from armtransfer.registration import MAX_EPISODE_STEPS
from armtransfer.tasks.envs import ARM_OPTIONS, rooms_arm, rooms_task

STEP_LIMIT = MAX_EPISODE_STEPS
"""Steps after which an episode is cut (a LAST step with discount 1), as the Gymnasium env's."""


ENVIRONMENT_OPTIONS = ("n_sub_steps", "control_timestep", "flat_observation", "legacy_step")
"""The ``dm_control.rl.control.Environment`` options ``load`` passes on."""


def load(arm: str | None = None, actions: str = "joint", task: int | None = 1, *,
         start: tuple[int, int] | None = None, goal: tuple[int, int] | None = None, wind: float = 0.0,
         step_reward: float = -1.0, goal_reward: float = 0.0, random=None, step_limit: int | None = STEP_LIMIT,
         trajectory: TrajectoryLike | Sequence[TrajectoryLike] | None = None, method: str = "pseudo",
         K: float | str = "auto", gamma: float = LearnerConfig().gamma, beta: float | None = None,
         environment_kwargs: dict[str, Any] | None = None, world: Any = None, **arm_options: Any) -> dm_env.Environment:
    """The dm_control environment of an arm robot on a Table I task (``task``) or from ``start``
    to ``goal`` cells, as ``dm_control.suite.load`` gives one of the suite's.

    ``arm`` is a built-in arm (planar2 by default) or, with ``xml_path=``, an arm file with
    ``tip_site=``/``tip_body=``, ``tip_offset=``, ``tool=``, ``arm_name=``, ``base_pos=``/``base_yaw=``
    (:data:`armtransfer.tasks.envs.ARM_OPTIONS`), compiled or loaded from the cache as the
    Gymnasium environment's. ``random`` is the wind's ``numpy.random.Generator`` or its seed.
    An episode is cut after ``step_limit`` steps (None: never). ``trajectory`` (a
    :class:`armtransfer.learning.trajectory.Trajectory`, a trajectory JSON file, or a list of
    them) adds ``method``'s shaping with ``K``, ``gamma`` and ``beta`` to the rewards.
    ``environment_kwargs`` go to ``dm_control.rl.control.Environment`` (``n_sub_steps``,
    ``control_timestep``, ``flat_observation``). ``world`` is the world the table is built from
    (``"rooms11"``, ``"generated:3"``, a layout file; the paper's rooms by default), and
    ``task`` one of its tasks.
    """
    unknown = sorted(set(arm_options) - set(ARM_OPTIONS))
    if unknown:
        raise InvalidParameterError(
            f"unknown option {unknown[0]!r}; valid arm options: {', '.join(ARM_OPTIONS)}")
    environment_kwargs = dict(environment_kwargs or {})
    extra = sorted(set(environment_kwargs) - set(ENVIRONMENT_OPTIONS))
    if extra:
        raise InvalidParameterError(f"unknown environment option {extra[0]!r}; valid: {', '.join(ENVIRONMENT_OPTIONS)} "
                                    "(the episode's length is step_limit)")
    if trajectory is not None and environment_kwargs.get("flat_observation"):
        raise InvalidParameterError("the transfer shaping reads the observation's state: not with flat_observation")
    if step_limit is not None and (isinstance(step_limit, bool) or not isinstance(step_limit, int) or step_limit < 1):
        raise InvalidParameterError(f"step_limit must be a positive integer or None, got {step_limit!r}")
    the_task = rooms_task(task, start, goal, world)  # a bad world or task fails before any compiling
    robot = rooms_arm(arm, actions, dict(arm_options), the_task.layout)
    rooms = RoomsTask(robot, the_task, wind=wind, step_reward=step_reward, goal_reward=goal_reward, random=random)
    physics = ArmPhysics.from_scene(robot_scene(robot))
    environment = control.Environment(physics, rooms, time_limit=_time_limit(physics, step_limit, environment_kwargs),
                                      **environment_kwargs)
    if trajectory is None:
        return environment
    return TransferShaping(environment, trajectory, method, K, gamma, beta)


def _time_limit(physics: ArmPhysics, step_limit: int | None, environment_kwargs: dict) -> float:
    """The time limit that ends an episode after exactly ``step_limit`` steps: the environment
    counts steps of ``timestep * n_sub_steps`` seconds against it, so half a step short of
    ``step_limit`` of them cannot round either way."""
    if step_limit is None:
        return math.inf
    n_sub_steps = environment_kwargs.get("n_sub_steps")
    if n_sub_steps is None:
        control_timestep = environment_kwargs.get("control_timestep")
        try:
            n_sub_steps = 1 if control_timestep is None else control.compute_n_steps(control_timestep,
                                                                                       physics.timestep())
        except (TypeError, ValueError) as err:
            raise InvalidParameterError(f"control_timestep: {err}") from None
    if isinstance(n_sub_steps, bool) or not isinstance(n_sub_steps, int) or n_sub_steps < 1:
        raise InvalidParameterError(f"n_sub_steps must be a positive integer, got {n_sub_steps!r}")
    return (step_limit - 0.5) * physics.timestep() * n_sub_steps


__all__ = ["ArmPhysics", "ENVIRONMENT_OPTIONS", "RoomsTask", "STEP_LIMIT", "TransferShaping", "load"]
