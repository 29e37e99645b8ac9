"""Tools outside the repository follow an editable install: after ``pip install -e`` in a fresh
virtual environment, mypy (and pyright, where it is installed) run from another directory, on a
contributor's own file that imports ``armtransfer.learning.sarsa`` and
``armtransfer.experiments``, find every module of the package, in the tree that was installed.
Setuptools' editable install of the old flat layout was an import hook that type checkers and
editors cannot follow: mypy said "Cannot find implementation or library stub for module named
'armtransfer'" (and with ``--ignore-missing-imports``, nothing, having typed it all ``Any``)."""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import subprocess
import sys
import venv
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

USER_CODE = '''\
import armtransfer.experiments
from armtransfer.experiments import experiment
from armtransfer.learning import sarsa
from armtransfer.learning.config import LearnerConfig

config = LearnerConfig(max_episodes=5)
result: sarsa.TrialResult | None = None
runs: list[experiment.MethodResult] = []
wrong: int = config  # the one error expected: only a resolved LearnerConfig makes it
'''
WRONG_LINE = 9


@dataclass(frozen=True)
class Install:
    python: Path
    """The fresh environment's interpreter."""
    package: Path
    """``src/armtransfer`` of the installed copy of the tree."""
    work: Path
    """Another directory (no pyproject.toml, no tool config) holding the user's ``mine.py``."""
    env: dict[str, str]


def _environment() -> dict[str, str]:
    """This process's environment without what would lead a tool to the tree by another way
    than the install (PYTHONPATH, MYPYPATH, the active venv)."""
    return {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "MYPYPATH", "VIRTUAL_ENV")}


@pytest.fixture(scope="module")
def install(tmp_path_factory) -> Install:
    """A fresh venv with ``pip install --no-deps -e`` of a copy of the tree (the copy, so that a
    module read from anywhere else shows)."""
    base = tmp_path_factory.mktemp("editable")
    tree = base / "checkout"
    tree.mkdir()
    shutil.copy(ROOT / "pyproject.toml", tree)
    shutil.copy(ROOT / "README.md", tree)
    shutil.copytree(ROOT / "src", tree / "src", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    venv.EnvBuilder(with_pip=True).create(base / "venv")
    python = base / "venv" / "bin" / "python"
    env = _environment()
    done = subprocess.run([str(python), "-m", "pip", "install", "-q", "--no-deps", "-e", str(tree)],
                          capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    work = base / "elsewhere"
    work.mkdir()
    (work / "mine.py").write_text(USER_CODE)
    return Install(python, tree / "src" / "armtransfer", work, env)


def _modules_of(package: Path) -> set[str]:
    return {".".join(p.relative_to(package.parent).with_suffix("").parts).removesuffix(".__init__")
            for p in package.rglob("*.py")}


REACHED = {"armtransfer.learning.sarsa", "armtransfer.experiments", "armtransfer.experiments.experiment",
           "armtransfer.learning.config", "armtransfer.tasks.robot"}
"""Modules the user's file reaches, directly or through the package's own imports."""


@pytest.mark.slow  # a venv, an editable install (pip builds it) and a cold mypy run: about 20 s
def test_mypy_from_another_directory_follows_an_editable_install(install):
    check = subprocess.run(
        [sys.executable, "-m", "mypy", "--python-executable", str(install.python), "--ignore-missing-imports",
         "--no-incremental", "--cache-dir", os.devnull, "--verbose", "mine.py"],
        cwd=install.work, capture_output=True, text=True, env=install.env, timeout=600,
    )
    out = check.stdout
    assert "Can't find package" not in out + check.stderr and "import-not-found" not in out, out
    errors = [line for line in out.splitlines() if ": error:" in line]
    assert len(errors) == 1 and errors[0].startswith(f"mine.py:{WRONG_LINE}:"), out
    assert 'expression has type "LearnerConfig", variable has type "int"' in errors[0]

    parsed = {module: Path(path) for path, module in re.findall(r"Parsing (\S+) \((armtransfer[\w.]*)\)",
                                                                 check.stderr)}
    assert REACHED <= set(parsed), sorted(parsed)
    elsewhere = {m: p for m, p in parsed.items() if not p.resolve().is_relative_to(install.package.resolve())}
    assert elsewhere == {}, f"read from outside the installed tree: {elsewhere}"
    assert set(parsed) <= _modules_of(install.package)


@pytest.mark.slow
def test_pyright_from_another_directory_follows_an_editable_install(install):
    if importlib.util.find_spec("pyright") is None:
        pytest.skip("pyright is not installed here (pip install pyright)")
    check = subprocess.run([sys.executable, "-m", "pyright", "--pythonpath", str(install.python), "--verbose",
                            "mine.py"], cwd=install.work, capture_output=True, text=True, env=install.env, timeout=600)
    log = check.stdout + check.stderr
    assert not re.search(r"Could not (import|resolve) '?armtransfer", log), log
    errors = re.findall(r"mine\.py:(\d+):\d+ - error: (.*)", log)
    assert len(errors) == 1 and int(errors[0][0]) == WRONG_LINE, log
    assert '"LearnerConfig" is not assignable to declared type "int"' in errors[0][1]
    assert check.returncode == 1  # errors found, and no other failure
    assert str(install.package.parent) in log.split("Search paths:", 1)[1], log  # the installed tree's src/
