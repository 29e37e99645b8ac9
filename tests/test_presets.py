"""Learner presets: ``--preset`` on every command, ``preset=`` in the API, ``preset`` in a sweep file."""

import json
from pathlib import Path

import pytest

import armtransfer
from armtransfer.cli import main
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import matrix, sweep
from armtransfer.learning import presets
from armtransfer.learning.config import LearnerConfig

ROOT = Path(__file__).resolve().parents[1]
CALIBRATED = presets.PRESETS[presets.PAPER_CALIBRATED]


def test_the_calibrated_preset_is_the_fit_the_search_wrote():
    fit = json.loads((ROOT / "research" / "calibration" / "calibration.json").read_text())["fit"]
    assert fit["initial_q"] == 0.0  # LearnerConfig has no initial Q: the fit must not need one
    for key in ("alpha", "gamma", "lam", "epsilon", "step_reward", "goal_reward"):
        assert CALIBRATED[key] == fit[key], key


def test_a_preset_fills_the_config_and_explicit_options_win():
    cfg = presets.config(presets.PAPER_CALIBRATED)
    for key, value in CALIBRATED.items():
        assert getattr(cfg, key) == value
    assert presets.config(presets.DEFAULT) == LearnerConfig()
    assert presets.config(presets.PAPER_CALIBRATED, {"epsilon": 0.42}).epsilon == 0.42


@pytest.mark.parametrize("bad", ["nope", "", None, 3])
def test_an_unknown_preset_is_refused_naming_the_valid(bad):
    with pytest.raises(InvalidParameterError, match="valid presets: default, paper-calibrated"):
        presets.config(bad)


def test_api_preset_changes_the_learner():
    r = armtransfer.transfer("coarse", "fine", task=1, methods=["none"], trials=1, controls=False,
                             preset="paper-calibrated", max_episodes=3)
    assert (r.config.alpha, r.config.epsilon) == (CALIBRATED["alpha"], CALIBRATED["epsilon"])
    assert r.config.max_episodes == 3
    with pytest.raises(InvalidParameterError, match="unknown preset 'x'; valid presets"):
        armtransfer.transfer("coarse", "fine", task=1, methods=["none"], trials=1, preset="x")


@pytest.mark.parametrize("command", [
    ["rooms", "--trials", "1"],
    ["arms", "--fast"],
    ["reproduce", "--trials", "1"],
    ["benchmark", "--suite", "paper"],
    ["matrix", "--robots", "coarse,fine", "--out", "OUT"],
    ["sweep", "FILE", "--out", "OUT"],
])
def test_every_command_refuses_an_unknown_preset_in_one_line(command, tmp_path, capsys):
    args = [str(tmp_path / "o") if a == "OUT" else a for a in command]
    if "FILE" in args:
        f = tmp_path / "s.toml"
        f.write_text('[sweep]\ntasks = [1]\npreset = "nope"\n')
        args = [str(f) if a == "FILE" else a for a in args]
    else:
        args += ["--preset", "nope"]
    with pytest.raises(SystemExit) as exc:  # argparse exits; a sweep file's error returns
        raise SystemExit(main(args))
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "nope" in err and "default, paper-calibrated" in err
    assert not (tmp_path / "o").exists()


def test_a_sweep_preset_sets_its_runs_learner_and_the_default_keeps_its_keys():
    plain = sweep.normalise({"sweep": {"tasks": [1]}})
    assert "preset" not in plain and all("preset" not in r.to_dict() for r in sweep.expand(plain))
    spec = sweep.normalise({"sweep": {"tasks": [1], "preset": "paper-calibrated", "epsilon": [0.3]}})
    runs = sweep.expand(spec)
    assert runs and all(r.preset == "paper-calibrated" for r in runs)
    cfg = runs[0].learner_config()
    assert (cfg.alpha, cfg.gamma, cfg.lam) == (CALIBRATED["alpha"], CALIBRATED["gamma"], CALIBRATED["lam"])
    assert cfg.epsilon == 0.3  # the sweep's own value wins over the preset's
    assert {r.key() for r in runs}.isdisjoint({r.key() for r in sweep.expand(plain)})


def test_a_matrix_carries_its_preset():
    spec = matrix.matrix_spec(["coarse", "fine"], [1], ["pseudo"], 1, preset="paper-calibrated")
    assert spec["preset"] == "paper-calibrated" and spec["alpha"] == [CALIBRATED["alpha"]]
    assert "preset" not in matrix.matrix_spec(["coarse", "fine"], [1], ["pseudo"], 1)
