"""The compiled learner against Algorithm 1, known answers, determinism and farming."""

import numpy as np
import pytest

from armtransfer.errors import InvalidParameterError
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.worlds.layout import Layout
from armtransfer.learning import reference, methods, rewards, sarsa
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig

# A 7 x 7 world with two rooms and one door: small enough for the dense reference.
SMALL = Layout(lo=-3, hi=3, walls=(((0, -3), (0, 3)),), doors=((0, 2),))


def small(robot_name="fine"):
    robot = grid_robot(robot_name, SMALL)
    start, goal = SMALL.cell(-2, -2), SMALL.cell(2, -2)
    return robot, robot.start_state(start), goal


@pytest.mark.parametrize("wind", [0.0, 0.2])
@pytest.mark.parametrize("with_transfer", [False, True])
def test_compiled_learner_is_bit_identical_to_dense_algorithm_1(wind, with_transfer):
    robot, s0, goal = small()
    config = LearnerConfig(trace_cutoff=0.0, max_episodes=15, patience=1000)
    traj = shaping = None
    K = 0.0
    if with_transfer:
        traj = trajectories.shortest(grid_robot("coarse", SMALL), robot.label[s0], goal)
        K = methods.get("pseudo").resolve_k("auto", config.step_reward, traj)
        shaping = methods.build_shaping("pseudo", robot, traj, K, config.step_reward)
    fast = sarsa.learn(robot, s0, goal, config, np.random.default_rng(3), shaping=shaping,
                       wind=wind, keep_q=True)
    Q, steps = reference.learn(robot, s0, goal, config, np.random.default_rng(3), episodes=15,
                               traj=traj, K=K, wind=wind)
    assert fast.episodes == 15
    assert fast.episode_steps.tolist() == steps
    assert np.array_equal(fast.Q, Q)


def test_default_trace_cutoff_stays_close_to_the_dense_algorithm():
    robot, s0, goal = small()
    # Over one episode both take the same actions (the random stream is the same and no
    # tie is broken differently); the Q tables then differ only by the dropped traces.
    exact = LearnerConfig(trace_cutoff=0.0, max_episodes=1)
    cut = LearnerConfig(max_episodes=1)
    a = sarsa.learn(robot, s0, goal, exact, np.random.default_rng(5), keep_q=True)
    b = sarsa.learn(robot, s0, goal, cut, np.random.default_rng(5), keep_q=True)
    assert a.episode_steps[0] == b.episode_steps[0] > 50
    # dropping traces below 1e-3 changes Q by far less than one step reward
    assert 0 < np.abs(a.Q - b.Q).max() < 0.05


def test_tiny_known_answer_task_converges_on_the_shortest_path():
    robot, s0, goal = small()
    res = sarsa.learn(robot, s0, goal, LearnerConfig(), np.random.default_rng(0))
    assert res.converged
    shortest = robot.shortest_path(s0, goal)
    assert res.greedy_steps == len(shortest) - 1 == 12  # 2 right and 4 up to the door, 2 right and 4 down
    assert res.greedy_path[-1][1] == -1 and robot.label[res.greedy_path[-1][0]] == goal
    # the path is a real path of the robot
    for (s, a), (t, _) in zip(res.greedy_path, res.greedy_path[1:]):
        assert robot.next_state[s, a] == t
    assert res.total_steps >= res.exploration_steps > 0


def test_same_seed_same_result_bit_for_bit():
    robot, s0, goal = small()
    runs = [sarsa.learn(robot, s0, goal, LearnerConfig(), np.random.default_rng(42), keep_q=True, wind=0.1)
            for _ in range(2)]
    assert np.array_equal(runs[0].episode_steps, runs[1].episode_steps)
    assert np.array_equal(runs[0].Q, runs[1].Q)
    other = sarsa.learn(robot, s0, goal, LearnerConfig(), np.random.default_rng(43), wind=0.1)
    assert not np.array_equal(other.episode_steps, runs[0].episode_steps)


def test_learner_does_not_touch_global_random_state():
    robot, s0, goal = small()
    np.random.seed(1)
    before = np.random.random()
    np.random.seed(1)
    sarsa.learn(robot, s0, goal, LearnerConfig(), np.random.default_rng(0))
    assert np.random.random() == before


def test_pseudo_reward_is_i_times_k_with_the_largest_index_on_loops():
    robot, s0, goal = small()
    c = SMALL.cell
    traj = trajectories.Trajectory(
        cells=(c(-2, -2), c(-1, -2), c(-2, -2), c(-1, -2), c(-1, -1)), actions=(2, 3, 2, 0, 0), goal=goal
    )
    sh = methods.build_shaping("pseudo", robot, traj, 0.1, -1.0)
    bonus = {SMALL.xy(int(robot.label[s])): sh.bonus[s] for s in range(robot.n_states) if sh.bonus[s]}
    assert bonus == pytest.approx({(-2, -2): 0.2, (-1, -2): 0.3, (-1, -1): 0.4})


def test_farmable_k_is_refused_with_the_bound_named():
    robot, s0, goal = small()
    traj = trajectories.shortest(grid_robot("coarse", SMALL), robot.label[s0], goal)
    bound = rewards.farming_bound(-1.0, traj)
    assert bound == pytest.approx(1.0 / traj.n)
    with pytest.raises(InvalidParameterError, match=r"farmed.*K < "):
        methods.build_shaping("pseudo", robot, traj, bound, -1.0)
    methods.build_shaping("pseudo", robot, traj, bound * 0.99, -1.0)  # just below: accepted
    methods.build_shaping("first-visit", robot, traj, bound * 10, -1.0)  # cannot be farmed


def test_pseudo_reward_speeds_up_the_first_episode_on_the_rooms_world():
    from armtransfer.tasks.catalog import table_task

    fine, coarse = grid_robot("fine"), grid_robot("coarse")
    start, goal = table_task(1).cells()
    traj = trajectories.shortest(coarse, start, goal)
    config = LearnerConfig(max_episodes=1)
    sh = methods.build_shaping("pseudo", fine, traj, "auto", config.step_reward)
    base, pseudo = [], []
    for trial in range(40):
        base.append(sarsa.learn(fine, fine.start_state(start), goal, config, np.random.default_rng(trial)).exploration_steps)
        pseudo.append(sarsa.learn(fine, fine.start_state(start), goal, config, np.random.default_rng(trial),
                                  shaping=sh).exploration_steps)
    assert np.mean(pseudo) < np.mean(base)


def test_config_rejects_out_of_range_parameters():
    with pytest.raises(InvalidParameterError, match="epsilon must be in"):
        LearnerConfig(epsilon=1.5)
    with pytest.raises(InvalidParameterError, match="alpha"):
        LearnerConfig(alpha=0)


def test_the_plain_kernel_is_the_guided_kernel_without_a_guide_bit_for_bit():
    """The kernel is compiled twice from one body (``sarsa._make_run_trial``); with no guide the
    one without the guide compiled in must learn exactly what the other does."""
    from armtransfer.tasks.catalog import TABLE_I

    S = sarsa
    robot = grid_robot("coarse")
    start, goal = TABLE_I[2].cells()
    config = LearnerConfig(max_episodes=30)
    runs = []
    for kernel in (S._run_trial, S._run_trial_guided):
        plain, S._run_trial = S._run_trial, kernel
        try:
            runs.append(S.learn(robot, robot.start_state(start), goal, config, np.random.default_rng(7), wind=0.1,
                                keep_q=True))
        finally:
            S._run_trial = plain
    a, b = runs
    assert S._run_trial is not S._run_trial_guided
    assert np.array_equal(a.Q, b.Q) and np.array_equal(a.episode_steps, b.episode_steps)
    assert a.greedy_path == b.greedy_path and a.first_path == b.first_path and a.episodes == b.episodes == 30
