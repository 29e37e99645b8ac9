"""The one place that chooses who learns a run: ``experiments.engines.engine_of``."""

from pathlib import Path

import pytest

from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import engines

ROOT = Path(__file__).resolve().parents[1]


def test_the_built_in_learner_has_an_engine_for_either_state_and_an_outside_one_for_a_table():
    assert engines.engine_of("sarsa") == engines.TABULAR
    assert engines.engine_of("sarsa", "continuous") == engines.CONTINUOUS
    assert engines.engine_of("dqn", "discrete") == engines.OUTSIDE
    assert set(engines.ENGINES) == {engines.TABULAR, engines.CONTINUOUS, engines.OUTSIDE}


def test_a_pairing_no_engine_runs_is_one_line_naming_the_valid_ones():
    with pytest.raises(InvalidParameterError) as err:
        engines.engine_of("dqn", "continuous", "case 3 has")
    text = str(err.value)
    assert "\n" not in text and "'dqn'" in text and "case 3 has a continuous one" in text and text.endswith("sarsa")
    with pytest.raises(InvalidParameterError, match="unknown state 'voxel'; valid states: discrete, continuous"):
        engines.engine_of("sarsa", "voxel")


def test_no_driver_makes_its_own_choice_of_engine():
    """The refusal of an outside learner on a continuous target is written once, in engines.py, and
    the transfer call, the benchmark and sweeps ask engine_of."""
    src = ROOT / "src" / "armtransfer"
    holders = [p.relative_to(src).as_posix() for p in src.rglob("*.py") if "learns on a discrete target" in p.read_text()]
    assert holders == ["experiments/engines.py"]
    for path in ("api.py", "experiments/benchmark.py", "experiments/benchmark_runs.py", "experiments/execute.py"):
        assert "engines.engine_of(" in (src / path).read_text(), path


def test_the_transfer_call_refuses_an_outside_learner_on_a_continuous_target_before_anything_runs():
    import armtransfer

    with pytest.raises(InvalidParameterError, match="learner 'dqn' learns on a discrete target; the target is a "
                                                    "continuous one; valid learners for it: sarsa"):
        armtransfer.transfer("planar2:joint", "planar3:joint", task=1, learner="dqn", state="continuous")
