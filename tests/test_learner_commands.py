"""Outside learners in every command: ``rooms``, ``arms``, ``sweep`` and ``matrix`` take
``--learner`` (a sweep file ``learner``) and run each method by it beside the ``none`` it runs,
through the benchmark's harness (``experiments.learner_transfer``); sarsa stays the default,
its output and store keys unchanged. Bad names, methods an outside learner cannot run and
learners that raise are one line, exit 2, nothing written.

In this process the learner is a tiny numpy Q-learner registered at run time; the sweep's and
the matrix's workers are other processes, so there it is installed as a plugin (a dist-info
beside its module on PYTHONPATH, as ``pip install --target`` leaves it).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import armtransfer
from armtransfer.cli import main
from armtransfer.experiments import sweep as sweeps
from armtransfer.learning import learners

ROOT = Path(__file__).resolve().parents[1]

CODE = textwrap.dedent('''
    import numpy as np
    import armtransfer

    class Q:
        """One-step Q-learning in a numpy table; every draw from the seed it is handed."""

        def __init__(self, env, seed):
            self.env, self.rng, self.obs = env, np.random.default_rng(seed), None
            self.q = np.zeros((env.observation_space.n, env.action_space.n))

        def learn(self, total_timesteps):
            for _ in range(int(total_timesteps)):
                if self.obs is None:
                    self.obs, _ = self.env.reset()
                s = int(self.obs)
                row = self.q[s]
                a = (int(self.rng.integers(len(row))) if self.rng.random() < 0.1
                     else int(self.rng.choice(np.flatnonzero(row == row.max()))))
                obs, r, term, trunc, _ = self.env.step(a)
                self.q[s, a] += 0.5 * (r + (0.0 if term else 0.99 * self.q[int(obs)].max()) - self.q[s, a])
                self.obs = None if term or trunc else obs
            return self

        def predict(self, observation, deterministic=True):
            return int(np.argmax(self.q[int(observation)])), None

    L = armtransfer.Learner("tiny-q", "test: one-step Q-learning in numpy", lambda env, seed: Q(env, seed))

    class Broken(Q):
        def learn(self, total_timesteps):
            raise RuntimeError("the table is on fire")

    BROKEN = armtransfer.Learner("broken-q", "test: raises in learn", lambda env, seed: Broken(env, seed))
''')

SMALL = ["--world", "rooms11", "--task", "1", "--trials", "2", "--max-total-steps", "2000", "--trajectory", "optimal"]
"""A small world, two trials, a tiny budget (the harness evaluates every 2000 // 200 = 10 steps)."""


def _module() -> dict:
    space: dict = {}
    exec(compile(CODE, "tiny_q", "exec"), space)  # noqa: S102 - the test's own learner
    return space


@pytest.fixture
def tiny():
    """``tiny-q`` and ``broken-q`` registered in this process for one test."""
    space = _module()
    armtransfer.register_learner(space["L"])
    armtransfer.register_learner(space["BROKEN"])
    yield
    for name in ("tiny-q", "broken-q"):
        if name in learners.LEARNERS:
            del learners.LEARNERS[name]


def one_line_error(capsys, code: int) -> str:
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    return err


def test_rooms_runs_an_outside_learner_beside_its_none_and_the_same_seed_gives_the_same_bytes(tiny, tmp_path, capsys):
    for name in ("a.json", "b.json"):
        assert main(["rooms", *SMALL, "--learner", "tiny-q", "--method", "none", "pseudo",
                     "--json", str(tmp_path / name)]) == 0
    out = capsys.readouterr().out
    assert "learner tiny-q (each method beside the none it runs; no controls)" in out
    assert "| pseudo | none " in out and "| none   | (baseline) " in out
    data = json.loads((tmp_path / "a.json").read_text())
    assert data["learner"] == "tiny-q" and list(data["results"]) == ["none", "pseudo"] and data["controls"] == {}
    for entry in data["results"].values():
        assert len(entry["exploration_steps"]) == 2
        assert all(t is None or 0 < t <= 2000 for t in entry["total_steps"])
        assert all(sum(abs(s) for s in ep) <= 2000 for ep in entry["episode_steps"])
    assert "none" in data["results"]["pseudo"]["improvement_against"]
    assert data["results"]["pseudo"]["K"] > 0
    assert (tmp_path / "a.json").read_bytes() == (tmp_path / "b.json").read_bytes()


def test_the_api_takes_learner_and_sarsa_is_the_default_unchanged(tiny):
    kw = dict(source="coarse", target="fine", world="rooms11", task="1", methods=["none", "pseudo"], trials=2,
              trajectory="optimal", max_total_steps=2000, controls=False)
    built_in = armtransfer.transfer(**kw).to_json()
    assert "learner" not in built_in and armtransfer.transfer(**kw, learner="sarsa").to_json() == built_in
    outside = armtransfer.transfer(**kw, learner="tiny-q")
    assert outside.learner == "tiny-q" and outside.to_json()["results"].keys() == built_in["results"].keys()
    # trial k of every method starts from the kernel's seeds of trial k: a method and its none are paired
    assert outside.to_json()["results"]["pseudo"]["improvement_design"].startswith("paired")


def test_arms_runs_an_outside_learner(tiny, tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["arms", "--source", "coarse", "--target", "fine", *SMALL, "--learner", "tiny-q", "--method", "none",
                 "pseudo", "--no-video", "--out", str(out)]) == 0
    data = json.loads((out / "results.json").read_text())
    assert data["learner"] == "tiny-q" and list(data["results"]) == ["none", "pseudo"]
    assert "learner tiny-q" in (out / "table.md").read_text() and "| pseudo | none " in capsys.readouterr().out


@pytest.mark.parametrize("command", ["rooms", "arms"])
def test_a_learner_typo_a_method_it_cannot_run_and_a_learner_that_raises_are_one_line(tiny, tmp_path, capsys,
                                                                                      command):
    out = tmp_path / "out"
    where = ["--json", str(out)] if command == "rooms" else ["--no-video", "--out", str(out)]
    robots = [] if command == "rooms" else ["--source", "coarse", "--target", "fine"]
    base = [command, *robots, *SMALL, *where]
    err = one_line_error(capsys, main([*base, "--learner", "tiny-qq"]))
    assert "unknown learner 'tiny-qq'; valid learners: sarsa, " in err and "tiny-q, broken-q" in err
    err = one_line_error(capsys, main([*base, "--learner", "tiny-q", "--method", "none", "plan"]))
    assert ("learner 'tiny-q' (registered at run time) cannot run method 'plan': an outside learner runs none and "
            "the reward-term methods; valid methods: none, pseudo,") in err
    err = one_line_error(capsys, main([*base, "--learner", "tiny-q", "--method", "none", "pseudo", "--K", "10"]))
    assert "K=10 can be farmed on this task" in err  # checked as for the kernel
    err = one_line_error(capsys, main([*base, "--learner", "broken-q", "--method", "none", "pseudo"]))
    assert "learner 'broken-q' (registered at run time), on robot fine: its learn raised RuntimeError: the table " \
           "is on fire" in err
    assert not out.exists() and not list(tmp_path.glob(".*"))


def test_help_of_rooms_and_arms_lists_the_learners(tiny, capsys):
    for command in ("rooms", "arms"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = " ".join(capsys.readouterr().out.split())
        assert "--learner NAME" in text and "Learners: sarsa: SARSA(lambda)" in text
        assert "tiny-q: test: one-step Q-learning in numpy" in text


# -- sweeps and the matrix: worker processes, so an installed learner ----------------------------

SWEEP = """[sweep]
name = "learners"
world = "rooms11"
tasks = ["1"]
pairs = [["coarse", "fine"]]
methods = ["none", "pseudo"]
trials = 2
trajectory = "optimal"
"""


def test_a_sweep_without_learner_keeps_its_spec_and_keys():
    raw = {"sweep": {"name": "s", "tasks": [1], "methods": ["none", "pseudo"]}}
    plain = sweeps.normalise(raw)
    assert "learner" not in plain and "max_total_steps" not in plain
    assert sweeps.normalise({"sweep": {**raw["sweep"], "learner": "sarsa"}}) == plain
    assert all("learner" not in run.to_dict() and "max_total_steps" not in run.to_dict() for run in sweeps.expand(plain))


def test_a_sweeps_learner_axis_keys_its_runs_apart(tiny):
    spec = sweeps.normalise({"sweep": {"name": "s", "tasks": [1], "methods": ["none", "pseudo"],
                                       "learner": ["sarsa", "tiny-q"], "max_total_steps": 500}})
    runs = sweeps.expand(spec)
    assert [r.learner for r in runs] == ["sarsa", "sarsa", "tiny-q", "tiny-q"]
    assert len({r.key() for r in runs}) == 4 and all(r.max_total_steps == 500 for r in runs)
    assert sweeps.check_stored(json.loads(json.dumps(spec)), "store") == spec


@pytest.mark.parametrize("body, message", [
    ('learner = "tiny-qq"', "unknown learner 'tiny-qq'; valid learners: sarsa, "),
    ('learner = ["tiny-q", "tiny-q"]', "learner lists a value twice"),
    ('learner = ["tiny-q"]\nmethods = ["none", "plan"]', "learner 'tiny-q' (registered at run time) cannot run "
                                                        "method 'plan'"),
    ('learner = "tiny-q"', "learner 'tiny-q' was registered in this process (register_learner) and a sweep's runs "
                           "run in other processes"),
])
def test_a_bad_learner_in_a_sweep_is_one_line_and_writes_nothing(tiny, tmp_path, capsys, body, message):
    text = SWEEP if "methods" not in body else SWEEP.replace('methods = ["none", "pseudo"]\n', "")
    (tmp_path / "s.toml").write_text(text + body + "\n")
    err = one_line_error(capsys, main(["sweep", str(tmp_path / "s.toml"), "--out", str(tmp_path / "store")]))
    assert message in err and not (tmp_path / "store").exists()


def test_a_bad_learner_on_the_matrix_is_one_line_and_writes_nothing(tiny, tmp_path, capsys):
    base = ["matrix", "--robots", "coarse,fine", "--world", "rooms11", "--tasks", "1", "--out", str(tmp_path / "m")]
    err = one_line_error(capsys, main([*base, "--learner", "sarsa,tiny-qq"]))
    assert "unknown learner 'tiny-qq'; valid learners: sarsa, " in err
    err = one_line_error(capsys, main([*base, "--learner", "tiny-q", "--methods", "plan"]))
    assert "cannot run method 'plan'" in err
    err = one_line_error(capsys, main([*base, "--learner", "tiny-q", "--methods", "pseudo"]))
    assert "was registered in this process" in err
    assert not (tmp_path / "m").exists()


def install(site: Path) -> Path:
    """The test's learners as an installed plugin ``tiny-learners`` (what pip --target leaves)."""
    site.mkdir()
    (site / "tiny_q.py").write_text(CODE)
    info = site / "tiny_learners-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: tiny-learners\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[armtransfer.learners]\ntiny-q = tiny_q:L\nbroken-q = tiny_q:BROKEN\n")
    return site


def cli(site: Path, cwd: Path, *args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(site), str(ROOT / "src")]))
    return subprocess.run([sys.executable, "-m", "armtransfer", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=300)


def test_a_sweep_runs_an_installed_learner_beside_its_none(tmp_path):
    site = install(tmp_path / "site")
    (tmp_path / "s.toml").write_text(SWEEP + 'learner = "tiny-q"\nmax_total_steps = 2000\n')
    done = cli(site, tmp_path, "sweep", "s.toml", "--out", "store", "--workers", "1")
    assert done.returncode == 0 and "2/2 runs in store; 0 failed" in done.stdout, done.stderr
    runs = [json.loads(p.read_text()) for p in sorted((tmp_path / "store" / "runs").glob("*.json"))]
    assert {r["config"]["learner"] for r in runs} == {"tiny-q"} and len(runs) == 2
    assert all(len(r["result"]["exploration_steps"]) == 2 for r in runs)
    summary = cli(site, tmp_path, "summarize", "store")
    assert "| pseudo@tiny-q " in summary.stdout and "| none@tiny-q " in summary.stdout, summary.stderr


def test_the_matrix_runs_an_installed_learner_beside_its_none(tmp_path):
    site = install(tmp_path / "site")
    done = cli(site, tmp_path, "matrix", "--robots", "coarse,fine", "--world", "rooms11", "--tasks", "1", "--methods",
               "pseudo", "--trials", "2", "--trajectory", "optimal", "--learner", "tiny-q", "--max-total-steps",
               "2000", "--out", "m", "--workers", "1")
    assert done.returncode == 0, done.stderr
    assert "### pseudo@tiny-q: improvement over no transfer (none@tiny-q)" in done.stdout
    cells = json.loads((tmp_path / "m" / "matrix.json").read_text())["cells"]
    assert {c["method"] for c in cells} == {"pseudo@tiny-q"} and all(c["improvement"] is not None for c in cells)


def test_an_installed_learner_that_raises_stops_a_sweep_before_its_store_and_rooms_help_lists_it(tmp_path):
    site = install(tmp_path / "site")
    (tmp_path / "s.toml").write_text(SWEEP + 'learner = "broken-q"\nmax_total_steps = 2000\n')
    done = cli(site, tmp_path, "sweep", "s.toml", "--out", "store")
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert "learner 'broken-q' (plugin tiny-learners 0.1 (entry point broken-q = tiny_q:BROKEN in group " \
           "armtransfer.learners)), on robot fine: its learn raised RuntimeError: the table is on fire" in done.stderr
    assert not (tmp_path / "store").exists()
    helped = " ".join(cli(site, tmp_path, "rooms", "--help").stdout.split())
    assert "tiny-q: test: one-step Q-learning in numpy" in helped
