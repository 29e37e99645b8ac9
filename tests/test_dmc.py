"""armtransfer.dmc: the arm tasks as dm_control environments, checked by dm_env's own
conformance tests and step for step against the Gymnasium environment."""

import unittest

import dm_env
import gymnasium as gym
import numpy as np
import pytest
from dm_control.rl import control
from dm_env import test_utils

import armtransfer  # noqa: F401  (registers the Gymnasium environments)
from armtransfer import dmc
from armtransfer.errors import ArmTransferError, InvalidActionError
from armtransfer.learning import trajectory as trajectories
from armtransfer.wrappers import TransferReward

ARM = dict(arm="planar2", actions="joint", task=1)


def shortest_actions(env) -> list[int]:
    """The actions of the robot's shortest path from the start to the goal."""
    task = env.task
    return [a for _, a in task.robot.shortest_path(task.start_state, task.goal_cell)[:-1]]


class ConformanceChecks(test_utils.EnvironmentTestMixin):
    """dm_env's checks, with an action sequence that reaches the end of an episode and goes on
    into the next (the mixin checks FIRST after LAST only when a LAST comes)."""

    def make_action_sequence(self):
        yield from shortest_actions(self.environment)
        yield from (0, 1, 2)  # after the LAST step: a FIRST, then on

    def test_the_action_sequence_ends_an_episode(self):
        self.environment.reset()
        steps = [self.environment.step(a) for a in self.make_action_sequence()]
        lasts = [i for i, t in enumerate(steps) if t.last()]
        assert len(lasts) == 1 and steps[lasts[0] + 1].first()


class PlainConformance(ConformanceChecks, unittest.TestCase):
    def make_object_under_test(self):
        return dmc.load(**ARM)


class WindyConformance(ConformanceChecks, unittest.TestCase):
    """Wind may push the robot off the path; the episode is cut after 40 steps instead."""

    def make_object_under_test(self):
        return dmc.load(**ARM, wind=0.3, random=3, step_limit=len(shortest_actions(dmc.load(**ARM))))

    def test_the_action_sequence_ends_an_episode(self):
        self.environment.reset()
        steps = [self.environment.step(a) for a in self.make_action_sequence()]
        assert any(t.last() for t in steps)


class ShapedConformance(ConformanceChecks, unittest.TestCase):
    def make_object_under_test(self):
        plain = dmc.load(**ARM)
        task = plain.task
        traj = trajectories.shortest(task.robot, task.start_cell, task.goal_cell)
        return dmc.load(**ARM, trajectory=traj, method="potential")


def gym_and_dmc(wind: float, seed: int, **kwargs):
    genv = gym.make("armtransfer/ArmRooms-v0", **ARM, wind=wind, **({"max_episode_steps": 10**6}))
    denv = dmc.load(**ARM, wind=wind, random=seed, **kwargs)
    return genv, denv


@pytest.mark.parametrize("wind", [0.0, 0.25])
def test_an_episode_gives_the_gymnasium_envs_rewards_and_states(wind):
    genv, denv = gym_and_dmc(wind, seed=11)
    obs, info = genv.reset(seed=11)
    first = denv.reset()
    assert first.first() and int(first.observation["state"]) == obs
    robot = denv.task.robot
    rng = np.random.default_rng(0)
    terminated, n = False, 0
    while not terminated:
        s = denv.task.state
        path = robot.shortest_path(s, denv.task.goal_cell)
        # wander for a while, then head for the goal (re-planned after every push of the wind)
        a = int(rng.integers(robot.n_actions)) if n < 60 else path[0][1]
        obs, reward, terminated, truncated, info = genv.step(a)
        t = denv.step(a)
        n += 1
        assert int(t.observation["state"]) == obs and int(t.observation["cell"]) == info["label"]
        assert t.reward == reward
        assert t.last() == terminated and (t.discount == 0.0) == terminated
        assert np.allclose(t.observation["joints"], robot.arm.qpos[obs])
        assert np.allclose(t.observation["tool"], robot.arm.tip[obs], atol=1e-9)
        assert n < 2000
    assert n > 60 and info["label"] == denv.task.goal_cell
    genv.close()


def test_the_shaped_rewards_are_the_gymnasium_wrappers():
    plain = dmc.load(**ARM)
    traj = trajectories.shortest(plain.task.robot, plain.task.start_cell, plain.task.goal_cell)
    for method in ("pseudo", "first-visit", "progress", "potential", "dense"):
        genv = TransferReward(gym.make("armtransfer/ArmRooms-v0", **ARM), traj, method=method, K="auto")
        denv = dmc.load(**ARM, trajectory=traj, method=method)
        rng = np.random.default_rng(1)
        for episode in range(2):  # per-episode state starts afresh in both (first-visit: per trial)
            obs, _ = genv.reset(seed=0)
            denv.reset()
            shaped = 0.0
            for a in [*rng.integers(4, size=30), *shortest_actions(plain)]:
                obs, reward, terminated, _, info = genv.step(int(a))
                t = denv.step(int(a))
                assert t.reward == reward and int(t.observation["state"]) == obs
                shaped += info["shaping"]
                if terminated:
                    break
            # the shaping paid something on the way; first-visit's cells, paid in the first episode, stay paid
            assert (shaped == 0.0) if (method == "first-visit" and episode == 1) else (shaped != 0.0)
        assert denv.transfer.K == genv.K


@pytest.mark.parametrize("action", [-1, 4, 1.5, np.float32(0.0), "q1+", np.array([0, 1]), np.zeros((5, 5), int),
                                    None])
def test_an_action_outside_the_spec_is_refused_in_one_line(action):
    env = dmc.load(**ARM)
    env.reset()
    before = env.task.state
    with pytest.raises(InvalidActionError) as err:
        env.step(action)
    message = str(err.value)
    assert "\n" not in message and "0..3" in message and "q1+, q1-, q2+, q2-" in message
    assert env.task.state == before
    assert isinstance(err.value, ArmTransferError)


def test_the_wind_draws_from_the_injected_generator():
    rng = np.random.default_rng(5)
    env = dmc.load(**ARM, wind=1.0, random=rng)
    assert env.task.random is rng
    env.reset()
    env.step(0)
    assert rng.bit_generator.state != np.random.default_rng(5).bit_generator.state  # it drew


def test_actions_of_the_spec_are_taken():
    env = dmc.load(**ARM)
    env.reset()
    spec = env.action_spec()
    for a in (np.int32(0), np.int64(3), 2, np.array(1, dtype=np.uint8)):
        spec.validate(np.asarray(a, spec.dtype))
        assert env.step(a).mid()


def test_the_physics_names_the_joints_and_the_tool_point():
    env = dmc.load(**ARM)
    physics, robot = env.physics, env.task.robot
    assert physics.joint_names() == ("arm/joint1", "arm/joint2")
    state = int(env.reset().observation["state"])
    assert np.array_equal(physics.joint_angles(), robot.arm.qpos[state])
    assert np.allclose(physics.tool_point(), physics.named.data.site_xpos[physics.tool_site()])
    twin = physics.copy()
    assert twin.joint_names() == physics.joint_names() and np.allclose(twin.tool_point(), physics.tool_point())


def test_an_episode_is_cut_after_step_limit_steps():
    env = dmc.load(**ARM, step_limit=3)
    env.reset()
    steps = [env.step(1) for _ in range(3)]
    assert [t.step_type for t in steps] == [dm_env.StepType.MID, dm_env.StepType.MID, dm_env.StepType.LAST]
    assert steps[-1].discount == 1.0  # cut, not ended: the goal is not reached
    env = dmc.load(**ARM, step_limit=3, environment_kwargs=dict(n_sub_steps=7))
    env.reset()
    assert [env.step(1).last() for _ in range(3)] == [False, False, True]


@pytest.mark.parametrize("kwargs,message", [
    (dict(arm="puma"), "unknown arm 'puma'; valid arms:"),
    (dict(arm="planar2", actions="swim"), "valid action models"),
    (dict(tip_sight="tip"), "unknown option 'tip_sight'; valid arm options:"),
    (dict(wind=2.0), "wind must be a probability"),
    (dict(random="seven"), "random must be a numpy Generator, a seed"),
    (dict(random=-1), "random must be a numpy Generator, a seed"),
    (dict(task=9), "task"),
    (dict(step_limit=0), "step_limit must be a positive integer"),
    (dict(environment_kwargs=dict(time_limit=3)), "unknown environment option 'time_limit'"),
    (dict(environment_kwargs=dict(control_timestep=0.003)), "control_timestep"),
    (dict(trajectory=[], method="pseudo"), "at least one trajectory"),
    (dict(trajectory="/nonexistent/t.json", method="nope"), "unknown method 'nope'"),
])
def test_bad_input_is_a_one_line_error(kwargs, message):
    with pytest.raises(ArmTransferError) as err:
        dmc.load(**{**ARM, **kwargs})
    assert message in str(err.value) and "\n" not in str(err.value)


def test_render_draws_the_arm_through_dm_controls_physics():
    env = dmc.load(**ARM)
    env.reset()
    try:
        first = env.physics.render()
    except Exception as err:  # noqa: BLE001  (any GL failure: this machine cannot render)
        pytest.skip(f"no OpenGL backend works here (MUJOCO_GL=egl/osmesa): {type(err).__name__}: {err}")
    assert first.dtype == np.uint8 and first.shape == (240, 320, 3)
    assert first.std() > 10  # not a blank frame
    for a in shortest_actions(env):
        env.step(a)
    last = env.physics.render(height=120, width=160)
    assert last.shape == (120, 160, 3)
    moved = env.physics.render()
    changed = np.any(np.abs(first.astype(int) - moved.astype(int)) > 30, axis=-1)
    assert changed.mean() > 0.002  # the arm moved across the picture
    assert isinstance(env, control.Environment)
