"""The stable-baselines3 learners (armtransfer.learning.sb3): the Model protocol, determinism on
the CPU, the missing extra in one line, and torch kept out of ``import armtransfer``.

The tests that train need the ``sb3`` extra (stable-baselines3 and torch), which the default
test environment does not install: they skip, saying so, where it is absent."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from importlib.metadata import entry_points
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import armtransfer  # noqa: F401  (registers the environments)
from armtransfer.errors import ArmTransferError, MissingExtraError
from armtransfer.learning import sb3
from armtransfer.experiments.benchmark import label
from armtransfer.learning.learners import GROUP, Learner

ROOT = Path(__file__).resolve().parents[1]

needs_sb3 = pytest.mark.skipif(not sb3.available(), reason="the sb3 extra (stable-baselines3, torch) is not "
                                                         "installed: pip install 'armtransfer[sb3]'")
MAKERS = {"dqn": sb3.make_dqn, "ppo": sb3.make_ppo}


def env(seed: int = 0) -> gym.Env:
    e = gym.make("armtransfer/Rooms-v0", world="rooms11", task=1, robot="fine")
    e.reset(seed=seed)
    return e


class Steps(gym.Wrapper):
    def __init__(self, inner: gym.Env) -> None:
        super().__init__(inner)
        self.n = 0
        self.actions: list[int] = []

    def step(self, action):
        self.n += 1
        self.actions.append(int(action))
        return self.env.step(action)


def test_import_armtransfer_and_the_adapters_never_import_torch():
    code = ("import sys, armtransfer, armtransfer.learning.sb3 as s; "
            "print('torch' in sys.modules, 'stable_baselines3' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert out.stdout.split() == ["False", "False"]


@pytest.mark.parametrize("name", sorted(MAKERS))
def test_without_the_extra_making_a_model_is_one_line_naming_it(monkeypatch, name):
    monkeypatch.setattr(sb3, "available", lambda: False)
    with pytest.raises(MissingExtraError) as err:
        MAKERS[name](env(), 0)
    message = str(err.value)
    assert isinstance(err.value, ArmTransferError) and "\n" not in message
    assert f"learner {name!r}" in message and "armtransfer[sb3]" in message


@needs_sb3
@pytest.mark.parametrize("name", sorted(MAKERS))
def test_a_model_learns_on_and_predicts_actions_of_the_env(name):
    e = Steps(env())
    model = MAKERS[name](e, 3)
    assert callable(model.learn) and callable(model.predict)
    model.learn(100)
    first = e.n
    assert first >= 100 and model.num_timesteps == first
    model.learn(100)  # goes on: steps add up, not restart
    assert e.n >= first + 100 and model.num_timesteps == e.n
    action, state = model.predict(0, deterministic=True)
    assert e.action_space.contains(int(action)) and state is None


@needs_sb3
@pytest.mark.parametrize("name", sorted(MAKERS))
def test_same_seed_same_actions_however_models_interleave(name):
    a_env, b_env, c_env = Steps(env()), Steps(env()), Steps(env())
    states = range(0, int(a_env.observation_space.n), 5)

    def greedy(model) -> list[int]:
        return [int(model.predict(s, deterministic=True)[0]) for s in states]

    a, b, c = MAKERS[name](a_env, 11), MAKERS[name](b_env, 11), MAKERS[name](c_env, 12)
    half = sb3.PPO_N_STEPS  # whole PPO rollouts, so that both learn the same steps
    a.learn(2 * half)
    np.random.seed(123)  # the global generators are not the models'
    b.learn(half)
    c.learn(half)
    b.learn(half)
    c.learn(half)
    assert a_env.actions == b_env.actions
    assert greedy(a) == greedy(b)
    assert a_env.actions != c_env.actions  # another seed, other actions: the check can fail


# -- through the benchmark: the pyproject's entry points, as an install would declare them ------------

def _entry_point_site(tmp_path: Path) -> Path:
    """A folder declaring the pyproject's ``armtransfer.learners`` entry points, as ``pip install``
    of this tree would (this tree runs from its source folder, not installed): what the
    benchmark's worker processes read."""
    import tomllib

    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["entry-points"][GROUP]
    site = tmp_path / "site"
    info = site / "armtransfer_sb3_entry_points-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: armtransfer-sb3-entry-points\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(f"[{GROUP}]\n" + "".join(f"{k} = {v}\n" for k, v in declared.items()))
    return site


def _cli(tmp_path: Path, *args: str, code: str | None = None) -> subprocess.CompletedProcess:
    """``armtransfer ARGS`` (or ``python -c code ARGS``) seeing this tree's learners' entry points."""
    installed = {ep.name for ep in entry_points(group=GROUP)}
    path = [str(ROOT / "src")]
    if not {"dqn", "ppo"} <= installed and not (tmp_path / "site").exists():
        _entry_point_site(tmp_path)
    if not {"dqn", "ppo"} <= installed:
        path.insert(0, str(tmp_path / "site"))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([*path, os.environ.get("PYTHONPATH", "")]))
    head = ["-m", "armtransfer"] if code is None else ["-c", code]
    return subprocess.run([sys.executable, *head, *args], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=900)


def test_the_pyproject_declares_dqn_and_ppo_and_the_sb3_extra():
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    declared = project["entry-points"][GROUP]
    assert declared == {"dqn": "armtransfer.learning.sb3:DQN", "ppo": "armtransfer.learning.sb3:PPO"}
    for name, target in declared.items():
        module, _, attr = target.partition(":")
        learner = getattr(importlib.import_module(module), attr)
        assert isinstance(learner, Learner) and learner.name == name
    assert project["optional-dependencies"]["sb3"] == ["stable-baselines3>=2.3", "torch"]
    assert not any("torch" in d or "stable-baselines3" in d for d in project["dependencies"])


def test_without_the_extra_the_benchmark_says_what_to_install_in_one_line(tmp_path):
    # stable-baselines3 hidden from the command's process (None in sys.modules: not found)
    hide = ("import sys; sys.modules['stable_baselines3'] = None; sys.modules['torch'] = None; "
            "from armtransfer.cli import main; sys.exit(main(sys.argv[1:]))")
    done = _cli(tmp_path, "benchmark", "--suite", "fast", "--learner", "dqn", "--out", "runs/x", code=hide)
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert "learner 'dqn' needs stable-baselines3 and torch" in done.stderr and "armtransfer[sb3]" in done.stderr
    assert not (tmp_path / "runs" / "x").exists()
    helped = _cli(tmp_path, "benchmark", "--help", code=hide)
    assert "unavailable here: pip install 'armtransfer[sb3]'" in " ".join(helped.stdout.split())


@needs_sb3
@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(MAKERS))
def test_a_tiny_benchmark_runs_through_the_harness(tmp_path, name):
    done = _cli(tmp_path, "benchmark", "--suite", "fast", "--learner", name, "--method", "pseudo", "--workers", "2",
                "--out", "runs/b")
    assert done.returncode == 0, done.stderr
    data = json.loads((tmp_path / "runs" / "b" / "results.json").read_text())
    mine = [r for r in data["records"] if r.get("learner") == name]
    assert sorted({r["method"] for r in mine}) == sorted({label("none", name), label("pseudo", name)})
    for r in mine:
        assert r["error"] is None and len(r["first_exposure"]) == 2
        assert all(f is None or 0 < f <= r["cap"] for f in r["first_exposure"])


# -- suite small: cases in the small worlds -------------------------------------------------------

def test_the_small_suite_runs_its_cases_in_their_worlds_and_the_rooms_cases_name_none():
    from armtransfer.experiments import benchmark, suites
    from armtransfer.tasks.catalog import world_task
    from armtransfer.worlds.resolve import world as resolve_world

    suite = suites.get("small")
    assert suite.held_out and suite.sections[0].learners == ("sarsa", "dqn", "ppo")
    robots = benchmark.Robots({})
    plan = benchmark.plan(suite, 0, robots, ran=["none", "pseudo", "dense"])
    assert len(plan.pairs) == 2 * suite.sections[0].source_seeds
    for pair in plan.pairs:
        world = pair.case.world
        assert world in ("rooms11", "rooms15")
        start, goal = world_task(resolve_world(world), pair.case.task).cells()
        layout = robots(pair.case.target, world).layout
        assert layout.name == world and (layout.cell(*pair.start), layout.cell(*pair.goal)) == (start, goal)
        assert pair.source_run().world == world
        assert pair.base({"trajectory": None, "failure": "x"})["world"] == world
    keys = {p.source_run().key() for p in plan.pairs}
    assert len(keys) == len(plan.pairs)  # the two worlds' runs never share a key
    in_rooms = suites.get("fast").sections[0]
    assert "world" not in in_rooms.to_dict()["cases"][0]
