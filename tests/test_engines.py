"""Who learns a run: the ``Engine`` interface and the one place that chooses it (``experiments.engines``)."""

from pathlib import Path

import pytest

from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import engines

ROOT = Path(__file__).resolve().parents[1]


def test_the_built_in_learner_has_an_engine_for_either_state_and_an_outside_one_for_a_table():
    assert engines.engine_for("sarsa").name == engines.TABULAR
    assert engines.engine_for("sarsa", "continuous").name == engines.CONTINUOUS
    assert engines.engine_for("dqn", "discrete").name == engines.OUTSIDE
    assert set(engines.ENGINES) == {engines.TABULAR, engines.CONTINUOUS, engines.OUTSIDE}


def test_a_pairing_no_engine_runs_is_one_line_naming_the_valid_ones():
    with pytest.raises(InvalidParameterError) as err:
        engines.engine_for("dqn", "continuous", "case 3 has")
    text = str(err.value)
    assert "\n" not in text and "'dqn'" in text and "case 3 has a continuous one" in text and text.endswith("sarsa")
    with pytest.raises(InvalidParameterError, match="unknown state 'voxel'; valid states: discrete, continuous"):
        engines.engine_for("sarsa", "voxel")


def test_no_driver_makes_its_own_choice_of_engine():
    """The refusal of an outside learner on a continuous target is written once, in engines.py;
    the transfer call, the benchmark's plan and trial runs and sweep runs ask engines.py for the
    engine, and the trial runs and sweep runs learn through its ``trials`` (no driver calls a
    learner's own run_method; the transfer call's kernel path, with its controls and mapping, too)."""
    src = ROOT / "src" / "armtransfer"
    holders = [p.relative_to(src).as_posix() for p in src.rglob("*.py") if "learns on a discrete target" in p.read_text()]
    assert holders == ["experiments/engines.py"]
    for path in ("api.py", "experiments/benchmark.py", "experiments/benchmark_runs.py", "experiments/execute.py"):
        text = (src / path).read_text()
        assert "engines.engine_for(" in text, path
    for path in ("experiments/benchmark_runs.py", "experiments/execute.py"):
        text = (src / path).read_text()
        assert ".trials(work_of(run)" in text and "run_method(" not in text, path
    api = (src / "api.py").read_text()  # the outside, continuous and kernel paths
    assert api.count("req.engine.trials(") == 3
    assert not any(f"{run}(" in api for run in ("run_method", "run_all", "run_control", "run_mapping"))


def test_each_engine_is_an_engine_and_a_learner_this_build_lacks_is_one_line():
    from armtransfer.errors import ArmTransferError

    chosen = {engines.engine_for("sarsa"), engines.engine_for("sarsa", "continuous"), engines.engine_for("dqn")}
    assert {e.name for e in chosen} == set(engines.ENGINES) and all(isinstance(e, engines.Engine) for e in chosen)
    with pytest.raises(ArmTransferError, match="unknown learner 'gone'; valid learners: sarsa, "):
        engines.engine_for("gone")


def test_the_tabular_engine_learns_what_the_kernel_learns_trial_k_alone_as_trial_k_of_all():
    """An engine's trials are the learner's own: trial 1 asked alone is trial 1 of two."""
    from armtransfer.experiments import experiment
    from armtransfer.learning.config import LearnerConfig
    from armtransfer.tasks.grid_robots import grid_robot

    fine, config = grid_robot("fine"), LearnerConfig(max_episodes=40)
    work = engines.Work("none", "fine", (0, 0), (-8, 12), 2, 3, config)
    both = engines.engine_for("sarsa").trials(work, fine, None)
    start, goal = fine.layout.cell(0, 0), fine.layout.cell(-8, 12)
    direct = experiment.run_method("none", fine, start, goal, None, 2, 3, config)
    assert [t.episode_steps.tolist() for t in both.trials] == [t.episode_steps.tolist() for t in direct.trials]
    alone = engines.engine_for("sarsa").trials(engines.Work("none", "fine", (0, 0), (-8, 12), 1, 3, config,
                                                            first_trial=1), fine, None)
    assert alone.trials[0].episode_steps.tolist() == both.trials[1].episode_steps.tolist()
    assert both.trials[0].episode_steps.tolist() != both.trials[1].episode_steps.tolist()


def test_the_tabular_engine_runs_a_control_and_the_mapping_as_the_kernel_runs_them():
    """A work with a control is ``run_control``'s trials (each its own stand-ins); a work with a
    mapping is ``run_mapping``'s, and its result carries the mapping updated."""
    from armtransfer.experiments import experiment
    from armtransfer.learning.config import LearnerConfig
    from armtransfer.learning.mapping import ActionMapping
    from armtransfer.tasks.grid_robots import grid_robot

    coarse, fine, config = grid_robot("coarse"), grid_robot("fine"), LearnerConfig(max_episodes=40)
    start, goal = fine.layout.cell(0, 0), fine.layout.cell(-8, 12)
    traj = experiment.source_trajectory("optimal", coarse, start, goal, config, 3)
    tabular = engines.engine_for("sarsa")
    work = engines.Work("pseudo", "fine", (0, 0), (-8, 12), 2, 3, config, control="random", source=coarse)
    got = tabular.trials(work, fine, [traj])
    want = experiment.run_control("pseudo", "random", coarse, fine, start, goal, [traj], 2, 3, config)
    assert got.label == want.label == "pseudo [random]" and got.extra == want.extra
    assert [t.episode_steps.tolist() for t in got.trials] == [t.episode_steps.tolist() for t in want.trials]
    empty = ActionMapping.for_robots(coarse, fine)
    got = tabular.trials(engines.Work("mapping", "fine", (0, 0), (-8, 12), 2, 3, config, mapping=empty), fine, [traj])
    want, learned = experiment.run_mapping(fine, start, goal, traj, empty, 2, 3, config)
    assert got.extra == want.extra and len(empty) == 0
    assert got.learned_mapping is not None and got.learned_mapping.to_json() == learned.to_json()
    with pytest.raises(InvalidParameterError, match="exactly one trajectory"):
        tabular.trials(engines.Work("mapping", "fine", (0, 0), (-8, 12), 1, 3, config, mapping=empty), fine,
                       [traj, traj])


def test_the_transfer_call_refuses_an_outside_learner_on_a_continuous_target_before_anything_runs():
    import armtransfer

    with pytest.raises(InvalidParameterError, match="learner 'dqn' learns on a discrete target; the target is a "
                                                    "continuous one; valid learners for it: sarsa"):
        armtransfer.transfer("planar2:joint", "planar3:joint", task=1, learner="dqn", state="continuous")
