"""The continuous-state arm: MuJoCo at every move, the tabular robot's labels, Gymnasium, the API."""

import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import armtransfer
from armtransfer.errors import ArmTransferError, InvalidActionError, InvalidParameterError, UnknownArmError
from armtransfer.ik.continuous import BLOCKED, ContinuousArm, clearance_cells
from armtransfer.ik.labels import cells_of_xy
from armtransfer.learning import linear, tiles
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.arms import robot
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.continuous import continuous_arm
from armtransfer.worlds.layout import ROOMS

sys.path.insert(0, str(Path(__file__).parent))
from sweepcheck import SweepChecker, move_clearance  # noqa: E402
from armtransfer.wrappers import TransferReward

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def arm():
    a = continuous_arm("planar3")
    a.place(TABLE_I[1].cells(a.layout)[0])
    return a


def _expected_end(arm, q, a):
    """What MuJoCo says at the end of move a from q: (inside the limits, touches, the end's cell)."""
    j, sign = a // 2, 1 - 2 * (a % 2)
    end = q.copy()
    end[j] += sign * arm.step
    lo, hi = arm.bounds
    if not (lo[j] - 1e-9 <= end[j] <= hi[j] + 1e-9):
        return False, False, -1
    touches = arm.checker.touches(end)
    cell = int(cells_of_xy(arm.checker.tip(end), arm.scene.cell, arm.layout))
    return True, touches, cell


def _random_moves(arm, n, seed):
    """``n`` random moves from the arm's start: (q before, the action, ``_expected_end``'s
    answer, what ``move`` returned). The caller may ask MuJoCo about other configurations in
    between: the arm's configuration is put back before the next move."""
    arm.reset()
    rng = np.random.default_rng(seed)
    for _ in range(n):
        q = arm.q.copy()
        a = int(rng.integers(arm.n_actions))
        expected = _expected_end(arm, q, a)
        arm.q[:] = q  # the check above moved MuJoCo's data
        label = arm.move(a)
        after = arm.q.copy()
        yield q, a, expected, label
        arm.q[:] = after


def test_every_move_is_checked_by_mujoco_at_its_end(arm):
    seen = {"moved": 0, "limit": 0, "wall or edge": 0, "contact": 0}
    for q, a, (inside, touches, cell), label in _random_moves(arm, 3000, 0):
        if not inside:
            assert label == BLOCKED and np.array_equal(arm.q, q)
            seen["limit"] += 1
        elif touches or cell < 0 or not arm.layout.free[cell]:
            assert label == BLOCKED and np.array_equal(arm.q, q)
            seen["wall or edge"] += not touches
            seen["contact"] += touches  # the stylus against a wall
        elif label != BLOCKED:  # the arc between may still pass over a wall
            assert label == cell == arm.label
            assert np.count_nonzero(arm.q != q) == 1
            seen["moved"] += 1
    assert seen["moved"] > 1000 and seen["wall or edge"] > 0 and seen["contact"] > 0


def test_a_bring_your_own_arm_file_is_blocked_by_its_own_links(tmp_path):
    """Menagerie's kind of planar 5-joint file, whose links may strike each other: every move
    into a configuration where MuJoCo finds the arm touching itself (or anything) is blocked."""
    import menagerie_like as ml

    a = continuous_arm(None, xml_path=ml.planar5_straight(tmp_path), joint_step=0.35, **ml.SUGGESTED["planar5"])
    assert a.checker.can_self_collide
    a.place(TABLE_I[1].cells(a.layout)[0])
    touched = 0
    for q, _, (inside, touches, _), label in _random_moves(a, 2500, 0):
        if inside and touches:
            touched += 1
            assert label == BLOCKED and np.array_equal(a.q, q)
    assert touched > 0


def test_limits_block_a_move_before_mujoco_is_asked():
    a = continuous_arm("planar2")
    a.place(TABLE_I[1].cells(a.layout)[0])
    lo, hi = a.bounds
    assert hi[0] <= a.scene.upper[0] + 1e-9 and hi[0] + a.step > a.scene.upper[0]
    a._n[0] = a._nhi[0]  # joint 1 at its last lattice point below its upper limit
    a.q[0] = hi[0]
    q = a.q.copy()
    assert a.move(0) == BLOCKED and np.array_equal(a.q, q)
    a._n[0] = a._nlo[0]
    a.q[0] = lo[0]
    q = a.q.copy()
    assert a.move(1) == BLOCKED and np.array_equal(a.q, q)


def test_a_move_and_its_reverse_return_to_the_same_bits(arm):
    arm.reset()
    start = arm.q.tobytes()
    for a in (4, 5, 2, 3, 0, 1):
        if arm.move(a) != BLOCKED:
            assert arm.move(a ^ 1) != BLOCKED
            assert arm.q.tobytes() == start


def test_a_move_is_blocked_exactly_when_a_point_of_its_arc_is_over_a_wall_or_off_the_table(arm):
    """The points between the ends count too (checked here with MuJoCo at each interpolated
    configuration): joint 1's move sweeps the tip about 5 cells. A move over free cells only is
    blocked by a contact MuJoCo finds at a point of its arc or by the swept check, and then the
    arm comes within a millimetre of the table or a wall along it."""
    crossed = 0
    checker = SweepChecker(arm.scene.model, arm.scene.tip)
    for q, a, (inside, touches, cell), label in _random_moves(arm, 1500, 5):
        j, sign, m = a // 2, 1 - 2 * (a % 2), int(arm._m[a])
        points = []
        for k in range(1, m + 1):
            qt = q.copy()
            qt[j] += sign * arm.step * k / (m + 1)
            points.append(int(cells_of_xy(arm.checker.tip(qt), arm.scene.cell, arm.layout)))
        if not inside or touches:
            continue
        off = [c for c in [cell, *points] if c < 0 or not arm.layout.free[c]]
        if off:
            assert label == BLOCKED
            crossed += cell >= 0 and arm.layout.free[cell]  # blocked though its end is free
        elif label == BLOCKED:  # then MuJoCo found a contact at a point along the arc, or the arm
            # comes within a millimetre of the table or a wall along it (an independent checker)
            probes = [q + np.eye(arm.dof)[j] * sign * arm.step * t for t in arm._probe[a]]
            if not any(arm.checker.touches(p) for p in probes):
                assert move_clearance(checker, q, q + np.eye(arm.dof)[j] * sign * arm.step) < 1e-3
    assert crossed > 0


def test_clearance_counts_cells_to_the_nearest_wall_or_edge():
    d = clearance_cells(ROOMS).reshape(ROOMS.width, ROOMS.width)
    assert d[0, 0] == 1 and (d[ROOMS.wall_mask] == 0).all()
    assert d.max() > 5


def test_labels_agree_with_the_tabular_joint_robot_at_its_lattice_points():
    tab = robot("planar3:joint")
    a = continuous_arm("planar3")
    rng = np.random.default_rng(1)
    for s in rng.choice(tab.n_states, 400, replace=False):
        assert a.set_configuration(tab.arm.qpos[s]) == tab.label[s]


def test_gymnasium_environment_passes_check_env_and_refuses_bad_actions():
    env = gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar3:joint", task=1)
    check_env(env.unwrapped)
    obs, info = env.reset(seed=0)
    assert obs.shape == (3 + 3,) and info["label"] == env.unwrapped.start_cell
    with pytest.raises(InvalidActionError, match=r"0\.\.5"):
        env.unwrapped.step(6)
    with pytest.raises(InvalidParameterError, match="valid wind: 0"):
        gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar2", wind=0.1)


def test_transfer_reward_wrapper_pays_the_pseudo_reward_on_the_label():
    env = gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar2", task=1)
    start, goal = env.unwrapped.start_cell, env.unwrapped.goal_cell
    traj = trajectories.shortest(robot("planar3:joint"), start, goal)
    wrapped = TransferReward(env, traj, method="pseudo", K=0.01)
    wrapped.reset(seed=0)
    bonus = {c: i * 0.01 for i, c in enumerate(traj.cells) if i >= 1}
    rng = np.random.default_rng(3)
    paid = 0
    for _ in range(300):
        _, reward, terminated, _, info = wrapped.step(int(rng.integers(4)))
        assert info["shaping"] == pytest.approx(bonus.get(info["label"], 0.0))
        assert reward == pytest.approx(-1.0 + info["shaping"])
        paid += info["shaping"] > 0
        if terminated:
            break
    assert paid > 0


def test_learning_on_the_arm_is_deterministic(arm):
    coding = tiles.TileCoding.over(*arm.bounds, 2 * arm.step, 4)
    goal = TABLE_I[1].cells(arm.layout)[1]
    config = LearnerConfig(max_episodes=3, max_total_steps=4000)
    runs = [linear.learn(arm, goal, coding, config, np.random.default_rng(9)) for _ in range(2)]
    assert runs[0].episode_steps.tobytes() == runs[1].episode_steps.tobytes()
    assert abs(runs[0].episode_steps).sum() == 4000 or runs[0].exploration_steps is not None


def test_api_runs_a_continuous_target_and_refuses_bad_values_in_one_line():
    r = armtransfer.transfer(source="planar2:joint", target="planar3:joint", state="continuous", task=1, trials=2,
                             trajectory="optimal", max_episodes=2, max_total_steps=3000)
    out = r.to_json()
    assert out["state"] == "continuous" and set(out["results"]) == {"none", "pseudo"}
    assert len(out["results"]["pseudo"]["exploration_steps"]) == 2
    bad = [(dict(state="cont"), "valid states: discrete, continuous"),
           (dict(state="continuous", target="ur5e_like:cartesian"), "valid action models: joint"),
           (dict(state="continuous", target="puma:joint"), "valid arms: planar2, planar3, planar4, ur5e_like"),
           (dict(state="continuous", target="planar3:cartesian"), "valid action models: joint"),
           (dict(state="continuous", methods=["guided"]), "method 'guided' does not apply.*valid methods: none, pseudo"),
           (dict(state="continuous", wind=0.1), "valid wind: 0")]
    for kwargs, message in bad:
        kw = {**dict(source="planar2:joint", target="planar3:joint", task=1, trials=1), **kwargs}
        with pytest.raises(ArmTransferError, match=message) as err:
            armtransfer.transfer(**kw)
        assert "\n" not in str(err.value)


def test_continuous_arm_names_the_valid_arms():
    with pytest.raises(UnknownArmError, match="valid arms: planar2, planar3, planar4, ur5e_like, panda_like, PATH.xml"):
        continuous_arm("puma")


@pytest.mark.slow
def test_benchmark_fast_mode_writes_its_report(tmp_path):
    out = tmp_path / "bench"
    done = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "bench_continuous.py"), "--fast", "--out", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    text = (out / "continuous.md").read_text()
    assert "ratio to bare MuJoCo" in text and "| planar2:joint -> planar3:joint (continuous) | 1 | pseudo |" in text
    again = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "bench_continuous.py"), "--fast", "--out",
                            str(out)], capture_output=True, text=True, timeout=120)
    assert again.returncode == 2 and again.stderr.count("\n") == 1 and "absent or empty" in again.stderr


@pytest.mark.slow
def test_a_generated_arm_is_a_continuous_arm_a_spatial_one_over_the_3d_workspace():
    from armtransfer.ik.continuous3d import SpatialContinuousArm

    arm = continuous_arm("gen:planar:3:1:joint")
    start = TABLE_I[1].cells(arm.layout)[0]
    arm.place(start)
    assert arm.dof == 3 and arm.label == start
    spatial = continuous_arm("gen:spatial6:6:1")
    assert isinstance(spatial, SpatialContinuousArm) and spatial.dof == 3 and spatial.levels == 3
    with pytest.raises(ArmTransferError, match="needs a planar arm"):
        ContinuousArm(spatial.scene, 0.05)


def test_from_its_start_the_arm_reaches_the_goal_in_the_joint_robots_fewest_moves():
    """The start is on the home lattice, so the moves reach what the joint model's reach: a
    breadth-first search over the continuous arm's own moves (MuJoCo at each) finds the goal
    of Table I task 1 as many moves away as the tabular planar2:joint robot's shortest path."""
    arm = continuous_arm("planar2")
    start, goal = TABLE_I[1].cells(arm.layout)
    arm.place(start)
    depth = {arm.key(): 0}
    frontier = [(arm.key(), arm.q.copy())]
    found = None
    while frontier and found is None:
        nxt = []
        for key, q in frontier:
            for a in range(arm.n_actions):
                arm.q[:] = q
                arm._n = list(key)
                label = arm.move(a)
                if label < 0 or arm.key() in depth:
                    continue
                depth[arm.key()] = depth[key] + 1
                if label == goal:
                    found = depth[arm.key()]
                nxt.append((arm.key(), arm.q.copy()))
        frontier = nxt
    tab = robot("planar2:joint")
    assert found == len(tab.shortest_path(tab.start_state(start), goal)) - 1
