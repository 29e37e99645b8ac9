"""A spatial arm in its continuous joint space over the 3D workspace (``ik.continuous3d``)."""

from __future__ import annotations

import numpy as np
import pytest

import armtransfer
from armtransfer.ik.continuous import BLOCKED
from armtransfer.ik.continuous3d import SpatialContinuousArm
from armtransfer.tasks.arms import arm_robot
from armtransfer.tasks.continuous import continuous_arm
from armtransfer.worlds.resolve import world

SMALL = world("rooms11")


@pytest.fixture(scope="module")
def arm():
    return continuous_arm("ur5e_like:joint", layout=SMALL)


def test_without_noise_its_moves_are_the_joint_robots_lattice_bit_for_bit(arm):
    """The same moved joints, origin and step as ur5e_like:joint; 3,000 random moves from the
    start land on the lattice state the compiled robot's next_state names, with its voxel."""
    assert isinstance(arm, SpatialContinuousArm) and arm.dof == 3 and arm.n_actions == 6 and arm.levels == 3
    robot = arm_robot("ur5e_like", "joint", layout=SMALL)
    assert robot.arm is not None and arm.moved == robot.arm.moved and arm.action_names == robot.action_names
    assert arm.step == float(robot.arm.joint_step)
    start = SMALL.cell(2, 2)
    arm.place(start)
    assert arm.label == start  # the start cell's voxel at the table level
    lattice = {tuple(int(v) for v in robot.arm.lattice[s]): s for s in range(robot.n_states)}
    s, start_key = lattice[arm.key()], arm.key()
    assert np.array_equal(robot.arm.qpos[s][list(arm.moved)], arm.q) and robot.label[s] == start
    rng = np.random.default_rng(0)
    moved = blocked = 0
    for _ in range(3000):
        a = int(rng.integers(arm.n_actions))
        v, t = arm.move(a), int(robot.next_state[s, a])
        if v == BLOCKED:
            blocked += 1
            assert t == s
            continue
        moved += 1
        s = lattice[arm.key()]
        assert s == t and v == robot.label[s] and np.array_equal(robot.arm.qpos[s][list(arm.moved)], arm.q)
    assert moved > 1000 and blocked > 0
    assert arm.reset() == start and arm.key() == start_key


def test_with_noise_a_move_turns_its_joint_by_a_noisy_step_and_the_same_seed_gives_the_same_walk(arm):
    noisy = continuous_arm("ur5e_like", layout=SMALL, noise=0.2)

    def walk(seed: int) -> list[tuple]:
        noisy.place(SMALL.cell(2, 2))
        noisy.seed_noise(np.random.default_rng(seed))
        out = []
        for a in np.random.default_rng(5).integers(6, size=300):
            before = noisy.q.copy()
            v = noisy.move(int(a))
            turn = noisy.q - before
            if v != BLOCKED:
                i = int(a) // 2
                assert np.count_nonzero(turn) == 1 and 0.5 * noisy.step - 1e-12 <= abs(turn[i]) <= 1.5 * noisy.step + 1e-12
            out.append((v, noisy.key()))
        return out

    first = walk(1)
    assert first == walk(1) and first != walk(2)
    assert len({k for _, k in first}) > 50  # off the lattice: the keys are the angles
    with noisy.noiseless():  # the greedy roll-out's moves: the lattice's, from the start
        noisy.reset()
        start = noisy.q.copy()
        for a in np.random.default_rng(6).integers(6, size=40):
            noisy.move(int(a))
            steps = (noisy.q - start) / noisy.step
            assert np.allclose(steps, np.rint(steps), rtol=0, atol=1e-9)
        assert all(isinstance(k, int) for k in noisy.key())


@pytest.mark.slow
def test_it_learns_rooms11_task_2_from_planar2s_path_under_actuation_noise():
    """planar2:joint's learned path -> ur5e_like:joint in its continuous joint space, noise 0.1,
    hashed tiles, via the API: every trial of none and pseudo reaches the goal within the
    budget (20,000 steps a trial; the first exposures measured were 450-4,300 steps)."""
    from armtransfer.api import resolve_trajectories
    from armtransfer.learning.config import LearnerConfig
    from armtransfer.tasks.arms import robot
    from armtransfer.tasks.catalog import world_task

    traj = resolve_trajectories(["learned"], robot("planar2:joint", layout=SMALL), world_task(SMALL, "2"),
                                LearnerConfig(), 0)[0]
    r = armtransfer.transfer("planar2:joint", "ur5e_like:joint", state="continuous", world="rooms11", task="2",
                             noise=0.1, methods=["none", "pseudo"], trials=2, max_total_steps=20_000, trajectory=traj)
    out = r.to_json()
    assert out["approximation"]["table_bits"] == 18 and r.target == "ur5e_like:joint (continuous)"
    for m in ("none", "pseudo"):
        steps = out["results"][m]["exploration_steps"]
        assert len(steps) == 2 and all(s is not None and s > 0 for s in steps), (m, steps)
        assert r.methods[m].extra["noise"] == 0.1
    assert r.methods["pseudo"].extra["K"] > 0


@pytest.mark.slow
@pytest.mark.parametrize("env_id", ["armtransfer/ContinuousArmRooms-v0", "armtransfer/ContinuousArmRoomsBox-v0"])
def test_the_environments_with_a_spatial_arm_pass_check_env(env_id):
    import gymnasium as gym
    from gymnasium.utils.env_checker import check_env

    env = gym.make(env_id, arm="ur5e_like", world="rooms11", task="2", noise=0.1, render_mode="ansi").unwrapped
    check_env(env, skip_render_check=True)
    assert env.observation_space.shape == (3 + 3,) and env.robot.n_states == 3 * SMALL.n_cells
    obs, info = env.reset(seed=0)
    assert info["label"] == SMALL.cell(2, 2) and "R" in env.render()
    rng = np.random.default_rng(0)
    labels = set()
    for _ in range(60):
        obs, _, terminated, _, info = env.step(env.action_space.sample() if env_id.endswith("Box-v0")
                                               else int(rng.integers(6)))
        labels.add(info["label"])
        assert env.observation_space.contains(obs)
        if terminated:
            break
    assert len(labels) > 1


@pytest.mark.slow  # 5-6 s: the default suite is near its budget
def test_a_bring_your_own_7_joint_file_learns_in_its_continuous_joint_space(tmp_path):
    """A Menagerie-style iiwa file (7 joints, its own servos, the mount chosen by the compiler)
    as a continuous target under actuation noise 0.1: every trial of none and pseudo reaches the
    goal of rooms11 task 2 from planar2:joint's learned path."""
    import sys
    from pathlib import Path

    from armtransfer.api import resolve_trajectories
    from armtransfer.learning.config import LearnerConfig
    from armtransfer.tasks.arms import robot
    from armtransfer.tasks.catalog import world_task

    sys.path.insert(0, str(Path(__file__).parent))
    import menagerie_like as ml

    xml = ml.iiwa_style(tmp_path)
    traj = resolve_trajectories(["learned"], robot("planar2:joint", layout=SMALL), world_task(SMALL, "2"),
                                LearnerConfig(), 0)[0]
    r = armtransfer.transfer("planar2:joint", "custom", arm_xml=xml, arm_options=dict(ml.SUGGESTED["iiwa"]),
                             state="continuous", world="rooms11", task="2", noise=0.1, methods=["none", "pseudo"],
                             trials=2, max_total_steps=20_000, trajectory=traj)
    out = r.to_json()
    assert r.target == "custom (continuous)" and out["approximation"]["table_bits"] == 18  # hashed: spatial
    for m in ("none", "pseudo"):
        steps = out["results"][m]["exploration_steps"]
        assert len(steps) == 2 and all(s is not None and s > 0 for s in steps), (m, steps)


def test_the_compiled_spatial_move_and_episode_are_the_python_ones_exactly(arm):
    """Noise 0: ``ik.fastmove3d.move`` walks the same configurations, labels and blocked moves as
    ``SpatialContinuousArm.move`` on 2,000 random actions, and a learner's trial gives the same
    bytes with the compiled episode (``experiments.fastloop``) as with the Python loop."""
    from armtransfer.experiments import continuous as runs
    from armtransfer.experiments import fastloop
    from armtransfer.ik import fastmove3d
    from armtransfer.learning import linear
    from armtransfer.learning.config import LearnerConfig

    start, goal = SMALL.cell(2, 2), SMALL.free_cell(-3, -3, what="goal")
    twin = continuous_arm("ur5e_like", layout=SMALL)
    arm.place(start)
    twin.place(start)
    acts = np.random.default_rng(7).integers(arm.n_actions, size=2000).tolist()
    state = twin.fast()
    assert state is not None
    blocked, before = 0, arm.moves
    for a in acts:
        v = arm.move(a)
        w = fastmove3d.move(a, state)
        assert v == w and np.array_equal(arm.q, twin.q) and np.array_equal(arm._tip, twin._tip)
        blocked += v == BLOCKED
    twin.fast_done()
    assert 0 < blocked < len(acts) and twin.moves == arm.moves - before and twin.label == arm.label

    arm.place(start)
    coding = runs.approximation_for(arm).coding(arm)
    steps_by = fastloop.episode_steps(arm)
    assert steps_by is not None
    config = LearnerConfig(max_total_steps=6000, max_episode_steps=1500, max_episodes=8)

    def trial(by):
        moves = arm.moves
        res = linear.learn(arm, goal, coding, config, np.random.default_rng(3), steps_by=by)
        return res, arm.moves - moves, arm.key()

    (fast, fast_moves, fast_key), (slow, slow_moves, slow_key) = trial(steps_by), trial(None)
    assert fast_moves == slow_moves > 6000 and fast_key == slow_key
    assert np.array_equal(fast.episode_steps, slow.episode_steps) and len(fast.episode_steps) > 1
    assert np.array_equal(fast.greedy_lengths, slow.greedy_lengths)
    assert (fast.exploration_steps, fast.converged, fast.total_steps, fast.episodes) == \
        (slow.exploration_steps, slow.converged, slow.total_steps, slow.episodes)
