"""The continuous arm's results as frames and reprs, its environment's single kinematics per step,
actuation noise, hashed tile coding and the Box action variant."""

import numpy as np
import pytest

import armtransfer
from armtransfer.experiments.continuous import ContinuousResult


@pytest.fixture(scope="module")
def result() -> ContinuousResult:
    r = armtransfer.transfer(source="planar2:joint", target="planar3:joint", state="continuous", task=1, trials=2,
                             trajectory="optimal", max_episodes=2, max_total_steps=3000)
    assert isinstance(r, ContinuousResult)
    return r


def test_a_continuous_result_is_a_frame_with_one_row_per_trial(result):
    pytest.importorskip("pandas")
    df = result.to_frame()
    out = result.to_json()
    assert list(df.method) == ["none", "none", "pseudo", "pseudo"] and list(df.trial) == [0, 1, 0, 1]
    assert set(df.control) == {"none"} and set(df.state) == {"continuous"}
    for m in ("none", "pseudo"):
        got = [None if v is None or v is pd_na() else int(v) for v in df[df.method == m].exploration_steps]
        assert got == out["results"][m]["exploration_steps"]
    assert list(df.reached) == [e is not None for m in ("none", "pseudo")
                                for e in out["results"][m]["exploration_steps"]]
    assert set(df.approximation_tilings) == {8} and set(df.max_total_steps) == {3000}


def pd_na():
    import pandas as pd

    return pd.NA


def test_a_continuous_result_says_continuous_once_and_shows_a_table(result):
    text = repr(result)
    assert text.count("continuous") == 1, text
    assert text.startswith("<ContinuousResult task 1: (0, 0) -> (-8, 12), planar2:joint -> planar3:joint")
    lines = text.splitlines()
    assert lines[1].split()[:2] == ["method", "mean"] and [ln.split()[0] for ln in lines[2:]] == ["none", "pseudo"]
    html = result._repr_html_()
    assert html.count("<tr>") == 3 and "<th>method</th>" in html and "-&gt;" in html


def test_the_environment_reports_the_tool_point_of_the_moves_own_kinematics():
    """One MuJoCo kinematics per step: the observation's tool point is the move's, and it is the
    point a fresh kinematics call gives (the old observation), bit for bit, on a seeded rollout
    with blocked moves and resets."""
    import gymnasium as gym
    import mujoco

    env = gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar3", task=1).unwrapped
    arm = env.arm
    calls = []
    real = mujoco.mj_kinematics

    def counting(m, d):
        calls.append(1)
        real(m, d)

    in_move = []
    move = arm.move

    def counted_move(a):
        before = len(calls)
        out = move(a)
        in_move.append(len(calls) - before)
        return out

    arm.move = counted_move
    rng = np.random.default_rng(5)
    blocked = 0
    for episode in range(3):
        obs, _ = env.reset(seed=episode)
        assert obs.tobytes() == np.concatenate([arm.q, arm.tool_point()]).tobytes()
        for _ in range(400):
            mujoco.mj_kinematics = counting
            try:
                before = len(calls)
                obs, _, terminated, _, info = env.step(int(rng.integers(env.action_space.n)))
                per_step = len(calls) - before
            finally:
                mujoco.mj_kinematics = real
            blocked += info["blocked"]
            assert per_step == in_move[-1] <= 4  # the move's own (with up to 3 probes near a wall)
            assert obs.tobytes() == np.concatenate([arm.q, arm.tool_point()]).tobytes()
            if terminated:
                break
    assert blocked > 0
