"""Plugin code the package did not write cannot hang or crash the testbed: whatever a method or
learner raises (a BaseException, an exception whose message cannot be made) or returns (an
object whose ``__array__`` raises, complex numbers), and however long it takes, the user reads
one line naming it; the probe runs in a child process under a time limit that is ended with
everything it started; a command that does not use a broken or sleeping plugin runs."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from test_plugins import fake_plugin, registered, run_cli  # noqa: F401  (registered: a fixture)

import armtransfer
from armtransfer.errors import InvalidParameterError, PluginError
from armtransfer.learning import methods


class Unprintable(Exception):
    def __str__(self) -> str:
        raise RuntimeError("no message")


class BadArray:
    def __array__(self, dtype=None, copy=None):
        raise KeyError("no array")


def _raise(err: BaseException):
    def potential(cells, trajectory):
        raise err
    return potential


@pytest.mark.parametrize("fn, fault", [
    (_raise(GeneratorExit()), r"its potential raised GeneratorExit$"),
    (_raise(SystemExit(3)), r"its potential raised SystemExit: 3$"),
    (_raise(Unprintable()), r"its potential raised Unprintable: \(its message cannot be printed"),
    (lambda c, t: BadArray(), r"its potential returned BadArray, which cannot be read as numbers \(KeyError"),
    (lambda c, t: np.zeros(len(c)) + 1j, r"its potential returned complex numbers"),
    (lambda c, t: np.full(len(c), 1e300), r"returned 1e\+300 for 2601 of 2601 states; .* at most 1e\+12"),
    (lambda c, t: os._exit(0), r"its potential ended the probe's process without an answer"),
])
def test_whatever_a_potential_raises_or_returns_is_one_line(registered, fn, fault):
    with pytest.raises(PluginError, match=fault) as err:
        registered(armtransfer.potential_method("hostile", "a hostile potential", fn))
    said = str(err.value)
    assert said.startswith("method 'hostile' (registered at run time): ") and "\n" not in said
    assert "hostile" not in armtransfer.METHODS


def test_a_sleeping_potential_is_named_within_the_limit_and_nothing_is_left_running(registered, tmp_path):
    """The probe's child, and a process the plugin started, are gone when the limit is reached."""
    marker = tmp_path / "pid"

    def sleepy(cells, trajectory):
        child = subprocess.Popen(["sleep", "300"])
        marker.write_text(str(child.pid))
        time.sleep(300)

    t0 = time.monotonic()
    with pytest.raises(PluginError, match=r"^method 'sleepy' \(registered at run time\): its potential did not "
                                          r"return within 1.5 s, the probe's time limit .*--probe-timeout"):
        registered(armtransfer.potential_method("sleepy", "sleeps", sleepy), probe_timeout=1.5)
    assert time.monotonic() - t0 < 10
    pid = int(marker.read_text())
    assert not _alive(pid), f"the plugin's process {pid} was left running"
    with pytest.raises(InvalidParameterError, match=r"probe_timeout must be a number of seconds in \(0, 86400\]"):
        armtransfer.register_method(armtransfer.potential_method("x", "x", lambda c, t: np.zeros(len(c))),
                                    probe_timeout=float("nan"))


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0]
    except FileNotFoundError:
        return False
    return state != "Z"  # a zombie is dead, waiting for its parent (init) to reap it


def test_k_is_bounded_before_and_after_the_multiplication(registered, capsys):
    from armtransfer.cli import main

    for K in (1e308, float("inf"), -1.0, "1e3", True):
        with pytest.raises(InvalidParameterError, match=r"K must be 'auto' or a number in \[0, 1e\+06\]"):
            armtransfer.transfer(methods=["potential"], K=K, trials=1)
    with pytest.raises(SystemExit) as code:
        main(["rooms", "--method", "potential", "--K", "1e308", "--trials", "1"])
    assert code.value.code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "must be 'auto' or a number in [0, 1e+06]" in err
    # a plugin's values pass their own check, then K times them is checked too
    registered(armtransfer.potential_method("big", "large values", lambda c, t: np.full(len(c), 1e9),
                                            auto_k=np.float32(1)))
    with pytest.raises(InvalidParameterError, match=r"K=1e\+06 times its potential gives -?1e\+15"):
        armtransfer.transfer(methods=["big"], K=1e6, trials=1, max_episodes=5, controls=False, trajectory="optimal")


def test_a_sleeping_or_raising_learner_is_named_in_one_line(tmp_path):
    from armtransfer.learning import learners

    class Model:
        def __init__(self, env, how):
            self.env, self.how = env, how

        def learn(self, total_timesteps):
            if self.how == "learn":
                time.sleep(300)
            if self.how == "raise":
                raise GeneratorExit
            self.env.reset()
            for _ in range(total_timesteps):
                self.env.step(0)
            return self

        def predict(self, obs, deterministic=True):
            if self.how == "predict":
                time.sleep(300)
            return 0, None

    for how, fault in (("learn", r"its learn did not return within 1 s"),
                       ("predict", r"its predict did not return within 1 s"),
                       ("raise", r"its learn raised GeneratorExit$")):
        name = f"slow-{how}"
        learners.register_learner(learners.Learner(name, "a hostile learner", lambda env, seed, h=how: Model(env, h)))
        try:
            t0 = time.monotonic()
            with pytest.raises(PluginError, match=rf"^learner '{name}' \(registered at run time\), on robot fine: "
                                                  + fault):
                armtransfer.transfer(methods=["none"], learner=name, trials=1, probe_timeout=1)
            assert time.monotonic() - t0 < 15
        finally:
            del learners.LEARNERS[name]


SLEEPY = """
import time
import numpy as np
import armtransfer

def potential(cells, trajectory):
    time.sleep(300)
    return np.zeros(len(cells))

SLEEPY = armtransfer.potential_method("sleepy", "sleeps", potential)
RAISES = armtransfer.potential_method("raises", "raises GeneratorExit",
                                      lambda c, t: (_ for _ in ()).throw(GeneratorExit()))
"""


@pytest.mark.slow  # the same cases, one command each, are dev/audit.py's (in the default suite)
def test_an_installed_plugin_that_sleeps_or_raises_breaks_only_itself(tmp_path):
    site = tmp_path / "site"
    site.mkdir()
    fake_plugin(site, "hostile-plugin", "hostile", SLEEPY, {"sleepy": "hostile:SLEEPY", "raises": "hostile:RAISES"})
    for argv in (["--help"], ["rooms", "--help"], ["benchmark", "--help"]):
        done = run_cli(tmp_path, *argv, path=site, timeout=60)
        assert done.returncode == 0 and done.stderr == "" and "usage:" in done.stdout, (argv, done.stderr)
    done = run_cli(tmp_path, "rooms", "--method", "none", "--trials", "1", "--max-episodes", "5", "--no-controls",
                   path=site, timeout=120)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    t0 = time.monotonic()
    out = tmp_path / "out"
    done = run_cli(tmp_path, "rooms", "--method", "sleepy", "--probe-timeout", "2", "--json", str(out / "r.json"),
                   path=site, timeout=120)
    assert time.monotonic() - t0 < 60
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert done.stderr.startswith("armtransfer rooms: error: plugin hostile-plugin 0.1 (entry point sleepy = "
                                  "hostile:SLEEPY in group armtransfer.methods), on robot fine: method 'sleepy': its potential did not "
                                  "return within 2 s"), done.stderr
    assert not out.exists()
    done = run_cli(tmp_path, "rooms", "--method", "raises", path=site, timeout=120)
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert "its potential raised GeneratorExit" in done.stderr and "Traceback" not in done.stderr
    done = run_cli(tmp_path, "rooms", "--help", path=site, env={"ARMTRANSFER_NO_PLUGINS": "yes"}, timeout=60)
    assert done.returncode == 2 and "ARMTRANSFER_NO_PLUGINS must be 1" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_learner_names_are_each_given_once(capsys):
    from armtransfer.learning.learners import parse

    for bad, said in (("sarsa,", "an empty learner name"), ("sarsa,sarsa", "learner 'sarsa' is named twice"),
                      (",", "no learner named"), (["sarsa", ""], "an empty learner name")):
        with pytest.raises(InvalidParameterError, match=said):
            parse(bad)
    assert parse("sarsa") == ("sarsa",)


def test_the_skip_variable_is_an_environment_variable_of_the_package():
    from armtransfer.environment import VARIABLES

    assert "ARMTRANSFER_NO_PLUGINS" in VARIABLES
    done = subprocess.run([sys.executable, "-c", "import armtransfer; print(len(armtransfer.METHODS))"],
                          env=dict(os.environ, ARMTRANSFER_NO_PLUGINS="1"), capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and int(done.stdout) == len(methods.BUILTIN), done.stderr


def test_a_long_trial_of_an_outside_learner_says_how_far_it_has_got(monkeypatch, capsys):
    """A slow learner is not mistaken for a hung one: a trial running past the heartbeat says
    its steps on stderr (here every chunk: the heartbeat is 0 s)."""
    from armtransfer.experiments import learner_trial
    from armtransfer.learning import learners

    class Slow:
        def __init__(self, env):
            self.env = env

        def learn(self, total_timesteps):
            self.env.reset()
            for _ in range(total_timesteps):
                self.env.step(0)
            return self

        def predict(self, obs, deterministic=True):
            return 0, None

    monkeypatch.setattr(learner_trial, "HEARTBEAT_SECONDS", 0.0)
    learners.register_learner(learners.Learner("slow", "a slow learner", lambda env, seed: Slow(env)))
    try:
        ticks = []
        armtransfer.transfer(methods=["none"], learner="slow", trials=1, max_total_steps=2000,
                             progress=lambda: ticks.append(1))
    finally:
        del learners.LEARNERS["slow"]
    lines = [line for line in capsys.readouterr().err.splitlines() if "steps learned in" in line]
    assert ticks == [1] and len(lines) >= 2, lines
    assert lines[0].startswith("armtransfer: learner 'slow' (registered at run time): method none, trial 1: ")
    assert " of 2,000 steps learned in " in lines[-1]


def test_a_plugin_that_hangs_as_it_is_imported_is_left_out(tmp_path, monkeypatch):
    import threading

    from armtransfer.learning import lazy_registry

    if threading.current_thread() is not threading.main_thread():
        pytest.skip("the import's timer runs in the main thread only")
    site = tmp_path / "site"
    site.mkdir()
    fake_plugin(site, "hanging-plugin", "hanging", "import time\ntry:\n    time.sleep(600)\nexcept Exception:\n"
                "    pass\nM = 3\n", {"hang": "hanging:M"})
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.setattr(lazy_registry, "IMPORT_SECONDS", 1.0)
    registry = lazy_registry.Registry({}, None)
    t0 = time.monotonic()
    with pytest.warns(lazy_registry.PluginWarning, match=r"plugin hanging-plugin 0.1 .* is left out \(did not import "
                                                         r"within 1 s\); remove it with 'pip uninstall hanging-plugin'"):
        found = lazy_registry.read_entry_points("armtransfer.methods", registry, "method", lambda obj, where: obj,
                                                lambda m: "hang", lambda m, where: m)
    assert found == {} and "hang" in registry.broken and time.monotonic() - t0 < 10
    assert "hanging" not in sys.modules
    with pytest.raises(PluginError, match="did not import within 1 s"):
        registry["hang"]
