"""Learners from outside the package (``armtransfer.learning.learners``) and the benchmark's
harness that runs them (``armtransfer.experiments.learner_trial``): the contract, the registry,
entry points, the harness's counting, seeds and convergence criterion, and bad learners refused
in one line before anything is written.

The installed example plugin's learner (``tabular-q``) is in ``test_example_plugin.py``.
"""

from __future__ import annotations

import dataclasses
import types
import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import gymnasium
import numpy as np
import pytest

import armtransfer
from armtransfer.cli import main
from armtransfer.errors import InvalidParameterError, PluginError
from armtransfer.experiments import benchmark, benchmark_runs, learner_trial, suites
from armtransfer.experiments.run import TrialRun
from armtransfer.learning import learners
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.grid_robots import grid_robot

AT_IMPORT = list(armtransfer.LEARNERS)
"""The learners before any test registers one: the built-in sarsa, then those installed
packages declare (armtransfer's own dqn and ppo, importable without their extra)."""

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def registered():
    """Register learners for one test; they are gone after it."""
    names: list[str] = []

    def register(learner, **kw):
        lr = armtransfer.register_learner(learner, **kw)
        names.append(lr.name)
        return lr

    yield register
    for name in names:
        if name in learners.LEARNERS:
            del learners.LEARNERS[name]


class Oracle:
    """A model that knows the shortest path from the start from step ``wise`` on: before, it
    learns by stepping at random and predicts action 0. Every draw from its own Generator."""

    def __init__(self, env, seed: int, wise: int = 0) -> None:
        self.env, self.rng, self.wise, self.steps, self.obs = env, np.random.default_rng(seed), wise, 0, None
        base = env.unwrapped
        path = base.robot.shortest_path(base.start_state, base.goal_cell)
        self.next = {int(s): int(a) for s, a in path[:-1]}

    def learn(self, total_timesteps: int):
        for _ in range(total_timesteps):
            if self.obs is None or self.steps == self.wise:  # wise from the start of an episode
                self.obs, _ = self.env.reset()
            wise = self.steps >= self.wise
            a = self.predict(self.obs)[0] if wise else int(self.rng.integers(self.env.action_space.n))
            self.obs, _, terminated, truncated, _ = self.env.step(a)
            self.steps += 1
            if terminated or truncated:
                self.obs = None
        return self

    def predict(self, observation, deterministic: bool = True):
        if self.steps < self.wise:
            return 0, None
        return self.next.get(int(observation), 0), None


SMALL = suites.Section("small", "coarse -> fine task 1, one source seed, a short budget",
                       (suites.Case("coarse", "fine", 1),), source_seeds=1, trials=2, max_total_steps=20_000)
SMALL_SUITE = suites.Suite("small", 1, False, SMALL.description, (SMALL,))


def _run(method: str, trial: int, budget: int, seed: int = 5, wind: float = 0.0) -> TrialRun:
    cfg = LearnerConfig(max_total_steps=budget)
    return benchmark_runs.trial_run(method, trial, "coarse", "fine", [0, 0], [-8, 12], wind, seed, cfg, None,
                                    learner="oracle")


# -- the contract and the registry ---------------------------------------------------------------

def test_the_contract_is_exported_and_sarsa_is_the_built_in_learner():
    assert armtransfer.Learner is learners.Learner and armtransfer.LEARNERS is learners.LEARNERS
    assert list(armtransfer.LEARNERS)[0] == "sarsa" and armtransfer.LEARNERS["sarsa"].origin == "armtransfer"
    assert [f.name for f in dataclasses.fields(armtransfer.Learner)][:3] == ["name", "description", "make"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        armtransfer.LEARNERS["sarsa"].name = "x"  # type: ignore[misc]
    with pytest.raises(InvalidParameterError, match="runs in armtransfer's compiled kernel"):
        armtransfer.LEARNERS["sarsa"].make(None, 0)  # type: ignore[arg-type]


def test_a_registered_learner_is_listed_and_its_name_is_guarded(registered):
    lr = registered(armtransfer.Learner("oracle", "knows the shortest path", Oracle))
    assert lr.origin == "registered at run time" and list(armtransfer.LEARNERS)[-1] == "oracle"
    assert learners.parse("sarsa, oracle") == ("sarsa", "oracle")
    with pytest.raises(InvalidParameterError, match="learner 'sarsa' is named twice"):
        learners.parse("sarsa, oracle,sarsa")  # a repeated name is a typo, said rather than dropped
    with pytest.raises(PluginError, match="learner 'oracle' .* the name is taken .*pass replace=True"):
        armtransfer.register_learner(armtransfer.Learner("oracle", "again", Oracle))
    assert registered(armtransfer.Learner("oracle", "again", Oracle), replace=True).description == "again"
    with pytest.raises(PluginError, match="taken by a learner of armtransfer; rename it$"):
        armtransfer.register_learner(armtransfer.Learner("sarsa", "mine", Oracle), replace=True)
    with pytest.raises(PluginError, match="register_learner takes an armtransfer.Learner"):
        armtransfer.register_learner(Oracle)  # type: ignore[arg-type]
    with pytest.raises(PluginError, match="a learner's name is lower-case"):
        armtransfer.register_learner(armtransfer.Learner("My Q", "bad name", Oracle))
    with pytest.raises(PluginError, match="make must be a function"):
        armtransfer.register_learner(armtransfer.Learner("q2", "no make", 3))  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match=f"unknown learner 'oracel'; valid learners: {', '.join(AT_IMPORT)}, oracle"):
        learners.parse("oracel")


# -- the harness ---------------------------------------------------------------------------------

def test_convergence_is_the_first_of_k_good_greedy_episodes(registered):
    """A learner that is wise from step 7,000 on: its greedy episodes are the shortest path from
    the first chunk boundary at or after 7,000, so it converges at that boundary exactly; its
    first exposure, a walk, is what the monitor counted."""
    registered(armtransfer.Learner("oracle", "wise from step 7000", lambda env, seed: Oracle(env, seed, 7000)))
    fine = grid_robot("fine")
    budget = 20_000
    res = benchmark_runs.execute(_run("none", 0, budget), {"fine": fine})[0]
    chunk = budget // learner_trial.CHUNKS
    first_good = -(-7000 // chunk) * chunk
    assert benchmark_runs.trial_problem(res) is None
    optimal = len(fine.shortest_path(fine.start_state(fine.layout.cell(0, 0)), fine.layout.cell(-8, 12))) - 1
    assert res["converged"] and res["convergence_steps"] == first_good and res["greedy_steps"] == optimal
    assert [s for _, s in res["evaluations"]] == [None] * (first_good // chunk - 1) + [optimal] * learner_trial.EVALS
    assert res["evaluations"][-1][0] == first_good + (learner_trial.EVALS - 1) * chunk  # it stopped there
    assert res["first_exposure"] is not None and res["first_exposure"] <= 7000 + optimal
    # the walk's episode given up at step 7,000 (negative in the stream), then shortest paths
    assert res["episodes"] >= 2 and res["curve"][res["episodes"] - 1] == optimal


def test_a_learner_that_never_gets_there_is_censored_at_the_budget(registered):
    registered(armtransfer.Learner("oracle", "never wise", lambda env, seed: Oracle(env, seed, 10**9)))
    res = benchmark_runs.execute(_run("none", 0, 6_000), {"fine": grid_robot("fine")})[0]
    assert benchmark_runs.trial_problem(res) is None
    assert not res["converged"] and res["convergence_steps"] is None and res["greedy_steps"] is None
    assert len(res["evaluations"]) == learner_trial.CHUNKS and res["evaluations"][-1][0] == 6_000
    assert res["first_exposure"] is None or res["first_exposure"] <= 6_000


def test_a_method_and_its_baseline_get_the_same_seeds_and_the_same_seed_the_same_bytes(registered):
    seen: list[tuple[str, int, int]] = []

    class Recording(Oracle):
        def __init__(self, env, seed):
            seen.append((type(env).__name__, seed, int(env.unwrapped.np_random.integers(2**31))))
            super().__init__(env, seed, 3000)

    registered(armtransfer.Learner("oracle", "wise from step 3000, recording its seeds", Recording))
    plan = benchmark.plan(SMALL_SUITE, 4, ran=["none", "pseudo"], learners=("oracle",))
    assert plan.labels() == ["none@oracle", "pseudo@oracle"]
    records, _ = benchmark.run_suite(SMALL_SUITE, 4, threads=1, learners=("oracle",))
    assert [(r["method"], r["learner"], r["baselines"]) for r in records] == [  # the suite's reward-term methods
        ("none@oracle", "oracle", []), ("pseudo@oracle", "oracle", ["none@oracle", "goal-dense@oracle"]),
        ("dense@oracle", "oracle", ["none@oracle", "goal-dense@oracle"]),
        ("goal-dense@oracle", "oracle", ["none@oracle"])]  # the goal-only baseline of the reward terms
    runs = plan.all_trial_runs(plan.pairs[0], {"trajectory": {"cells": [0], "actions": [0], "goal": 1,
                                                              "source": "x"}, "failure": None})
    assert [(r.method, r.trial) for r in runs] == [("none", 0), ("none", 1), ("pseudo", 0), ("pseudo", 1)]
    # none's trial k and pseudo's trial k: the same model seed and the same environment stream
    assert len(seen) == 8 and [s[1:] for s in seen[:2]] == [s[1:] for s in seen[2:4]] == [s[1:] for s in seen[4:6]] \
        == [s[1:] for s in seen[6:]]  # none, pseudo, dense, goal-dense
    assert seen[0][1:] != seen[1][1:]
    assert seen[0][0] == "Monitor"
    again, _ = benchmark.run_suite(SMALL_SUITE, 4, threads=1, learners=("oracle",))
    assert json.dumps(again) == json.dumps(records)
    other, _ = benchmark.run_suite(SMALL_SUITE, 5, threads=1, learners=("oracle",))
    assert [r["seed"] for r in other] != [r["seed"] for r in records]


def test_the_training_env_carries_the_methods_reward_term_and_none_none(registered):
    envs: dict[str, object] = {}

    def make(env, seed):
        envs[env.unwrapped.__class__.__name__ + str(len(envs))] = env
        return Oracle(env, seed, 0)

    registered(armtransfer.Learner("oracle", "keeps its envs", make))
    fine = grid_robot("fine")
    traj = benchmark_runs.trajectory_json(armtransfer.learning.trajectory.shortest(grid_robot("coarse"),
                                                                                 fine.layout.cell(0, 0),
                                                                                 fine.layout.cell(-8, 12)))
    cfg = LearnerConfig(max_total_steps=2_000)
    run = benchmark_runs.trial_run("pseudo", 0, "coarse", "fine", [0, 0], [-8, 12], 0.0, 5, cfg,
                                   {"trajectory": traj, "failure": None}, learner="oracle")
    res = benchmark_runs.execute(run, {"fine": fine})[0]
    assert res["K"] is not None and res["K"] > 0
    res = benchmark_runs.execute(_run("none", 0, 2_000), {"fine": fine})[0]
    assert res["K"] is None
    pseudo_env, none_env = envs.values()
    assert type(pseudo_env.env).__name__ == "TransferReward" and type(none_env.env).__name__ == "TimeLimit"


def test_an_outside_learner_runs_only_none_and_the_reward_term_methods():
    ran, _ = benchmark.methods_to_run(("pseudo", "guided", "dense"))
    assert benchmark.learner_methods("sarsa", ran) == ran
    assert benchmark.learner_methods("dqn", ran) == ["none", "pseudo", "dense", "goal-dense"]
    assert benchmark.baselines_of("pseudo@dqn") == ("none@dqn", "goal-dense@dqn")
    assert benchmark.baselines_of("pseudo") == ("none", "goal-dense")
    from armtransfer.experiments.reports.benchmark_report import describe

    assert describe("none@dqn").startswith("no transfer; learned by dqn")
    assert describe("none") == "Algorithm 1 without transfer"


def test_the_default_learners_keep_the_suites_key_and_bytes():
    """A suite of the built-in learner alone keeps the store key it had before learners."""
    assert "learners" not in suites.FAST.to_dict()
    plan = benchmark.plan(suites.get("fast"), 0, ran=["none", "pseudo"])
    assert "learners" not in plan.spec()["benchmark"]
    many = benchmark.plan(suites.get("fast"), 0, ran=["none", "pseudo"], learners=("sarsa", "sarsa"))
    assert many.spec()["benchmark"]["learners"] == ["sarsa", "sarsa"]
    two = dataclasses.replace(suites.FAST, learners=("sarsa", "other"))
    assert two.to_dict()["learners"] == ["sarsa", "other"]


@pytest.mark.parametrize("action, fault", [
    (np.array([1, 2]), r"an action of shape \(2,\)"),
    (float("nan"), r"the action nan, not in the action space"),
    (99, r"the action 99, not in the action space Discrete\(\d+\)"),
    (1.5, r"the action 1.5, not in the action space"),
    ("up", r"str 'up' as an action"),
])
def test_a_bad_action_is_refused_naming_the_learner(registered, action, fault):
    class Bad(Oracle):
        def predict(self, observation, deterministic=True):
            return action, None

    registered(armtransfer.Learner("oracle", "acts badly", lambda env, seed: Bad(env, seed, 10**9)))
    said = r"learner 'oracle' \(registered at run time\): its predict returned "
    with pytest.raises(PluginError, match=said + fault):
        benchmark_runs.execute(_run("none", 0, 2_000), {"fine": grid_robot("fine")})
    four = gymnasium.spaces.Discrete(4)
    assert [learner_trial.action_of(a, four, "x") for a in (np.int64(3), np.array(2), np.array([1]), 0.0)] == \
        [3, 2, 1, 0]


def test_a_learner_that_takes_no_step_is_refused(registered):
    class Idle(Oracle):
        def learn(self, total_timesteps):
            return self

    registered(armtransfer.Learner("oracle", "idles", lambda env, seed: Idle(env, seed, 0)))
    with pytest.raises(PluginError, match=r"learner 'oracle' .*: its learn\(10\) took no step of the environment"):
        benchmark_runs.execute(_run("none", 0, 2_000), {"fine": grid_robot("fine")})


# -- the command ---------------------------------------------------------------------------------

def test_a_learner_typo_is_one_line_listing_the_learners(tmp_path, capsys):
    code = main(["benchmark", "--suite", "fast", "--learner", "sarsa,sarsaa", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and err.strip() == ("armtransfer benchmark: error: unknown learner 'sarsaa'; valid learners: "
                                         + ", ".join(AT_IMPORT)) and not (tmp_path / "o").exists()


def test_help_lists_the_learners(capsys):
    with pytest.raises(SystemExit):
        main(["benchmark", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--learner NAME[,NAME...]" in text and "Learners: sarsa: SARSA(lambda)" in text


# -- installed plugins: entry points, and bad ones refused in one line with nothing written ----------

def fake_plugin(where: Path, dist: str, module: str, code: str, entry_points: dict[str, str]) -> None:
    """What ``pip install --target where`` leaves of a distribution declaring learners."""
    (where / f"{module}.py").write_text(textwrap.dedent(code))
    info = where / f"{dist.replace('-', '_')}-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 0.1\n")
    lines = "".join(f"{k} = {v}\n" for k, v in entry_points.items())
    (info / "entry_points.txt").write_text(f"[armtransfer.learners]\n{lines}")


def run_cli(cwd: Path, *args: str, path: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(path), str(ROOT / "src"),
                                                        os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-m", "armtransfer", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)


MODEL = """
import numpy as np
import armtransfer

class M:
    def __init__(self, env, seed):
        self.env, self.obs = env, None
    def learn(self, total_timesteps):
        for _ in range(total_timesteps):
            if self.obs is None:
                self.obs, _ = self.env.reset()
            self.obs, _, te, tr, _ = self.env.step(ACT)
            if te or tr:
                self.obs = None
        return self
    def predict(self, observation, deterministic=True):
        return PRED, None
"""


def _learner(act="0", pred="0", make="M(env, seed)", extra="") -> str:
    return (MODEL.replace("ACT", act).replace("PRED", pred) + extra
            + f"\nL = armtransfer.Learner('walker', 'steps action 0', lambda env, seed: {make})\n")


@pytest.mark.parametrize("code, ep, fault", [
    ("import numpyy\n", "walker = badlearn:L", r"plugin bad-learner 0.1 \(entry point walker = badlearn:L in group "
     r"armtransfer.learners\) fails to import: ModuleNotFoundError: No module named 'numpyy'"),
    ("L = 3\n", "walker = badlearn:L", r"plugin bad-learner 0.1 .* is int, not a learner"),
    (_learner(), "other = badlearn:L", r"plugin bad-learner 0.1 .* is a learner named 'walker'; name the entry point"),
    (_learner(make="1 / 0"), "walker = badlearn:L",
     r"learner 'walker' \(plugin bad-learner 0.1 .*\), on robot fine: its make raised ZeroDivisionError"),
    (_learner(act="np.array([0, 1])"), "walker = badlearn:L",
     r"learner 'walker' .*: its model stepped the environment with an action of shape \(2,\)"),
    (_learner(extra="\nM.learn = lambda self, n: {}['x']\n"), "walker = badlearn:L",
     r"learner 'walker' .*: its learn raised KeyError: 'x'"),
    (_learner(pred="float('nan')"), "walker = badlearn:L", r"learner 'walker' .*: its predict returned the action nan"),
    (_learner(pred="np.array([[0]])"), "walker = badlearn:L",
     r"learner 'walker' .*: its predict returned an action of shape \(1, 1\)"),
    (_learner(pred="-1"), "walker = badlearn:L",
     r"learner 'walker' .*: its predict returned the action -1, not in the action space"),
    (_learner(extra="\nM.predict = lambda self, o, deterministic=True: 1 / 0\n"), "walker = badlearn:L",
     r"learner 'walker' .*: its predict raised ZeroDivisionError"),
])
def test_a_bad_installed_learner_is_one_line_and_nothing_is_written(tmp_path, code, ep, fault):
    site = tmp_path / "site"
    site.mkdir()
    fake_plugin(site, "bad-learner", "badlearn", code, dict([ep.split(" = ")]))
    out = tmp_path / "out"
    learner = ep.split(" = ")[0]
    done = run_cli(tmp_path, "benchmark", "--suite", "fast", "--method", "none", "--learner", learner, "--out",
                   str(out), path=site)
    assert done.returncode == 2, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert re.search(fault, done.stderr), done.stderr
    assert done.stderr.startswith("armtransfer benchmark: error: ") and not out.exists()


def test_a_learner_named_as_the_built_in_one_is_left_out_with_a_warning(tmp_path):
    site = tmp_path / "site"
    site.mkdir()
    fake_plugin(site, "bad-learner", "badlearn", _learner().replace("'walker'", "'sarsa'"), {"sarsa": "badlearn:L"})
    done = run_cli(tmp_path, "benchmark", "--learner", "sarsa", "--help", path=site)
    assert done.returncode == 0 and "usage:" in done.stdout
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert re.search(r"^armtransfer: warning: plugin bad-learner 0.1 .* is left out \(is named 'sarsa', as a learner "
                     r"of armtransfer is; rename one of them\); remove it with 'pip uninstall bad-learner'",
                     done.stderr), done.stderr


def test_two_installed_learners_with_one_name_are_left_out(tmp_path):
    """Neither is used (which one is meant?); the help works, with one warning line; naming the
    learner is its one-line error."""
    site = tmp_path / "site"
    site.mkdir()
    fake_plugin(site, "learner-a", "learn_a", _learner(), {"walker": "learn_a:L"})
    fake_plugin(site, "learner-b", "learn_b", _learner(), {"walker": "learn_b:L"})
    said = ("plugin learner-b 0.1 (entry point walker = learn_b:L in group armtransfer.learners) is named "
            "'walker', as a learner of plugin learner-a 0.1")
    done = run_cli(tmp_path, "benchmark", "--help", path=site)
    assert done.returncode == 0 and "usage:" in done.stdout
    assert len(done.stderr.strip().splitlines()) == 1 and "pip uninstall learner-b" in done.stderr
    assert "is left out (is named 'walker', as a learner of plugin learner-a 0.1" in done.stderr
    used = run_cli(tmp_path, "benchmark", "--suite", "fast", "--learner", "walker", "--out", str(tmp_path / "o"),
                   path=site)
    assert used.returncode == 2 and len(used.stderr.strip().splitlines()) == 1 and said in used.stderr
    assert not (tmp_path / "o").exists()


def test_an_installed_learner_is_read_on_first_use_and_listed(tmp_path):
    site = tmp_path / "site"
    site.mkdir()
    fake_plugin(site, "good-learner", "goodlearn", _learner() + "\nprint('imported', flush=True)\n",
                {"walker": "goodlearn:L"})
    code = ("import sys, armtransfer\n"
            "assert 'goodlearn' not in sys.modules\n"
            "print('before')\n"
            "print(list(armtransfer.LEARNERS), armtransfer.LEARNERS['walker'].origin)\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(site), str(ROOT / "src")]))
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        "before", "imported",
        f"{['sarsa', *sorted([*AT_IMPORT[1:], 'walker'])]} plugin good-learner 0.1 (entry point walker = goodlearn:L "
        "in group armtransfer.learners)"]
    helped = run_cli(tmp_path, "benchmark", "--help", path=site)
    assert "walker: steps action 0" in " ".join(helped.stdout.split())


# -- worlds: a case carries its world, and a suite can run on a small one -------------------------

def test_a_case_of_the_default_world_keeps_its_bytes_and_label():
    case = suites.Case("coarse", "fine", 1)
    assert case.world == "rooms" and case.label == "coarse -> fine, task 1"
    assert "world" not in suites.FAST.to_dict()["cases"][0]
    run = benchmark_runs.trial_run("none", 0, "coarse", "fine", [0, 0], [-8, 12], 0.0, 1, LearnerConfig(), None)
    assert "world" not in run.to_dict() and benchmark_runs.robot_key("fine") == benchmark_runs.robot_key("fine", "rooms") == "fine"


def test_a_suite_runs_on_a_small_world_with_its_tasks(registered):
    registered(armtransfer.Learner("oracle", "wise from step 500", lambda env, seed: Oracle(env, seed, 500)))
    small = suites.Section("rooms11", "coarse -> fine task 1 of rooms11", (suites.Case("coarse", "fine", 1,
                                                                                        world="rooms11"),),
                           source_seeds=1, trials=1, max_total_steps=4_000, learners=("oracle",))
    suite = suites.Suite("rooms11", 1, False, small.description, (small,))
    assert small.to_dict()["cases"][0]["world"] == "rooms11" and small.to_dict()["learners"] == ["oracle"]
    robots = benchmark.Robots({})
    plan = benchmark.plan(suite, 0, robots, ran=["none", "pseudo"])
    pair = plan.pairs[0]
    assert (pair.start, pair.goal) == ((0, 0), (-4, 4)) and pair.case.label.endswith(", in rooms11")
    assert pair.source_run().world == "rooms11" and set(robots.resolved) == {"coarse in rooms11", "fine in rooms11"}
    records, _ = benchmark.run_suite(suite, 0, threads=1)
    assert [r["method"] for r in records] == ["none@oracle", "pseudo@oracle", "dense@oracle", "goal-dense@oracle"]
    assert all(r["world"] == "rooms11" and r["optimal"] == pair.optimal for r in records)
    assert records[0]["converged"] == [True] and records[0]["source_failure"] is None
    # the built-in learner's trial of the same case runs on the same world's robot
    source, _ = benchmark_runs.execute(pair.source_run(), robots.resolved)
    sarsa = pair.trial_runs(["none"], source)[0]
    result, _ = benchmark_runs.execute(sarsa, robots.resolved)
    assert sarsa.world == "rooms11" and benchmark_runs.result_problem(sarsa.to_dict(), result) is None
    with pytest.raises(armtransfer.ArmTransferError, match="unknown task '9' in world rooms11"):
        benchmark.plan(suites.Suite("x", 1, False, "x", (dataclasses.replace(
            small, cases=(suites.Case("coarse", "fine", 9, world="rooms11"),)),)), 0)


def test_workers_are_sent_the_robots_of_a_cases_world():
    """A worker looks a robot up by spec and world; the robots a pool sends must be keyed so."""
    from armtransfer.experiments.benchmark_runs import robot_key
    from armtransfer.parallel.executors import _robots_for

    robots = {"coarse": object(), robot_key("coarse", "rooms11"): object(), robot_key("fine", "rooms11"): object(),
              robot_key("fine", "rooms15"): object()}
    runs = [types.SimpleNamespace(source="coarse", target="fine", world="rooms11"),
            types.SimpleNamespace(source="coarse", target="coarse", world=None)]
    assert set(_robots_for(runs, robots)) == {"coarse", "coarse in rooms11", "fine in rooms11"}
    sweep = {"coarse": object(), "fine": object()}  # a sweep's robots, resolved in its one world
    assert set(_robots_for(runs, sweep)) == {"coarse", "fine"}
