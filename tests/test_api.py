"""The Python API: typed results, the same JSON as the command, errors before any learning,
and a method registry that a new method needs only one entry in."""

import json
import subprocess
import sys

import numpy as np
import pytest

import armtransfer
from armtransfer.cli import main
from armtransfer.errors import ArmTransferError, InvalidParameterError
from armtransfer.learning import methods as registry
from armtransfer.learning import shaping as modes
from armtransfer.experiments.experiment import MethodResult
from armtransfer.learning.trial_result import TrialResult
from armtransfer.learning.shaping import Shaping


def test_transfer_returns_typed_results_with_controls_as_a_field():
    r = armtransfer.transfer(source="coarse", target="fine", task=1, methods=["none", "pseudo"], trials=3, seed=1)
    assert list(r.methods) == ["none", "pseudo"]
    assert isinstance(r.methods["pseudo"], MethodResult)
    assert all(isinstance(t, TrialResult) for t in r.methods["pseudo"].trials)
    assert len(r.methods["none"].trials) == 3
    assert set(r.controls) == {"shuffled", "random"}
    assert r.controls["random"]["pseudo"].control == "random"
    assert r.methods["pseudo"].control is None
    assert r.distance == 20  # Table I task 1 for the fine robot
    data = r.to_json()
    assert set(data["results"]) == {"none", "pseudo"}
    assert set(data["controls"]["shuffled"]) == {"pseudo"}
    assert data["results"]["pseudo"]["exploration_steps"] == r.methods["pseudo"].column("exploration_steps")
    assert data["trajectory"]["source"] == "coarse"


def test_to_json_is_exactly_what_rooms_json_writes(tmp_path, capsys):
    path = tmp_path / "r.json"
    code = main(["rooms", "--task", "2", "--method", "none", "pseudo", "dense", "--trials", "2", "--seed", "3",
                 "--epsilon", "0.2", "--json", str(path)])
    assert code == 0
    api = armtransfer.transfer(source="coarse", target="fine", task=2, methods=["none", "pseudo", "dense"],
                               trials=2, seed=3, epsilon=0.2)
    assert json.loads(path.read_text()) == json.loads(json.dumps(api.to_json()))


def test_same_seed_same_json_bit_for_bit():
    kw = dict(source="fine", target="coarse", task=3, methods=["pseudo"], trials=2, seed=5, controls=False)
    a, b = armtransfer.transfer(**kw).to_json(), armtransfer.transfer(**kw).to_json()
    assert json.dumps(a) == json.dumps(b)
    c = armtransfer.transfer(**{**kw, "seed": 6}).to_json()
    assert json.dumps(a) != json.dumps(c)


@pytest.mark.parametrize("kwargs,message", [
    (dict(methods=["nope"]), "unknown method 'nope'; valid methods: none, pseudo, mapping"),
    (dict(bogus=1), "unknown learner option 'bogus'; valid options: alpha"),
    (dict(seed=-1), "seed must be an integer >= 0"),
    (dict(trials=0), "trials must be an integer >= 1"),
    (dict(wind=1.5), "wind must be a probability"),
    (dict(task=9), "unknown task 9"),
    (dict(start=(0, 0)), "start and goal go together"),
    (dict(start=(0, 0), goal=(-3, 0)), "inside a wall"),
    (dict(epsilon=float("nan")), "epsilon must be in [0, 1]"),
    (dict(step_reward=float("inf")), "step_reward must be in [-1e+06, 1e+06]"),
    (dict(source="nobody"), "unknown robot 'nobody'; valid: coarse, fine"),
    (dict(K=5.0), "can be farmed"),
    (dict(mapping="m.json"), "a mapping goes with method 'mapping'"),
])
def test_bad_input_is_one_line_error_before_learning(kwargs, message):
    with pytest.raises(ArmTransferError) as err:
        armtransfer.transfer(**{"methods": ["none", "pseudo"], "trials": 1, **kwargs})
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_a_farmable_k_is_refused_before_the_first_trial(monkeypatch):
    import armtransfer.experiments.experiment as experiment

    calls = []
    monkeypatch.setattr(experiment, "run_method", lambda *a, **k: calls.append(a))
    with pytest.raises(InvalidParameterError):
        armtransfer.transfer(methods=["none", "first-visit", "pseudo"], K=5.0, trials=1)
    assert calls == []


def test_a_new_method_needs_only_a_registry_entry(monkeypatch):
    """A method defined by one Method entry runs through the API, the CLI and the controls."""

    def double_bonus(robot, trajs, k, beta):
        base = registry.METHODS["first-visit"].build(robot, trajs, k, beta)
        return Shaping(modes.MODE_FIRST_VISIT, 2 * base.bonus, base.traj_index, base.phi, k)

    new = registry.Method("double", "first-visit paying twice", paper=False, build=double_bonus, auto_k=5.0)
    monkeypatch.setitem(registry.METHODS, "double", new)  # SHAPED and the controls' list see it
    r = armtransfer.transfer(methods=["none", "double"], trials=2, seed=0)
    assert r.methods["double"].extra["K"] == 5.0
    assert "double" in r.controls["shuffled"]
    fv = armtransfer.transfer(methods=["first-visit"], trials=2, seed=0, K=10.0, controls=False)
    assert r.methods["double"].column("exploration_steps") == fv.methods["first-visit"].column("exploration_steps")


def test_every_registered_method_runs_and_describes_itself():
    for name, m in registry.METHODS.items():
        assert m.name == name and m.description and "\n" not in m.description
        r = armtransfer.transfer(methods=[name], trials=1, seed=0, controls=False, max_episodes=50,
                                 trajectory="optimal", world="rooms15")
        assert len(r.methods[name].trials) == 1
    help_text = subprocess.run([sys.executable, "-m", "armtransfer.cli", "rooms", "--help"],
                               capture_output=True, text=True, timeout=120).stdout
    flat = " ".join(help_text.split())
    for m in registry.METHODS.values():
        assert " ".join(m.description.split()) in flat


def test_learner_config_fields_are_the_flags(tmp_path):
    """Every settable LearnerConfig field is a flag of `rooms` and reaches the result's config."""
    from dataclasses import fields

    from armtransfer.learning.config import LearnerConfig

    path = tmp_path / "r.json"
    args = ["rooms", "--method", "none", "--trials", "1", "--no-controls", "--json", str(path)]
    expected = dict(alpha=0.2, gamma=0.98, lam=0.8, epsilon=0.05, step_reward=-2.0, goal_reward=1.0,
                    max_episodes=1999, max_total_steps=19_000_000, max_episode_steps=190_000, patience=19, quality=1.1, run_on=2.0)
    assert set(expected) == {f.name for f in fields(LearnerConfig) if f.metadata.get("cli")}
    for name, value in expected.items():
        assert getattr(LearnerConfig(), name) != value
        args += [f"--{name.replace('_', '-')}", str(value)]
    assert main(args) == 0
    config = json.loads(path.read_text())["config"]
    for name, value in expected.items():
        assert config[name] == value, name


def test_robot_objects_and_specs_are_interchangeable():
    from armtransfer.tasks.grid_robots import grid_robot

    a = armtransfer.transfer(source=grid_robot("coarse"), target="fine", methods=["pseudo"], trials=1, controls=False)
    b = armtransfer.transfer(source="coarse", target=grid_robot("fine"), methods=["pseudo"], trials=1, controls=False)
    assert a.to_json() == b.to_json()
    assert np.array_equal(a.methods["pseudo"].trials[0].episode_steps, b.methods["pseudo"].trials[0].episode_steps)


def test_an_arm_file_is_a_robot_spec(scara_xml):
    r = armtransfer.transfer(source="coarse", target=f"{scara_xml}:cartesian", task=4, methods=["none"], trials=1,
                             controls=False, arm_options={"tip_site": "pen_tip", "base_pos": (-0.1, 0.0, 0.0)})
    assert r.target.name == "my_scara:cartesian"
    assert r.target.arm is not None and r.target.arm.xml_path == str(scara_xml)
    assert r.methods["none"].trials[0].exploration_steps is not None
