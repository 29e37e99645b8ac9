"""The good-path clock: a trial ends on a settled path only when it is good, the clock counts the
steps until the greedy path is good and stays so, and the learner never reads the good length."""

from __future__ import annotations

import math

import numpy as np
import pytest

from armtransfer.experiments import experiment
from armtransfer.learning import clock, reference, sarsa
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.worlds.layout import Layout

# The small world of test_sarsa: two rooms and one door, small enough for the dense reference.
SMALL = Layout(lo=-3, hi=3, walls=(((0, -3), (0, 3)),), doors=((0, 2),))


def test_good_length_is_the_ceiling_without_the_floats_last_bit():
    assert clock.good_length(1.05, 20) == 21  # 1.05 * 20 is 21.000000000000004 as a float
    assert clock.good_length(1.05, 21) == 23  # 22.05 -> 23
    assert clock.good_length(1.0, 37) == 37
    assert clock.good_length(1.05, 40) == 42


def test_good_path_steps_counts_through_the_first_episode_of_the_last_good_run():
    lengths = [-1, 30, 21, 25, 21, 20]
    steps = [100, -50, 40, 30, 20, 20]
    # good (<= 21) from episode 4 to the end; episode 2 was good but not for good
    assert clock.good_path_steps(lengths, steps, 21) == 100 + 50 + 40 + 30 + 20
    assert clock.good_path_steps(lengths, steps, 20) == sum(abs(x) for x in steps)
    assert clock.good_path_steps(lengths + [-1], steps + [5], 21) is None  # not good at the end: none
    assert clock.good_path_steps([], [], 21) is None


def _small():
    robot = grid_robot("fine", SMALL)
    start, goal = SMALL.cell(-2, -2), SMALL.cell(2, -2)
    return robot, robot.start_state(start), goal


@pytest.mark.parametrize("seed, run_on", [(3, 1000.0), (3, 0.1), (4, 1.0)])
def test_the_stopping_rule_is_the_dense_references_greedy_paths_read_apart(seed, run_on):
    """The kernel with a good length learns exactly as Algorithm 1 (the dense reference, bit for
    bit) and stops at the first episode after which the reference's own greedy path has stayed the
    same for ``patience`` episodes and is at most the good length, or once it has run ``run_on``
    times the steps it took to first settle more (seed 3 settles on 14 steps of 12: with a large
    budget it runs to the episode cap, with 0.1 it stops soon after); its settled clock is the
    first such episode of any length."""
    robot, s0, goal = _small()
    optimal = len(robot.shortest_path(s0, goal)) - 1
    config = LearnerConfig(trace_cutoff=0.0, max_episodes=60, patience=3, quality=1.0, epsilon=0.3, run_on=run_on)
    fast = sarsa.learn(robot, s0, goal, config, np.random.default_rng(seed), keep_q=True, optimal=optimal)
    paths: list = []
    Q, steps = reference.learn(robot, s0, goal, config, np.random.default_rng(seed), episodes=fast.episodes,
                               paths=paths)
    assert fast.episode_steps.tolist() == steps
    assert np.array_equal(fast.Q, Q)
    assert fast.greedy_lengths.tolist() == [-1 if p is None else len(p) - 1 for p in paths]

    def settled(e: int) -> bool:
        last = paths[e - config.patience: e + 1]
        return e >= config.patience and last[0] is not None and all(p == last[0] for p in last)

    first = next(e for e in range(len(paths)) if settled(e))
    budget = sum(abs(x) for x in steps[: first + 1]) * (1 + config.run_on)  # the run-on budget, in steps
    spent = [e for e in range(first, len(paths)) if sum(abs(x) for x in steps[: e + 1]) >= budget]
    stops = [e for e in range(len(paths)) if settled(e) and len(paths[e]) - 1 <= optimal] + spent
    assert (fast.episodes - 1 == min(stops)) if stops else fast.episodes == config.max_episodes
    changed = max(e for e in range(first + 1) if e == 0 or paths[e] != paths[e - 1])
    assert fast.total_steps == sum(abs(x) for x in steps[: changed + 1])
    assert fast.greedy_steps == len(paths[first]) - 1
    assert fast.settled_ratio == fast.greedy_steps / optimal


def test_a_trial_with_a_good_path_ends_within_the_threshold_and_a_worse_settled_path_pays():
    """On the rooms (fine, Table I task 1) trials that settle on a longer path go on; every trial
    with a ``good_path_steps`` ends with a greedy path (followed afresh from its Q) within
    ceil(1.05 x shortest), the shortest read from the robot's table apart from the harness."""
    robot = grid_robot("fine")
    start, goal = table_task(1).cells()
    s0 = robot.start_state(start)
    optimal = len(robot.shortest_path(s0, goal)) - 1
    config = LearnerConfig()
    ran_on = 0
    for seed in range(3):
        t = sarsa.learn(robot, s0, goal, config, np.random.default_rng(seed), keep_q=True, optimal=optimal)
        assert t.good_len == math.ceil(1.05 * optimal - 1e-9)
        assert t.good_path_steps is not None
        path = reference.greedy_path(robot, t.Q, s0, goal)
        assert path is not None and len(path) - 1 <= t.good_len
        assert t.good_path_steps <= t.steps_run
        if t.settled_ratio > 1.05:  # settled on a worse path first: the trial went on and paid
            ran_on += 1
            assert t.good_path_steps > t.total_steps and t.episodes > config.patience + 1
    assert ran_on >= 1  # seeds 0-2 settle first on 22 steps of 20 (measured): the rule is exercised


def test_the_good_length_is_read_by_the_stopping_rule_alone():
    """The same trial without a good length, run for as many episodes, learns the same Q bit for
    bit: no choice of the learner reads it."""
    robot = grid_robot("fine")
    start, goal = table_task(1).cells()
    s0 = robot.start_state(start)
    optimal = len(robot.shortest_path(s0, goal)) - 1
    told = sarsa.learn(robot, s0, goal, LearnerConfig(), np.random.default_rng(0), keep_q=True, optimal=optimal)
    plain = sarsa.learn(robot, s0, goal, LearnerConfig(max_episodes=told.episodes, patience=1_000_000),
                        np.random.default_rng(0), keep_q=True)
    assert np.array_equal(told.Q, plain.Q)
    assert told.episode_steps.tolist() == plain.episode_steps.tolist()


def test_run_method_hands_the_shortest_path_over_and_summaries_carry_the_clock():
    robot = grid_robot("fine")
    start, goal = table_task(1).cells()
    res = experiment.run_method("none", robot, start, goal, None, 2, 5, LearnerConfig(), threads=1)
    optimal = len(robot.shortest_path(robot.start_state(start), goal)) - 1
    assert [t.optimal for t in res.trials] == [optimal, optimal]
    entry = experiment.summarize([res])["none"]
    for name in experiment.CLOCK:
        assert len(entry[name]) == 2
    assert all(v is not None for v in entry["good_path_steps"])
    assert entry["good_len"] == [clock.good_length(1.05, optimal)] * 2


def test_robot_1_stops_on_any_settled_path():
    """Robot 1's learning (the trajectory handed over) is as before: no good length, no clock."""
    robot = grid_robot("coarse")
    start, goal = table_task(1).cells()
    t = sarsa.learn(robot, robot.start_state(start), goal, LearnerConfig(), np.random.default_rng(1))
    assert t.good_len is None and t.good_path_steps is None and t.converged
    # it stopped when it settled: its last change then patience episodes unchanged
    assert int(np.abs(t.episode_steps[: t.episodes - LearnerConfig().patience]).sum()) == t.total_steps


def test_quality_below_one_is_refused():
    from armtransfer.errors import InvalidParameterError

    with pytest.raises(InvalidParameterError, match="quality"):
        LearnerConfig(quality=0.9)


def test_lazy_cannot_buy_the_good_path_clock_on_a_small_case():
    """``lazy`` (``plan`` told nothing, exploring less) settles sooner than ``plan`` on worse paths:
    the settled clock ranks it ahead, the good-path clock behind (fine, Table I task 3, 4 trials;
    geometric means of the trial-paired factors, a trial never good counted at the cap)."""
    robot = grid_robot("fine")
    start, goal = table_task(3).cells()
    config = LearnerConfig()
    plan = experiment.run_method("plan", robot, start, goal, None, 4, 11, config, threads=2)
    lazy = experiment.run_method("lazy", robot, start, goal, None, 4, 11, config, threads=2)

    def factor(name: str) -> float:
        cap = config.max_total_steps
        base = [getattr(t, name) or cap for t in plan.trials]
        mine = [getattr(t, name) or cap for t in lazy.trials]
        return float(np.exp(np.mean(np.log(np.array(base, float) / np.array(mine, float)))))

    assert factor("total_steps") > 1.5  # the settled clock: lazy "wins"
    assert factor("good_path_steps") < 1.0  # the good-path clock: it does not
    assert max(t.settled_ratio for t in lazy.trials) > 1.05 >= max(t.settled_ratio for t in plan.trials)


def test_a_quality_below_one_is_a_one_line_error_before_the_benchmark_writes(tmp_path, capsys):
    from armtransfer.cli import main

    out = tmp_path / "b"
    assert main(["benchmark", "--suite", "fast", "--quality", "0.9", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "quality" in err and len(err.splitlines()) == 1
    assert not out.exists() or not any(out.iterdir())


def test_a_benchmark_of_another_quality_is_another_store():
    from armtransfer.experiments import benchmark, suites

    default = benchmark.plan(suites.get("fast"))
    exact = benchmark.plan(suites.get("fast"), quality=1.0)
    assert "quality" not in default.spec()["benchmark"] and exact.spec()["benchmark"]["quality"] == 1.0
    assert exact.pairs[0].config.quality == 1.0


def test_an_outside_learners_clock_comes_from_its_greedy_evaluations():
    from armtransfer.experiments.learner_trial import eval_clock

    evals = [[100, None], [200, 21], [300, 25], [400, 21], [500, 20]]
    out = eval_clock(evals, optimal=20, good_len=21, settled=22, total=510)
    assert out == {"good_path_steps": 400, "shortest_path_steps": 500, "settled_ratio": 1.1, "final_ratio": 1.0,
                   "steps_run": 510}
    assert eval_clock(evals + [[600, 30]], 20, 21, None, 610)["good_path_steps"] is None


def test_the_frame_and_the_json_carry_the_clock_per_trial():
    pytest.importorskip("pandas")
    import armtransfer

    r = armtransfer.transfer("coarse", "fine", task=1, methods=["none", "pseudo"], trials=2, seed=3, controls=False)
    df = r.to_frame()
    for name in ("good_path_steps", "settled_ratio", "shortest_path_steps", "final_ratio", "steps_run"):
        assert name in df.columns
    assert list(df.columns[:6]) == ["method", "control", "trial", "reached", "good_path_steps", "settled_ratio"]
    data = r.to_json()["results"]["pseudo"]
    assert len(data["good_path_steps"]) == len(data["settled_ratio"]) == 2
