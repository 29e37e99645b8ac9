"""The baselines that isolate each source of gain (``plan``, ``goal-only``, ``pseudo-plan``) and
the registry's record of which baseline shares each method's learner."""

from dataclasses import replace

import numpy as np
import pytest

import armtransfer
from armtransfer.learning import guide, methods, sarsa
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.experiments import experiment, matrix
from test_first_exposure import SMALL, assert_kernel_is_reference, small_task

EXACT = LearnerConfig(trace_cutoff=0.0, max_episodes=6, patience=1000)


def test_every_method_names_baselines_that_share_its_learner():
    for name, m in methods.METHODS.items():
        for b in m.baselines:
            base = methods.get(b)
            assert b != name and base.is_baseline or b == "none"
            if not m.macros:  # the same updates and the same way of choosing actions
                assert base.chooses == m.chooses, (name, b)
        if m.baselines:  # the first is told nothing
            first = methods.get(m.baseline)
            assert not first.shaped or not first.uses_trajectory
        else:
            assert not m.shaped or not m.uses_trajectory, name
    assert methods.get("guided").baselines == ("plan", "goal-only")
    assert methods.get("pseudo-plan").baseline == "plan" and methods.get("dense").baseline == "none"
    assert methods.get("none").baseline is None and methods.get("plan").baseline is None


def test_the_baselines_are_run_beside_the_methods_that_need_them():
    assert methods.with_baselines(["guided"]) == ["plan", "goal-only", "guided"]
    assert methods.with_baselines(["pseudo", "dense"]) == ["none", "pseudo", "dense"]
    assert methods.with_baselines(["none", "pseudo-plan", "plan"]) == ["none", "plan", "pseudo-plan"]
    spec = matrix.matrix_spec(["coarse", "fine"], [1], ["guided"], trials=1)
    assert spec["methods"] == ["none", "plan", "goal-only", "guided"]
    r = armtransfer.transfer(methods=["pseudo-plan"], trials=1, seed=0, controls=False, max_episodes=5,
                             trajectory="optimal")
    assert list(r.methods) == ["plan", "pseudo-plan"]
    alone = armtransfer.transfer(methods=["pseudo-plan"], trials=1, seed=0, controls=False, max_episodes=5,
                                 trajectory="optimal", baselines=False)
    assert list(alone.methods) == ["pseudo-plan"]
    # the baselines are not transfer methods of their own: no controls, not in the paper's tables
    assert not set(methods.SHAPED) & {"plan", "goal-only", "pseudo-plan"}


@pytest.mark.parametrize("name", ["plan", "goal-only", "pseudo-plan"])
def test_kernel_is_bit_identical_to_the_dense_reference_for_each_baseline(name):
    fine, coarse, start, goal = small_task()
    traj = trajectories.shortest(coarse, start, goal)
    sh = methods.build_shaping(name, fine, [traj], "auto" if name != "pseudo-plan" else 0.05, -1.0)
    assert sh.guide is not None
    assert_kernel_is_reference(fine, start, goal, EXACT, 11, sh, traj=traj if name == "pseudo-plan" else None)


def test_plan_is_guided_with_the_trajectory_weighing_nothing():
    """plan's placeholder trajectory changes nothing: the guide of the real trajectory with weight
    0 (and no give-up, tip model or fill, which only feed the trajectory's score) runs the same
    trial, bit for bit; and plan needs no trajectory at all."""
    fine, coarse, start, goal = small_task()
    traj = trajectories.shortest(coarse, start, goal)
    plan = methods.build_shaping("plan", fine, None, "auto", -1.0)
    real = replace(plan, guide=guide.build(fine, [traj], weight=0.0, give_up=0, tip=False, fill=0.0))
    config = LearnerConfig(max_episodes=20)
    s0 = fine.start_state(start)
    a = sarsa.learn(fine, s0, goal, config, np.random.default_rng(4), shaping=plan, keep_q=True)
    b = sarsa.learn(fine, s0, goal, config, np.random.default_rng(4), shaping=real, keep_q=True)
    assert a.episode_steps.tolist() == b.episode_steps.tolist() and np.array_equal(a.Q, b.Q)
    guided = sarsa.learn(fine, s0, goal, config, np.random.default_rng(4),
                         shaping=methods.build_shaping("guided", fine, [traj], "auto", -1.0))
    assert guided.episode_steps.tolist() != a.episode_steps.tolist()  # the weight is what the route acts through


def test_goal_only_is_told_the_start_and_the_goal_and_nothing_of_the_route():
    fine, coarse, start, goal = small_task()
    direct = trajectories.shortest(coarse, start, goal)
    mid = SMALL.cell(-2, 2)
    a, b = trajectories.shortest(coarse, start, mid), trajectories.shortest(coarse, mid, goal)
    detour = trajectories.Trajectory(cells=(*a.cells, *b.cells), actions=(*a.actions, *b.actions), goal=goal)
    g1 = methods.build_shaping("goal-only", fine, [direct], "auto", -1.0).guide
    g2 = methods.build_shaping("goal-only", fine, [detour], "auto", -1.0).guide
    for field in ("tx", "ty", "trem", "tstart", "params"):
        assert np.array_equal(getattr(g1, field), getattr(g2, field))
    # its score reads the start and the goal only, and the goal from anywhere (the window)
    assert [(x, y) for x, y in zip(g1.tx, g1.ty)] == [SMALL.xy(start), SMALL.xy(goal)]
    assert g1.params.window >= 1e6 and g1.params.give_up == 0 and g1.params.fill == methods.GOAL_FILL > 0


def test_pseudo_plan_is_the_pseudo_reward_on_plans_learner():
    fine, coarse, start, goal = small_task()
    traj = trajectories.shortest(coarse, start, goal)
    pp = methods.build_shaping("pseudo-plan", fine, [traj], 0.05, -1.0)
    pseudo = methods.build_shaping("pseudo", fine, [traj], 0.05, -1.0)
    plan = methods.build_shaping("plan", fine, None, "auto", -1.0)
    assert pp.mode == pseudo.mode and np.array_equal(pp.bonus, pseudo.bonus)
    assert np.array_equal(pp.guide.params, plan.guide.params)
    assert methods.get("pseudo-plan").farmable  # the planner does not change what a loop earns


def test_summaries_state_each_improvement_against_the_baselines_sharing_its_learner():
    fine, coarse, start, goal = small_task()
    traj = trajectories.shortest(coarse, start, goal)
    config = LearnerConfig(max_episodes=30)
    names = methods.with_baselines(["none", "dense", "guided"])
    runs = [experiment.run_method(n, fine, start, goal, [traj], 4, 0, config) for n in names]
    out = experiment.summarize(runs)
    assert set(out["guided"]["improvement_against"]) == {"plan", "goal-only"}
    assert set(out["dense"]["improvement_against"]) == {"none"}
    assert out["dense"]["improvement_against"]["none"]["percent"] == out["dense"]["improvement_percent"]
    for key in ("censored", "cap_dominated"):  # the flags travel with every improvement
        assert out["dense"]["improvement_against"]["none"][key] == out["dense"][f"improvement_{key}"]
    assert out["none"]["improvement_against"] == {} and out["plan"]["improvement_against"] == {}
    plan = np.array(out["plan"]["exploration_steps"], float)
    guided = np.array(out["guided"]["exploration_steps"], float)
    assert out["guided"]["improvement_against"]["plan"]["percent"] == pytest.approx(
        100 * (1 - guided.mean() / plan.mean()))
