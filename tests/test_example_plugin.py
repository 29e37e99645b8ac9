"""The example plugin (``examples/plugin``), installed beside armtransfer as a user installs a
package, without touching this environment: ``pip install --target`` into a temporary folder
put on PYTHONPATH, where importlib.metadata finds its dist-info and so its entry point. Its
method, ``breadcrumbs``, is then a method of every command, with ``none`` as its baseline; its
learner, ``tabular-q``, a learner of the benchmark."""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PLUGIN = ROOT / "examples" / "plugin"
NAME = "breadcrumbs"
LEARNER = "tabular-q"


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The plugin installed into a folder of its own (built from a copy: no build files are left
    in the repository)."""
    tmp = tmp_path_factory.mktemp("plugin")
    shutil.copytree(PLUGIN, tmp / "src", ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    target = tmp / "site"
    # built with this environment's setuptools (no download); a Python whose venvs come without
    # setuptools (3.12+) builds it in pip's isolated environment instead
    isolation = [] if importlib.util.find_spec("setuptools") is None else ["--no-build-isolation"]
    done = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", *isolation,
                           "--target", str(target), str(tmp / "src")], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert list(target.glob("armtransfer_example_plugin-*.dist-info"))
    return target


def run(site: Path, cwd: Path, *argv: str, timeout: float = 600) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(site), str(ROOT / "src")]), MUJOCO_GL="egl")
    done = subprocess.run(list(argv), cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, f"{argv}\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}"
    return done


def cli(site: Path, cwd: Path, *args: str) -> subprocess.CompletedProcess:
    return run(site, cwd, sys.executable, "-m", "armtransfer", *args)


def test_the_installed_plugin_is_in_methods_and_in_the_help(site, tmp_path):
    code = ("import armtransfer\n"
            f"m = armtransfer.METHODS[{NAME!r}]\n"
            "print(list(armtransfer.METHODS)[-1], m.baselines, m.origin)\n")
    out = run(site, tmp_path, sys.executable, "-c", code).stdout
    assert out.startswith(f"{NAME} ('none',) plugin armtransfer-example-plugin 0.1.0 (entry point {NAME} = "
                          "armtransfer_example_plugin.method:BREADCRUMBS")
    help_text = " ".join(cli(site, tmp_path, "rooms", "--help").stdout.split())
    assert f"{NAME}: example plugin: phi = the index of the nearest trajectory cell" in help_text


def test_rooms_runs_it_beside_none(site, tmp_path):
    cli(site, tmp_path, "rooms", "--method", NAME, "--trials", "2", "--trajectory", "optimal",
        "--max-episodes", "30", "--json", "r.json")
    data = json.loads((tmp_path / "r.json").read_text())
    text = json.dumps(data)
    assert f'"{NAME}"' in text and '"none"' in text


@pytest.mark.slow  # compiles or loads two arms, then learns: 10-60 s
def test_arms_runs_it(site, tmp_path):
    done = cli(site, tmp_path, "arms", "--fast", "--no-video", "--method", NAME, "--out", "arms")
    assert f"| {NAME} " in done.stdout and "| none " in done.stdout


@pytest.mark.slow  # worker processes find the plugin by its entry point, as the driver does
def test_sweep_and_matrix_run_it_in_worker_processes(site, tmp_path):
    (tmp_path / "s.toml").write_text(f'[sweep]\nname = "plugin"\ntasks = [1]\npairs = [["coarse", "fine"]]\n'
                                     f'methods = ["none", "{NAME}"]\nseeds = [0]\ntrials = 2\n')
    done = cli(site, tmp_path, "sweep", "s.toml", "--out", "sweep", "--workers", "2")
    assert "2/2 runs in sweep; 0 failed" in done.stdout
    done = cli(site, tmp_path, "matrix", "--robots", "coarse,fine", "--tasks", "1", "--methods", "none", NAME,
               "--trials", "2", "--out", "matrix", "--workers", "2")
    assert f"| {NAME} " in done.stdout


@pytest.mark.slow  # the fast suite, the plugin's method and its baseline: 10-30 s
def test_benchmark_runs_it_against_none(site, tmp_path):
    cli(site, tmp_path, "benchmark", "--suite", "fast", "--method", NAME, "--out", "bench")
    results = json.loads((tmp_path / "bench" / "results.json").read_text())
    # beside its baseline, the goal-only one of a reward term: dense's potential from the goal alone
    assert results["methods"] == ["none", "goal-dense", NAME] and results["baselines"][NAME] == ["none", "goal-dense"]
    assert {r["method"] for r in results["records"]} == {"none", "goal-dense", NAME}
    assert f"`{NAME}`" in (tmp_path / "bench" / "report.md").read_text()


@pytest.mark.slow  # starts a local Ray instance: 10-30 s
def test_ray_workers_find_it_by_its_entry_point(site, tmp_path):
    pytest.importorskip("ray", reason="Ray is the cluster extra: pip install -e '.[cluster]'")
    (tmp_path / "s.toml").write_text(f'[sweep]\nname = "plugin"\ntasks = [1]\npairs = [["coarse", "fine"]]\n'
                                     f'methods = ["none", "{NAME}"]\nseeds = [0]\ntrials = 2\n')
    done = cli(site, tmp_path, "sweep", "s.toml", "--out", "sweep", "--executor", "ray", "--workers", "2")
    assert "2/2 runs in sweep; 0 failed" in done.stdout


def test_the_installed_learner_is_in_learners_and_in_the_help(site, tmp_path):
    code = ("import armtransfer\n"
            f"lr = armtransfer.LEARNERS[{LEARNER!r}]\n"
            "print(list(armtransfer.LEARNERS), lr.origin)\n")
    out = run(site, tmp_path, sys.executable, "-c", code).stdout
    from importlib.metadata import entry_points

    own = [e.name for e in entry_points(group="armtransfer.learners")]  # armtransfer's own dqn and ppo
    assert out.startswith(f"{['sarsa', *sorted({*own, LEARNER})]} plugin armtransfer-example-plugin 0.1.0 (entry point {LEARNER} = "
                          "armtransfer_example_plugin.learner:TABULAR_Q in group armtransfer.learners)")
    help_text = " ".join(cli(site, tmp_path, "benchmark", "--help").stdout.split())
    assert f"{LEARNER}: example plugin:" in help_text


@pytest.mark.slow  # the fast suite: two learners, the plugin's method and its baseline: 1-4 min
def test_benchmark_runs_its_method_and_its_learner(site, tmp_path):
    cli(site, tmp_path, "benchmark", "--suite", "fast", "--method", NAME, "--learner", f"sarsa,{LEARNER}",
        "--out", "bench", "--workers", "2")
    results = json.loads((tmp_path / "bench" / "results.json").read_text())
    labels = [f"none@{LEARNER}", f"goal-dense@{LEARNER}", f"{NAME}@{LEARNER}"]
    assert results["methods"] == ["none", "goal-dense", NAME, *labels]
    assert results["baselines"][labels[2]] == labels[:2]
    mine = [r for r in results["records"] if r.get("learner") == LEARNER]
    assert {r["method"] for r in mine} == set(labels) and len(mine) == 3 * 2  # 2 source seeds
    assert all(r["error"] is None and len(r["first_exposure"]) == 2 for r in mine)
    assert all(n is None or 0 < n <= r["cap"] for r in mine for n in r["convergence_steps"])
    report = (tmp_path / "bench" / "report.md").read_text()
    assert f"`{labels[1]}` against `{labels[0]}`" in report and "outside learner tabular-q" in report
    done = cli(site, tmp_path, "benchmark", "--suite", "fast", "--method", NAME, "--learner", f"sarsa,{LEARNER}",
               "--out", "bench")  # every run is in: resumes to nothing
    assert "0 to run" in done.stdout


@pytest.mark.slow  # pip-installs the plugin (module fixture), then learns on rooms11: 10-60 s
def test_rooms_and_arms_run_the_installed_learner_and_list_it(site, tmp_path):
    for command in ("rooms", "arms"):
        help_text = " ".join(cli(site, tmp_path, command, "--help").stdout.split())
        assert f"{LEARNER}: example plugin: one-step Q-learning" in help_text
    small = ["--world", "rooms11", "--learner", LEARNER, "--method", "none", "pseudo", "--trials", "2",
             "--max-total-steps", "4000", "--trajectory", "optimal"]
    done = cli(site, tmp_path, "rooms", *small, "--json", "r.json")
    assert f"learner {LEARNER}" in done.stdout and "| pseudo | none " in done.stdout
    data = json.loads((tmp_path / "r.json").read_text())
    assert data["learner"] == LEARNER and list(data["results"]) == ["none", "pseudo"]
    cli(site, tmp_path, "arms", "--source", "coarse", "--target", "fine", *small, "--no-video", "--out", "arms")
    assert json.loads((tmp_path / "arms" / "results.json").read_text())["learner"] == LEARNER
