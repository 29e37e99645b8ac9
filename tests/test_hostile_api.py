"""The Python API and the environments under misuse: every bad keyword is an
``ArmTransferError`` naming it, raised before any learning; numpy scalars are numbers."""

import gymnasium as gym
import numpy as np
import pytest

import armtransfer
from armtransfer.errors import ArmTransferError, InvalidParameterError, InvalidTrajectoryError
from armtransfer.learning import trajectory as trajectories
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.wrappers import TransferReward

FAST = dict(methods=["none"], trials=1, max_episodes=2, controls=False)


def _no_learning(monkeypatch):
    """Any trial started fails the test: the error must come before the first one."""
    from armtransfer.experiments import engines

    def boom(*a, **k):
        raise AssertionError("learning started before the bad input was refused")

    monkeypatch.setattr(engines.Tabular, "trials", boom)


@pytest.mark.parametrize("kwargs,names", [
    (dict(arm_options={"bogus": 1}), "bogus"),
    (dict(arm_options=[1]), "arm_options"),
    (dict(controls="no"), "controls"),
    (dict(controls=1), "controls"),
    (dict(save_mapping="yes"), "save_mapping"),
    (dict(progress=1), "progress"),
    (dict(source="custom", arm_xml=123), "arm_xml"),
    (dict(source="custom", arm_xml=""), "arm_xml"),
    (dict(methods=["pseudo"], trajectory="optimal", K="bogus"), "K"),
    (dict(methods=["pseudo"], trajectory="optimal", K=float("nan")), "K"),
    (dict(methods=["pseudo"], trajectory="optimal", K=[1]), "K"),
    (dict(methods=["dense"], trajectory="optimal", beta="x"), "beta"),
    (dict(methods=["dense"], trajectory="optimal", beta=float("inf")), "beta"),
    (dict(methods=["mapping"], trajectory="optimal", mapping=123), "mapping"),
    (dict(wind=float("nan")), "wind"),
    (dict(trials=2.0), "trials"),
    (dict(start=(0, 0), goal=(1,)), "goal"),
    (dict(start="0,0", goal=(-8, True)), "goal"),
])
def test_transfer_misuse_is_one_named_error_before_learning(kwargs, names, monkeypatch):
    _no_learning(monkeypatch)
    with pytest.raises(ArmTransferError) as err:
        armtransfer.transfer(**{**FAST, **kwargs})
    message = str(err.value)
    assert "\n" not in message and names in message


def test_numpy_scalars_are_numbers(monkeypatch):
    seen = {}
    from armtransfer.experiments import engines

    def capture(engine, work, target, trajs):
        seen.update(trials=work.trials, seed=work.seed, config=work.config, wind=work.wind)
        raise StopIteration

    monkeypatch.setattr(engines.Tabular, "trials", capture)
    with pytest.raises(StopIteration):
        armtransfer.transfer(methods=["none"], trials=np.int64(3), seed=np.uint8(4), wind=np.float32(0.25),
                             alpha=np.float32(0.5), max_episodes=np.int32(7), controls=np.bool_(False))
    assert seen["trials"] == 3 and type(seen["trials"]) is int
    assert seen["wind"] == 0.25 and seen["config"].alpha == 0.5 and type(seen["config"].alpha) is float
    assert seen["config"].max_episodes == 7 and type(seen["config"].max_episodes) is int


@pytest.mark.parametrize("env_id", ["armtransfer/Rooms-v0", "armtransfer/ArmRooms-v0"])
def test_step_outside_the_action_space_is_refused(env_id):
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    n = env.action_space.n
    for bad in (-1, 1.7, n, "a", None, True, np.float64(1.0)):
        with pytest.raises(InvalidParameterError, match="action must be an integer"):
            env.step(bad)
    for good in (0, np.int64(n - 1), np.array(1)):
        obs, *_ = env.step(good)
        assert env.observation_space.contains(obs)


@pytest.mark.parametrize("env_id", ["armtransfer/Rooms-v0", "armtransfer/ArmRooms-v0"])
@pytest.mark.parametrize("kwargs,names", [
    (dict(step_reward=float("nan")), "step_reward"),
    (dict(goal_reward="x"), "goal_reward"),
    (dict(wind="x"), "wind"),
    (dict(start=(1,), goal=(2, 2)), "start"),
    (dict(start="ab", goal=(2, 2)), "start"),
    (dict(start=(0, 0)), "together"),
    (dict(task="1"), "task"),
    (dict(bogus=1), "bogus"),
])
def test_environment_arguments_are_checked(env_id, kwargs, names):
    with pytest.raises(ArmTransferError) as err:
        gym.make(env_id, **kwargs)
    assert names in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("kwargs,names", [
    (dict(joint_step=0), "joint step"),
    (dict(joint_step=float("nan")), "joint step"),
    (dict(cache="no"), "cache"),
    (dict(base_pos=(1,)), "base position"),
    (dict(base_pos="x"), "base position"),
    (dict(base_pos=(0.1, 0.1, 1e300)), "base position"),
    (dict(xml_path=123), "xml_path"),
    (dict(cell_size="x"), "cell size"),
    (dict(base_yaw="x"), "base yaw"),
    (dict(tip_offset=(0, 0, 0.1)), "tip_offset"),
    (dict(arm=3), "arm"),
])
def test_arm_environment_arguments_are_checked(kwargs, names):
    with pytest.raises(ArmTransferError) as err:
        gym.make("armtransfer/ArmRooms-v0", **kwargs)
    assert names in str(err.value) and "\n" not in str(err.value)


def _trajectory(task: int):
    start, goal = table_task(task).cells()
    return trajectories.shortest(grid_robot("coarse"), start, goal)


def test_transfer_reward_refuses_a_trajectory_of_another_task():
    env = gym.make("armtransfer/Rooms-v0", task=1)
    with pytest.raises(InvalidTrajectoryError, match="the task is"):
        TransferReward(env, _trajectory(2))
    wrapped = TransferReward(env, _trajectory(1))  # the grid robot's path of this task is fine
    wrapped.reset(seed=0)
    assert np.isfinite(wrapped.step(0)[1])


def test_transfer_reward_on_an_arm_refuses_a_grid_robots_trajectory():
    env = gym.make("armtransfer/ArmRooms-v0", task=1)
    for task in (1, 2):
        with pytest.raises(InvalidTrajectoryError, match="of the grid robot 'coarse' but this environment's robot"):
            TransferReward(env, _trajectory(task))
    robot = env.unwrapped.robot
    own = trajectories.shortest(robot, *table_task(1).cells())  # an arm's path of this task is fine
    wrapped = TransferReward(env, own)
    wrapped.reset(seed=0)
    assert np.isfinite(wrapped.step(0)[1])


@pytest.mark.parametrize("bad,error", [(123, InvalidTrajectoryError), ([None], InvalidTrajectoryError),
                                       ([], InvalidParameterError)])
def test_transfer_reward_refuses_what_is_not_a_trajectory(bad, error):
    with pytest.raises(error):
        TransferReward(gym.make("armtransfer/Rooms-v0", task=1), bad)


def test_transfer_reward_takes_a_numpy_gamma():
    wrapped = TransferReward(gym.make("armtransfer/Rooms-v0", task=1), _trajectory(1), gamma=np.float32(0.5))
    assert wrapped.gamma == 0.5
