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
    """At most one MuJoCo kinematics per step: the observation's tool point is the move's, and it is the
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

    compiled = env._move
    assert compiled == arm.fast_step
    env._move = counted_move  # the Python move, whose MuJoCo calls can be counted
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
            assert per_step == in_move[-1] <= 1  # the move's own (the swept check asks MuJoCo nothing)
            assert obs.tobytes() == np.concatenate([arm.q, arm.tool_point()]).tobytes()
            if terminated:
                break
    assert blocked > 0
    env._move = compiled  # the compiled move (MuJoCo called from numba): the same observations
    obs, _ = env.reset(seed=0)
    for _ in range(400):
        obs, _, terminated, _, info = env.step(int(rng.integers(env.action_space.n)))
        assert obs.tobytes() == np.concatenate([arm.q, arm.tool_point()]).tobytes()
        blocked += info["blocked"]
        if terminated:
            break


def _planar3(noise=0.0):
    from armtransfer.tasks.catalog import TABLE_I
    from armtransfer.tasks.continuous import continuous_arm

    arm = continuous_arm("planar3", noise=noise)
    start, goal = TABLE_I[1].cells(arm.layout)
    arm.place(start)
    return arm, goal


@pytest.fixture(scope="module")
def noisy():
    return _planar3(0.2)


def test_with_noise_the_arm_leaves_the_lattice_and_every_move_is_checked(noisy):
    """Noise: the start is IK's (not snapped), a move turns its joint by 0.5 to 1.5 steps the
    right way, q leaves the lattice, and a move that is not blocked ends touching nothing with
    every point of its arc (checked densely, by MuJoCo) over a free cell."""
    from armtransfer.ik.labels import cells_of_xy

    arm, _ = noisy
    home = arm.scene.home.astype(float)
    arm.seed_noise(np.random.default_rng(4))
    arm.reset()
    q0 = arm.q.copy()
    assert not np.allclose((q0 - home) / arm.step, np.rint((q0 - home) / arm.step), atol=1e-6)
    rng = np.random.default_rng(0)
    free = arm.layout.free
    moved = blocked = 0
    for _ in range(300):
        q = arm.q.copy()
        a = int(rng.integers(arm.n_actions))
        label = arm.move(a)
        after = arm.q.copy()
        j, sign = a // 2, 1 - 2 * (a % 2)
        if label < 0:
            blocked += 1
            assert after.tobytes() == q.tobytes()
            continue
        moved += 1
        turn = (after[j] - q[j]) / arm.step * sign
        assert 0.5 - 1e-9 <= turn <= 1.5 + 1e-9 and np.delete(after - q, j).tolist() == [0.0] * (arm.dof - 1)
        assert not arm.checker.touches(after)
        assert label == int(cells_of_xy(arm.checker.tip(after), arm.scene.cell, arm.layout))
        for t in np.linspace(0, 1, 41):
            mid = q.copy()
            mid[j] = q[j] + t * (after[j] - q[j])
            cell = int(cells_of_xy(arm.checker.tip(mid), arm.scene.cell, arm.layout))
            assert cell >= 0 and free[cell]
        arm.q[:] = after
    assert moved > 100 and blocked > 0
    steps = (arm.q - q0) / arm.step
    assert not np.allclose(steps, np.rint(steps), atol=1e-6)  # off the lattice


def test_noisy_learning_is_deterministic_and_its_greedy_path_is_noiseless(noisy):
    from armtransfer.learning import linear
    from armtransfer.learning.config import LearnerConfig
    from armtransfer.learning.tiles import TileCoding

    arm, goal = noisy
    coding = TileCoding.over(*arm.bounds, 2 * arm.step, 4)
    config = LearnerConfig(max_episodes=3, max_total_steps=3000)
    class Recorded:  # the arm, with every move's result and configuration recorded
        def __init__(self):
            self.seen = []

        def __getattr__(self, name):
            return getattr(arm, name)

        def move(self, a):
            out = arm.move(a)
            self.seen.append((out, arm.q.tobytes()))
            return out

    runs = []
    for seed in (1, 1, 2):
        arm.seed_noise(np.random.default_rng(seed))
        rec = Recorded()
        r = linear.learn(rec, goal, coding, config, np.random.default_rng(9))
        runs.append((r.episode_steps.tobytes(), rec.seen))
    assert runs[0] == runs[1]
    assert runs[0][1] != runs[2][1]  # only the noise differs
    with arm.noiseless():
        arm.reset()
        arm.move(0)
        arm.move(1)
        assert arm.key() == (0, 0, 0)
    assert arm.noise == 0.2


def test_no_noise_is_the_arm_without_noise_bit_for_bit():
    from armtransfer.learning import linear
    from armtransfer.learning.config import LearnerConfig
    from armtransfer.learning.tiles import TileCoding

    out = []
    for noise in (None, 0.0):
        arm, goal = _planar3() if noise is None else _planar3(noise)
        arm.seed_noise(np.random.default_rng(3))
        coding = TileCoding.over(*arm.bounds, 2 * arm.step, 4)
        r = linear.learn(arm, goal, coding, LearnerConfig(max_episodes=2, max_total_steps=2000),
                         np.random.default_rng(2))
        out.append((arm.q.tobytes(), r.episode_steps.tobytes(), arm.key()))
    assert out[0] == out[1]


def test_the_noisy_environment_and_api_are_reproducible_and_refuse_bad_noise_in_one_line():
    import gymnasium as gym

    from armtransfer.errors import ArmTransferError

    def rollout(seed):
        env = gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar3", task=1, noise=0.1).unwrapped
        obs = [env.reset(seed=seed)[0]]
        for a in np.random.default_rng(0).integers(0, 6, 200):
            obs.append(env.step(int(a))[0])
        return np.array(obs)

    a, b, c = rollout(1), rollout(1), rollout(2)
    assert a.tobytes() == b.tobytes() and a.tobytes() != c.tobytes()
    r = armtransfer.transfer(source="planar2:joint", target="planar3:joint", state="continuous", task=1, trials=2,
                             trajectory="optimal", max_episodes=2, max_total_steps=2000, noise=0.1)
    again = armtransfer.transfer(source="planar2:joint", target="planar3:joint", state="continuous", task=1,
                                 trials=2, trajectory="optimal", max_episodes=2, max_total_steps=2000, noise=0.1)
    assert r.to_json() == again.to_json() and r.methods["none"].extra["noise"] == 0.1
    for make in (lambda: gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar3", noise=-0.1),
                 lambda: gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar3", noise=float("nan")),
                 lambda: gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar3", noise="x"),
                 lambda: armtransfer.transfer(source="planar2", target="planar3:joint", noise=0.1),
                 lambda: armtransfer.transfer(source="planar2:joint", target="planar3:joint", state="continuous",
                                              noise=0.6)):
        with pytest.raises(ArmTransferError, match="noise") as err:
            make()
        assert "\n" not in str(err.value)


def _reference_hash(t, coords, table):
    """The hash the tiles module documents, on Python integers."""
    m, g = 2**64, 0x9E3779B97F4A7C15

    def mix(z):
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) % m
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) % m
        return z ^ (z >> 31)

    h = mix((t + 1) * g % m)
    for c in coords:
        h = mix((h + int(c) + g) % m)
    return h & (table - 1)


def test_hashed_tiles_are_the_dense_tiles_under_the_documented_hash():
    from armtransfer.learning.tiles import TileCoding

    lo, hi = [-3.0, -2.0, -2.5], [3.0, 2.0, 2.5]
    dense = TileCoding.over(lo, hi, 0.24, 8)
    hashed = TileCoding.over(lo, hi, 0.24, 8, table_bits=12)
    assert hashed.size == 4096 and hashed.tilings == 8
    rng = np.random.default_rng(0)
    points = rng.uniform(lo, hi, (300, 3))
    for q in points[:50]:
        f = hashed.active(q)
        assert f.tolist() == [_reference_hash(t, c, 4096) for t, c in enumerate(hashed.tiles(q))]
    # the same tiles: two points share a hashed feature of tiling t whenever they share the dense one
    fd = np.array([dense.active(q) for q in points])
    fh = np.array([hashed.active(q) for q in points])
    same_dense = fd[:, None, :] == fd[None, :, :]
    same_hashed = fh[:, None, :] == fh[None, :, :]
    assert np.all(same_hashed[same_dense]) and same_dense.sum() > 300 * 8
    for bits in (12, 4):
        coding = TileCoding.over(lo, hi, 0.24, 8, table_bits=bits)
        tiles = {(t, *coding.tiles(q)[t].tolist()) for q in points for t in range(8)}
        feature = {k: _reference_hash(k[0], k[1:], 2**bits) for k in tiles}
        owners = {}
        for f in feature.values():
            owners[f] = owners.get(f, 0) + 1
        expected = {"tiles": len(tiles), "features": len(owners),
                    "tiles_sharing": sum(v for v in owners.values() if v > 1)}
        assert coding.collisions(points) == expected
        assert expected["tiles_sharing"] > 0 and (bits == 4 or expected["features"] > 0.6 * expected["tiles"])
    assert dense.collisions(points)["tiles_sharing"] == 0
    for bad in (-1, 25, 2.0, True):
        with pytest.raises(armtransfer.errors.InvalidParameterError, match="table_bits"):
            TileCoding.over(lo, hi, 0.24, 8, table_bits=bad)


@pytest.mark.slow
def test_hashed_tiles_generalise_two_steps_and_their_memory_does_not_grow_with_the_joints():
    """A 6-joint planar arm: its dense tiles are refused (the lattice is too big), hashed ones
    take 2**16 features per action whatever the joint count; a configuration two steps away
    (one step in each of two joints) shares features with q; the learner runs on it."""
    from armtransfer.errors import InvalidParameterError
    from armtransfer.experiments.continuous import Approximation
    from armtransfer.learning import linear
    from armtransfer.learning.config import LearnerConfig
    from armtransfer.tasks.catalog import TABLE_I
    from armtransfer.tasks.continuous import continuous_arm

    sizes = {}
    for spec in ("planar3", "gen:planar:6:0"):
        arm = continuous_arm(spec)
        start, goal = TABLE_I[1].cells(arm.layout)
        arm.place(start)
        coding = Approximation(table_bits=16).coding(arm)
        sizes[arm.dof] = coding.size
        q = arm.q.copy()
        for j in range(arm.dof - 1):
            two = q.copy()
            two[j] += arm.step
            two[j + 1] -= arm.step
            assert len(set(coding.active(q)) & set(coding.active(two))) >= 1
        far = q + 4 * arm.step
        assert not set(coding.active(q)) & set(coding.active(far))
    assert sizes == {3: 2**16, 6: 2**16}
    with pytest.raises(InvalidParameterError, match="features"):
        Approximation().coding(arm)  # 6 joints, dense: 2.7e7 features
    r = linear.learn(arm, goal, coding, LearnerConfig(max_episodes=2, max_total_steps=2000), np.random.default_rng(0))
    assert r.episodes >= 1 and np.abs(r.episode_steps).sum() <= 2000
    assert Approximation(table_bits=16).to_json()["table_bits"] == 16 and "table_bits" not in Approximation().to_json()


def test_both_environments_pass_check_env_and_box_moves_are_checked_along_their_line():
    import gymnasium as gym
    from gymnasium.utils.env_checker import check_env

    from armtransfer.errors import InvalidActionError, InvalidParameterError
    from armtransfer.ik.labels import cells_of_xy

    check_env(gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar3", task=1).unwrapped)
    env = gym.make("armtransfer/ContinuousArmRoomsBox-v0", arm="planar3", task=1).unwrapped
    check_env(env)
    same = gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar3", task=1, actions="box").unwrapped
    assert env.action_space == same.action_space and env.action_space.shape == (3,)
    arm = env.arm
    env.reset(seed=0)
    rng = np.random.default_rng(1)
    free = arm.layout.free
    moved = blocked = 0
    for _ in range(150):
        q = arm.q.copy()
        a = rng.uniform(-1, 1, 3)
        obs, _, terminated, _, info = env.step(a)
        after = arm.q.copy()
        if info["blocked"]:
            blocked += 1
            assert after.tobytes() == q.tobytes()
            continue
        moved += 1
        assert np.allclose(after - q, a * arm.step, rtol=0, atol=1e-12)
        assert not arm.checker.touches(after)
        assert info["label"] == int(cells_of_xy(arm.checker.tip(after), arm.scene.cell, arm.layout))
        for t in np.linspace(0, 1, 41):
            cell = int(cells_of_xy(arm.checker.tip(q + t * (after - q)), arm.scene.cell, arm.layout))
            assert cell >= 0 and free[cell]
        arm.q[:] = after
        assert obs.tobytes() == np.concatenate([after, arm.tool_point()]).tobytes()
        if terminated:
            break
    assert moved > 50 and blocked > 0
    for bad in ([0.5, 0.5], [2.0, 0.0, 0.0], [np.nan, 0, 0], "x", 3):
        with pytest.raises(InvalidActionError, match=r"3 finite numbers in \[-1, 1\]") as err:
            env.step(bad)
        assert "\n" not in str(err.value)
    for kwargs in (dict(actions="boxes"), dict(actions=1)):
        with pytest.raises(InvalidParameterError, match="valid actions: discrete, box"):
            gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar3", **kwargs)
    with pytest.raises(InvalidParameterError, match="valid actions: box"):
        gym.make("armtransfer/ContinuousArmRoomsBox-v0", arm="planar3", actions="discrete")


def test_the_compiled_episode_is_the_python_loop_bit_for_bit():
    """``experiments.fastloop`` (the arm's move and the learner's update compiled together, MuJoCo
    called from numba) gives the trial ``learn``'s own loop gives, with the pseudo reward, and
    also when every move with a contact is handed back to Python."""
    from armtransfer.experiments import fastloop
    from armtransfer.ik import fastmove
    from armtransfer.learning import cells, linear
    from armtransfer.learning import trajectory as trajectories
    from armtransfer.learning.config import LearnerConfig
    from armtransfer.learning.tiles import TileCoding
    from armtransfer.tasks.arms import robot

    arm, goal = _planar3()
    start = arm.label
    traj = trajectories.shortest(robot("planar3:joint"), start, goal)
    shaping = cells.cell_shaping("pseudo", arm.layout, [traj], "auto", LearnerConfig())
    coding = TileCoding.over(*arm.bounds, 2 * arm.step, 8)
    config = LearnerConfig(max_episodes=3, max_total_steps=5000, max_episode_steps=2000)
    steps_by = fastloop.episode_steps(arm)
    assert steps_by is not None

    def trial(by):
        moves = arm.moves
        r = linear.learn(arm, goal, coding, config, np.random.default_rng(11), shaping, linear.LinearConfig(greedy_cap=300),
                         by)
        return (r.episode_steps.tobytes(), r.greedy_lengths.tobytes(), r.exploration_steps, arm.key(),
                arm.q.tobytes(), arm.moves - moves)

    handed = []
    real = arm.move

    def counted(a):  # the moves taken in Python: the greedy roll-outs', and those handed back
        handed.append(a)
        return real(a)

    arm.move = counted
    try:
        python = trial(None)
        before = len(handed)
        assert trial(steps_by) == python
        greedy = len(handed) - before  # the fast trial's Python moves: its greedy roll-outs'
        before = len(handed)
        state = arm._fast
        raw = state[0]
        arm._fast = (raw[:6] + (np.int64(0),) + raw[7:],) + state[1:]  # the contacts "moved": Python takes those
        try:
            assert trial(steps_by) == python
        finally:
            arm._fast = state
    finally:
        arm.move = real
    assert len(handed) - before > greedy  # and the moves with a contact, handed back
    assert fastloop.episode_steps(_planar3(0.1)[0]) is None  # noise: no compiled move
    assert fastmove.PYTHON == -3
