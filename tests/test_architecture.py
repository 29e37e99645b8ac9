"""The project's one-way data flow, as the README draws it, checked on the imports.

    errors/io -> models -> worlds -> ik -> tasks -> learning -> experiments -> parallel -> armtransfer (API, wrappers, command)

A module may import its own layer and the layers before it, never a later one; imports
inside functions and those for type hints count too. The import graph has no cycles, learning/ never imports MuJoCo, and only the
``armtransfer`` namespace is installed.
"""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

FOUNDATION = ("armtransfer.errors", "armtransfer.checks", "armtransfer.io", "armtransfer.cpus",
              "armtransfer.registration")
# the layers in the order data flows; the rest of armtransfer (API, wrappers, command) comes last
LAYERS = ["foundation", "armtransfer.models", "armtransfer.worlds", "armtransfer.ik", "armtransfer.tasks",
          "armtransfer.learning", "armtransfer.experiments", "armtransfer.parallel", "armtransfer"]
MUJOCO = ("mujoco", "dm_control", "mink")


def _modules() -> dict[str, Path]:
    """Every module of the package, named by its path: the file path is the module path."""
    out = {}
    for path in sorted((ROOT / "src" / "armtransfer").rglob("*.py")):
        rel = path.relative_to(ROOT / "src").with_suffix("")
        out[".".join(p for p in rel.parts if p != "__init__")] = path
    return out


def _layer(module: str) -> int:
    """0 for the foundation, then models, worlds, ik, tasks, learning, experiments, parallel; the rest
    of armtransfer last."""
    if module in FOUNDATION:
        return 0
    for i, prefix in enumerate(LAYERS[1:-1], start=1):
        if module == prefix or module.startswith(prefix + "."):
            return i
    return len(LAYERS) - 1


def _imports(path: Path, module: str) -> set[str]:
    """Every module that ``path`` imports, wherever in the file: lazy imports and imports for type
    hints (under ``if TYPE_CHECKING:``) included, since a type hint that names a higher layer is a
    dependency on it all the same."""
    tree = ast.parse(path.read_text())
    found: set[str] = set()
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(up + ([base] if base else []))
            found.add(base)
            found.update(f"{base}.{a.name}" for a in node.names)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return found


def _graph() -> dict[str, set[str]]:
    modules = _modules()
    graph = {}
    for name, path in modules.items():
        graph[name] = {m for m in _imports(path, name) if m in modules and m != name}
    return graph


def test_layering_follows_the_readme():
    graph = _graph()
    assert len(graph) > 40
    bad = [f"{a} ({LAYERS[_layer(a)]}) imports {b} ({LAYERS[_layer(b)]})"
           for a, deps in graph.items() for b in deps if _layer(b) > _layer(a)]
    assert bad == []


def test_results_print_without_the_reports():
    """Inside experiments/, the text tables and tidy frames import nothing of the experiments,
    and the result types nothing of reports/ (the top of experiments/: what a person reads)."""
    graph = _graph()
    for name in ("armtransfer.experiments.tables", "armtransfer.experiments.frames"):
        assert name in graph and [m for m in graph[name] if m.startswith("armtransfer.experiments")] == [], name
    for name in ("armtransfer.experiments.results", "armtransfer.experiments.continuous",
                 "armtransfer.experiments.experiment"):
        assert [m for m in graph[name] if m.startswith("armtransfer.experiments.reports")] == [], name


def test_import_graph_has_no_cycles():
    graph = _graph()
    # a package's __init__ importing its own submodules is not a cycle of the design
    edges = {a: {b for b in deps if not a.startswith(b + ".")} for a, deps in graph.items()}
    state: dict[str, int] = {}
    cycles: list[list[str]] = []

    def dfs(node: str, stack: list[str]) -> None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == 1:
                cycles.append(stack[stack.index(nxt):] + [nxt])
            elif nxt not in state:
                dfs(nxt, stack)
        stack.pop()
        state[node] = 2

    for node in sorted(edges):
        if node not in state:
            dfs(node, [])
    assert cycles == []


def test_layer_check_catches_an_upward_import(tmp_path):
    """The checker itself: an ik module that imports learning is reported."""
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from armtransfer.learning import sarsa\n")
    deps = _imports(bad, "armtransfer.ik.bad")
    assert "armtransfer.learning.sarsa" in deps
    assert _layer("armtransfer.learning.sarsa") > _layer("armtransfer.ik.bad")
    typed = tmp_path / "typed.py"
    typed.write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from armtransfer.tasks import robot\n")
    assert "armtransfer.tasks.robot" in _imports(typed, "armtransfer.ik.typed")
    assert _layer("armtransfer.tasks.robot") > _layer("armtransfer.ik.typed")


def test_learning_and_experiments_never_import_mujoco_statically():
    modules = _modules()
    for name, path in modules.items():
        if name.startswith(("armtransfer.learning", "armtransfer.experiments")):
            hits = [m for m in _imports(path, name) if m.split(".")[0] in MUJOCO]
            assert hits == [], f"{name} imports {hits}"


def test_learning_experiments_and_tasks_import_no_mujoco_at_run_time():
    names = [n for n in _modules() if n.startswith(("armtransfer.learning", "armtransfer.experiments", "armtransfer.tasks"))]
    code = (
        "import importlib, sys\n"
        f"for m in {names!r}: importlib.import_module(m)\n"
        f"bad = sorted(m for m in sys.modules if m.split('.')[0] in {MUJOCO!r})\n"
        "print(','.join(bad))\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd="/", timeout=180)
    assert proc.returncode == 0, proc.stderr
    assert len(names) > 25
    assert proc.stdout.strip() == "", f"imported: {proc.stdout.strip()}"


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """A regular (non-editable) wheel, built from a clean copy of the sources."""
    src = tmp_path_factory.mktemp("src") / "armtransfer"
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(
        ".git", ".ci", "venv", ".venv", "runs", "build", "*.egg-info", "__pycache__", ".pytest_cache"))
    out = tmp_path_factory.mktemp("wheel")
    proc = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(src)],
        capture_output=True, text=True, timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    (whl,) = out.glob("armtransfer-*.whl")
    return whl


@pytest.mark.slow  # builds a wheel from a copy of the tree: 10 s of pip
def test_wheel_installs_only_the_armtransfer_namespace(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    top = {n.split("/")[0] for n in names}
    assert {t for t in top if not t.endswith(".dist-info")} == {"armtransfer"}
    for module in ("learning/sarsa.py", "ik/compile.py", "worlds/layout.py", "models/planar2/planar2.xml",
                   "commands/rooms.py"):
        assert "armtransfer/" + module in names
