"""Methods from outside the package: a potential or a state bonus written in numpy over cells,
registered in a notebook (``armtransfer.register_method``) or declared by an installed package
under the entry-point group ``armtransfer.methods``, is a method everywhere, and a bad one is
refused in one line before anything is written.

The installed example plugin (``examples/plugin``) is in ``test_example_plugin.py``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import armtransfer
from armtransfer.errors import InvalidParameterError, PluginError
from armtransfer.experiments import experiment
from armtransfer.experiments import sweep as sweeps
from armtransfer.learning import cells as cell_methods
from armtransfer.learning import farming, methods, potentials, sarsa
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.wrappers import TransferReward

ROOT = Path(__file__).resolve().parents[1]
CFG = LearnerConfig()


def index_potential(cells: np.ndarray, trajectory: np.ndarray) -> np.ndarray:
    """The built-in ``potential``'s phi per unit K, written as a plugin would: the largest index
    i >= 1 of the trajectory cell a state is on (the goal, last, left out), 0 elsewhere."""
    phi = np.zeros(len(cells))
    for i, point in enumerate(trajectory[:-1]):
        if i >= 1:
            phi[(cells == point).all(axis=1)] = i
    return phi


@pytest.fixture
def registered():
    """Register methods for one test; they are gone after it."""
    names: list[str] = []

    def register(method, **kw):
        m = armtransfer.register_method(method, **kw)
        names.append(m.name)
        return m

    yield register
    for name in names:
        if name in methods.METHODS:
            del methods.METHODS[name]


@pytest.fixture(scope="module")
def task1():
    fine, coarse = grid_robot("fine"), grid_robot("coarse")
    start, goal = table_task(1).cells()
    return fine, coarse, start, goal, trajectories.shortest(coarse, start, goal)


def test_a_registered_potential_is_a_method_everywhere(registered):
    m = registered(armtransfer.potential_method("my-index", "the index as a plugin's potential", index_potential))
    assert m.origin == "registered at run time" and m.baselines == ("none",)
    assert "my-index" in armtransfer.METHODS and list(armtransfer.METHODS)[-1] == "my-index"
    for names in (methods.SHAPED, methods.REWARD_ONLY, experiment.METHODS, experiment.SHAPING_METHODS,
                  sweeps.METHODS, cell_methods.CELL_METHODS):
        assert "my-index" in names
    assert methods.with_baselines(["my-index"]) == ["none", "my-index"]
    r = armtransfer.transfer(methods=["my-index"], trials=2, seed=0, max_episodes=30, trajectory="optimal")
    assert list(r.methods) == ["none", "my-index"]  # its baseline joins it
    assert set(r.controls) == {"shuffled", "random"} and "my-index" in r.controls["shuffled"]
    # the command line's listing is made from the registry
    from armtransfer.cli import build_parser

    assert "my-index: the index as a plugin's potential" in " ".join(_subparser_help(build_parser(), "rooms").split())
    # a typo lists the valid names, the plugin's among them
    with pytest.raises(InvalidParameterError, match=r"unknown method 'my-indx'; valid methods: .*my-index"):
        armtransfer.transfer(methods=["my-indx"])


def _subparser_help(parser, name: str) -> str:
    import argparse

    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[name].format_help()


def test_a_plugin_potential_runs_in_the_kernel_bit_for_bit_as_the_built_in_one(registered, task1):
    """The built-in ``potential`` (phi = i*K) and the same phi written as a plugin give the same
    shaping arrays and the same trials, step for step: a plugin's potential is the kernel's
    potential mode, nothing slower or different."""
    fine, _, start, goal, traj = task1
    registered(armtransfer.potential_method("my-index", "the index", index_potential, auto_k=3.0))
    built_in = methods.build_shaping("potential", fine, [traj], "auto", CFG.step_reward, gamma=CFG.gamma)
    plugin = methods.build_shaping("my-index", fine, [traj], "auto", CFG.step_reward, gamma=CFG.gamma)
    assert plugin.mode == built_in.mode and plugin.K == built_in.K == 3.0
    assert np.array_equal(plugin.phi, built_in.phi)
    config = LearnerConfig(max_episodes=40)
    s0 = fine.start_state(start)
    a = sarsa.learn(fine, s0, goal, config, np.random.default_rng(3), shaping=built_in)
    b = sarsa.learn(fine, s0, goal, config, np.random.default_rng(3), shaping=plugin)
    assert np.array_equal(a.episode_steps, b.episode_steps) and a.greedy_path == b.greedy_path


def test_a_plugin_potential_is_bounded_like_the_built_in_ones(registered, task1):
    """A potential far below zero would pay a learner for bumping a wall (gamma * phi - phi > 0);
    it is bounded (``potentials.bounded``) and then passes the self-loop check."""
    fine, _, start, goal, traj = task1
    registered(armtransfer.potential_method("deep", "minus a thousand everywhere",
                                            lambda cells, t: np.full(len(cells), -1000.0)))
    sh = methods.build_shaping("deep", fine, [traj], "auto", CFG.step_reward, gamma=CFG.gamma)
    assert np.array_equal(sh.phi, potentials.bounded(np.full(fine.n_states, -1000.0), CFG.gamma, CFG.step_reward))
    farming.check_self_loops("deep", fine, goal, sh, CFG, wind=0.2)


def test_the_plugin_is_handed_cells_and_the_trajectory_as_documented(registered, task1):
    fine, _, start, goal, traj = task1
    seen = {}

    def spy(cells, trajectory):
        seen["cells"], seen["trajectory"] = cells.copy(), trajectory.copy()
        cells[:] = 0  # writing into what it is handed changes nothing of the robot's
        return np.zeros(len(cells))

    registered(armtransfer.potential_method("spy", "records its arguments", spy))
    methods.build_shaping("spy", fine, [traj], "auto", CFG.step_reward)
    assert seen["cells"].shape == (fine.n_states, 2) and seen["cells"].dtype.kind == "i"
    assert np.array_equal(seen["cells"], fine.layout.xy_of(fine.label))
    assert seen["trajectory"].tolist() == [list(fine.layout.xy(c)) for c in (*traj.cells, traj.goal)]
    assert fine.layout.xy_of(fine.label).any()


def test_transfer_reward_takes_a_plugin_method(registered, task1):
    _, _, _, _, traj = task1
    registered(armtransfer.potential_method("my-index", "the index", index_potential, auto_k=3.0))
    plugin = TransferReward(gym.make("armtransfer/Rooms-v0", task=1, robot="fine"), traj, method="my-index")
    built_in = TransferReward(gym.make("armtransfer/Rooms-v0", task=1, robot="fine"), traj, method="potential")
    terms = []
    for env in (plugin, built_in):
        env.reset(seed=0)
        terms.append([env.step(a)[4]["shaping"] for a in [0, 0, 0, 3, 3, 2, 1]])
    assert terms[0] == terms[1] and any(terms[0])


def pseudo_index(cells: np.ndarray, trajectory: np.ndarray) -> np.ndarray:
    """The paper's pseudo reward per unit K as a plugin's bonus (== ``index_potential``)."""
    return index_potential(cells, trajectory)


def test_a_state_bonus_gets_the_pseudo_rewards_farming_checks(registered, task1):
    """A plugin's state bonus equal to the paper's i is checked exactly as ``pseudo`` is: the same
    automatic K, verified by value iteration; a K that can be farmed is refused; and its trials
    are ``pseudo``'s, step for step."""
    fine, _, start, goal, traj = task1
    registered(armtransfer.bonus_method("my-pseudo", "the paper's i as a plugin's bonus", pseudo_index))
    s0 = fine.start_state(start)
    k_plugin = farming.check_k("my-pseudo", fine, s0, goal, [traj], "auto", CFG)
    k_pseudo = farming.check_k("pseudo", fine, s0, goal, [traj], "auto", CFG)
    assert k_plugin == k_pseudo > 0
    n = traj.n
    with pytest.raises(InvalidParameterError, match="can be farmed"):
        farming.check_k("my-pseudo", fine, s0, goal, [traj], 1.0 / n, CFG)  # step + n*K = 0
    with pytest.raises(InvalidParameterError, match="can be farmed"):
        methods.build_shaping("my-pseudo", fine, [traj], 1.0 / n, CFG.step_reward)
    a = experiment.run_method("pseudo", fine, start, goal, [traj], 2, 0, LearnerConfig(max_episodes=30))
    b = experiment.run_method("my-pseudo", fine, start, goal, [traj], 2, 0, LearnerConfig(max_episodes=30))
    assert a.column("exploration_steps") == b.column("exploration_steps")
    assert a.extra["K"] == b.extra["K"]


def test_a_state_bonus_that_pays_for_standing_still_is_refused(registered, task1):
    fine, _, start, goal, traj = task1
    registered(armtransfer.bonus_method("everywhere", "pays on every cell", lambda c, t: np.ones(len(c))))
    with pytest.raises(InvalidParameterError, match="farmed|leaves its state unchanged"):
        experiment.run_method("everywhere", fine, start, goal, [traj], 1, 0, CFG, K=1.0)
    with pytest.raises(PluginError, match="must be >= 0"):
        registered(armtransfer.bonus_method("negative", "a negative bonus", lambda c, t: -np.ones(len(c))))


@pytest.mark.parametrize("fn, fault", [
    (lambda c, t: 1 / 0, r"its potential raised ZeroDivisionError: division by zero"),
    (lambda c, t: np.zeros(len(c) - 1), r"returned shape \(2600,\) for 2601 states"),
    (lambda c, t: np.full(len(c), np.nan), r"returned nan for 2601 of 2601 states"),
    (lambda c, t: "high", r"returned str, not 2601 numbers"),
])
def test_a_bad_potential_is_refused_in_one_line_when_registered(registered, fn, fault):
    with pytest.raises(PluginError, match=fault) as err:
        registered(armtransfer.potential_method("bad", "a bad potential", fn))
    assert "method 'bad' (registered at run time)" in str(err.value) and "\n" not in str(err.value)
    assert "bad" not in armtransfer.METHODS


def test_a_fault_that_shows_only_on_a_robot_is_refused_before_any_trial(registered, task1):
    fine, _, start, goal, traj = task1

    def only_small(cells, trajectory):
        if len(cells) > 3000:
            raise ValueError("too many cells")
        return np.zeros(len(cells))

    registered(armtransfer.potential_method("small-only", "fails on large robots", only_small))
    arm_like = grid_robot("fine")
    big = type(arm_like)(name="big", next_state=np.tile(arm_like.next_state, (2, 1)),
                         wind_state=np.tile(arm_like.wind_state, 2), label=np.tile(arm_like.label, 2),
                         action_names=arm_like.action_names, layout=arm_like.layout)
    with pytest.raises(PluginError, match="method 'small-only': its potential raised ValueError: too many cells"):
        methods.build_shaping("small-only", big, [traj], "auto", CFG.step_reward)


def test_names_are_checked(registered):
    with pytest.raises(PluginError, match="the name is taken by a method of armtransfer"):
        registered(armtransfer.potential_method("pseudo", "a second pseudo", index_potential))
    registered(armtransfer.potential_method("mine", "one", index_potential))
    with pytest.raises(PluginError, match="pass replace=True"):
        registered(armtransfer.potential_method("mine", "two", index_potential))
    registered(armtransfer.potential_method("mine", "two", index_potential), replace=True)
    assert armtransfer.METHODS["mine"].description == "two"
    for bad in ("", "Has Caps", "a b", "x" * 65, 3):
        with pytest.raises(PluginError, match="a method's name is"):
            armtransfer.potential_method(bad, "d", index_potential)  # type: ignore[arg-type]
    with pytest.raises(PluginError, match="description must be one line"):
        armtransfer.potential_method("ok", "two\nlines", index_potential)
    with pytest.raises(PluginError, match="must be a function"):
        armtransfer.potential_method("ok", "d", 3)  # type: ignore[arg-type]
    with pytest.raises(PluginError, match="register_method takes a method"):
        armtransfer.register_method(index_potential)  # type: ignore[arg-type]


def test_the_benchmark_runs_every_plugin_method_beside_the_suites(registered):
    from armtransfer.experiments import benchmark, suites

    registered(armtransfer.potential_method("mine", "one", index_potential))
    ran, missing = benchmark.methods_to_run()
    assert ran[-1] == "mine" and set(suites.METHODS) <= set(ran) and missing == []
    assert benchmark.methods_to_run(("mine",)) == (["none", "goal-dense", "mine"], [])  # with its goal-only baseline


def test_benchmark_method_option_lists_the_valid_names_on_a_typo(tmp_path, capsys):
    from armtransfer.cli import main

    assert main(["benchmark", "--suite", "fast", "--method", "pseudoo", "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("armtransfer benchmark: error: unknown method 'pseudoo'; valid methods: none, pseudo")
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "b").exists()


def test_a_sweep_tries_a_plugin_on_each_target_robot_before_it_writes(monkeypatch, tmp_path, task1):
    """A fault that shows only on one robot (here: any robot with more states than the rooms has
    cells) stops a sweep in one line naming the plugin and the robot, before its store exists.
    The plugin is made to look installed (its origin), as the worker processes need."""
    from dataclasses import replace as with_

    from armtransfer.commands.sweep import check_runs

    def only_cells(cells, trajectory):
        if len(cells) != 2601:
            raise ValueError(f"{len(cells)} states")
        return np.zeros(len(cells))

    m = armtransfer.potential_method("cells-only", "works on the rooms' cells only", only_cells)
    monkeypatch.setitem(methods.METHODS, "cells-only", with_(m, origin="plugin cells 0.1"))
    runs = list(sweeps.expand(sweeps.normalise({"sweep": {"tasks": [1], "methods": ["none", "cells-only"],
                                                          "pairs": [["coarse", "fine"]]}})))
    with pytest.raises(PluginError, match=r"^plugin cells 0.1, on robot fine: method 'cells-only': its potential "
                                          r"raised ValueError: \d+ states$"):
        check_runs(runs)


def test_the_benchmark_stops_on_a_plugin_fault_in_one_line_and_writes_nothing(registered, tmp_path, capsys):
    """A method that refuses a case is recorded as failing it; a plugin that raises is a bug, and
    the benchmark stops at it (its report is written only when complete)."""
    from armtransfer.cli import main

    def cells_only(cells, trajectory):
        if len(cells) != 2601:
            raise ValueError(f"{len(cells)} states")
        return np.zeros(len(cells))

    registered(armtransfer.potential_method("cells-only", "works on the rooms' cells only", cells_only))
    out = tmp_path / "bench"
    assert main(["benchmark", "--suite", "fast", "--method", "cells-only", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("armtransfer benchmark: error: ")
    assert "method 'cells-only': its potential raised ValueError" in err
    assert len(err.strip().splitlines()) == 1 and not out.exists() and list(tmp_path.iterdir()) == []


def test_worker_processes_refuse_a_run_time_method_in_one_line(registered):
    from armtransfer.commands.sweep import check_runs

    registered(armtransfer.potential_method("mine", "one", index_potential))
    runs = list(sweeps.expand(sweeps.normalise({"sweep": {"tasks": [1], "methods": ["none", "mine"]}})))
    with pytest.raises(PluginError, match=r"method 'mine' was registered in this process .* entry-point group "
                                          r"armtransfer.methods"):
        check_runs(runs)


# --- entry points: packages on the path, made by hand (a dist-info folder is what pip writes) ---

def fake_plugin(where: Path, dist: str, module: str, code: str, entry_points: dict[str, str]) -> None:
    """A distribution ``dist`` on ``where`` with the module ``module`` and methods declared under
    ``armtransfer.methods``: what ``pip install --target where`` would leave."""
    (where / f"{module}.py").write_text(textwrap.dedent(code))
    info = where / f"{dist.replace('-', '_')}-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 0.1\n")
    lines = "".join(f"{k} = {v}\n" for k, v in entry_points.items())
    (info / "entry_points.txt").write_text(f"[armtransfer.methods]\n{lines}")


def run_cli(tmp_path: Path, *args: str, path: Path, env: dict | None = None,
            timeout: float = 300) -> subprocess.CompletedProcess:
    env = dict(os.environ, **(env or {}), PYTHONPATH=os.pathsep.join([str(path), str(ROOT / "src"),
                                                                       os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-m", "armtransfer", *args], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=timeout)


GOOD = """
import numpy as np
import armtransfer

ROUTE = armtransfer.potential_method("route", "minus the distance to the nearest trajectory cell",
                                     lambda cells, t: -np.min(np.abs(cells[:, None] - t[None]).sum(-1), axis=1))
"""


@pytest.mark.parametrize("code, ep, fault, at_import", [
    ("import numpyy\n", "bad = badplug:M",
     r"plugin bad-plugin 0.1 \(entry point bad = badplug:M in group armtransfer.methods\) fails to import: "
     r"ModuleNotFoundError: No module named 'numpyy'", "left out (fails to import: ModuleNotFoundError: No module "
     "named 'numpyy')"),
    ("import armtransfer\nM = armtransfer.potential_method('bad', 'raises', lambda c, t: c[10**9])\n",
     "bad = badplug:M", r"plugin bad-plugin 0.1 .*: method 'bad': its potential raised IndexError", ""),
    pytest.param("import armtransfer, numpy as np\nM = armtransfer.potential_method('bad', 'short', lambda c, t: np.ones(3))\n",
                 "bad = badplug:M", r"plugin bad-plugin 0.1 .*: method 'bad': its potential returned shape \(3,\)", "",
                 marks=pytest.mark.slow),  # 3-4 s each; two others run by default
    pytest.param("import armtransfer, numpy as np\n"
                 "M = armtransfer.potential_method('bad', 'nan', lambda c, t: np.where(c[:, 0] > 0, np.nan, 0.0))\n",
                 "bad = badplug:M", r"plugin bad-plugin 0.1 .*: method 'bad': its potential returned nan", "",
                 marks=pytest.mark.slow),
    pytest.param("M = 3\n", "bad = badplug:M", r"plugin bad-plugin 0.1 .* is int, not a method",
                 "left out (is int, not a method;", marks=pytest.mark.slow),
])
def test_a_bad_installed_plugin_breaks_only_itself(tmp_path, code, ep, fault, at_import):
    """A command that does not use the plugin runs, with one warning line naming it and how to
    remove it when it cannot even be imported (no line when only its code is faulty: none of its
    code runs); using it is one line, exit 2, nothing written."""
    import re

    site = tmp_path / "site"
    site.mkdir()
    fake_plugin(site, "bad-plugin", "badplug", code, dict([ep.split(" = ")]))
    out = tmp_path / "out"
    done = run_cli(tmp_path, "rooms", "--method", "none", "--trials", "1", "--max-episodes", "5", "--no-controls",
                   "--json", str(out / "r.json"), path=site)
    assert done.returncode == 0, done.stderr
    lines = done.stderr.strip().splitlines()
    if at_import:
        assert len(lines) == 1 and lines[0].startswith("armtransfer: warning: plugin bad-plugin 0.1"), done.stderr
        assert at_import in lines[0], lines[0]
        assert "remove it with 'pip uninstall bad-plugin'" in lines[0] and "ARMTRANSFER_NO_PLUGINS=1" in lines[0]
        top = run_cli(tmp_path, "--help", path=site)  # the top-level help too: printed, with the one warning
        assert top.returncode == 0 and "commands:" in top.stdout and top.stderr.strip().splitlines() == lines
    else:
        assert lines == [], done.stderr
    assert (out / "r.json").exists()
    out2 = tmp_path / "out2"
    used = run_cli(tmp_path, "rooms", "--method", "bad", "--trials", "1", "--json", str(out2 / "r.json"), path=site)
    assert used.returncode == 2, used.stderr
    assert len(used.stderr.strip().splitlines()) == 1, used.stderr
    assert re.search(fault, used.stderr), used.stderr
    assert used.stderr.startswith("armtransfer rooms: error: ") and not out2.exists()
    skipped = run_cli(tmp_path, "rooms", "--help", path=site, env={"ARMTRANSFER_NO_PLUGINS": "1"})
    assert skipped.returncode == 0 and skipped.stderr == "" and "--probe-timeout" in skipped.stdout


def test_two_plugins_with_one_name_are_left_out(tmp_path):
    site = tmp_path / "site"
    site.mkdir()
    fake_plugin(site, "plugin-a", "plug_a", GOOD, {"route": "plug_a:ROUTE"})
    fake_plugin(site, "plugin-b", "plug_b", GOOD, {"route": "plug_b:ROUTE"})
    done = run_cli(tmp_path, "rooms", "--help", path=site)  # the help is printed, with one warning line
    assert done.returncode == 0 and "usage:" in done.stdout, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and done.stderr.startswith("armtransfer: warning: plugin plugin-b")
    used = run_cli(tmp_path, "rooms", "--method", "route", path=site)
    assert used.returncode == 2 and len(used.stderr.strip().splitlines()) == 1, used.stderr
    assert "plugin plugin-b 0.1 (entry point route = plug_b:ROUTE in group armtransfer.methods) is named " \
           "'route', as a method of plugin plugin-a 0.1" in used.stderr


def test_an_installed_plugin_is_read_on_first_use_not_at_import(tmp_path):
    site = tmp_path / "site"
    site.mkdir()
    fake_plugin(site, "good-plugin", "goodplug", GOOD + "\nprint('imported', flush=True)\n",
                {"route": "goodplug:ROUTE"})
    code = ("import sys, armtransfer\n"
            "assert 'goodplug' not in sys.modules and 'armtransfer.learning.plugins' not in sys.modules\n"
            "print('before')\n"
            "print(list(armtransfer.METHODS)[-1], armtransfer.METHODS['route'].origin)\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(site), str(ROOT / "src")]))
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        "before", "imported",
        "route plugin good-plugin 0.1 (entry point route = goodplug:ROUTE in group armtransfer.methods)"]
    ran = run_cli(tmp_path, "rooms", "--method", "route", "--trials", "1", "--no-controls", "--max-episodes", "20",
                  "--trajectory", "optimal", path=site)
    assert ran.returncode == 0, ran.stderr
    assert "| route " in ran.stdout and "| none " in ran.stdout  # with its baseline
