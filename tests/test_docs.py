"""The documentation runs: every ```bash block of README.md and docs/*.md, and every ```python
block of the pages whose snippets stand alone (PYTHON_PAGES), is executed, and every file,
link and module it names exists.

A block runs in a fresh temporary directory that links the repository's script folders, so
relative paths (`scripts/...`, `examples/sweeps/...`) work and every output (`--out runs/x`,
`runs/<timestamp>`) lands in the temporary directory. `pip install` is left out of a command
(the package is installed already). A block whose line before the fence is `<!-- slow -->` runs
only under `-m slow`; the block after `<!-- test-command -->` is what CI runs (`.ci/run`) and is
checked word for word instead of run.
"""

from __future__ import annotations

import importlib
import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
PYTHON_PAGES = ("README.md", "docs/api.md", "docs/extending.md")
"""Pages whose ```python blocks stand alone and are run too."""
LINKED = ("scripts", "research", "benchmarks", "examples", "dev", "tests")
"""Repository folders a block may name by a relative path."""
TIMEOUT = 300
"""Seconds a default-run block may take at most (each takes seconds on an idle machine)."""
SLOW_TIMEOUT = 4 * 3600

SETUP_COMMAND = "pip install -e . && python scripts/transfer_arms.py"
TEST_COMMAND = 'pip install -e ".[test]" && python -m pytest'
"""The README's two set-up commands, a contract: `.ci/run` runs the second verbatim."""


@dataclass(frozen=True)
class Block:
    page: str
    line: int
    lang: str
    text: str
    markers: frozenset[str]

    @property
    def id(self) -> str:
        return f"{self.page}:{self.line}"


def blocks(path: Path) -> list[Block]:
    """The fenced blocks of a Markdown page, with the HTML comments on the lines just before."""
    lines = path.read_text(encoding="utf-8").splitlines()
    out, i = [], 0
    while i < len(lines):
        m = re.match(r"^```(\w+)\s*$", lines[i])
        if not m:
            i += 1
            continue
        markers, j = set(), i - 1
        while j >= 0 and re.fullmatch(r"<!--\s*([\w-]+)\s*-->", lines[j].strip()):
            markers.add(lines[j].strip()[4:-3].strip())
            j -= 1
        end = next(k for k in range(i + 1, len(lines)) if lines[k].startswith("```"))
        out.append(Block(str(path.relative_to(ROOT)), i + 1, m.group(1), "\n".join(lines[i + 1:end]) + "\n",
                         frozenset(markers)))
        i = end + 1
    return out


def without_pip(script: str) -> str:
    """The block without its `pip install` commands (a line `pip install X && Y` keeps Y)."""
    kept = []
    for line in script.splitlines():
        if "pip install" in line:
            parts = [p for p in line.split("&&") if not p.strip().startswith("pip install")]
            line = " && ".join(p.strip() for p in parts)
        kept.append(line)
    return "\n".join(kept) + "\n"


def _all(lang: str) -> list[Block]:
    found = [b for page in PAGES for b in blocks(page) if b.lang == lang]
    if lang == "python":
        found = [b for b in found if b.page in PYTHON_PAGES]
    return [b for b in found if "test-command" not in b.markers]


def _param(b: Block):
    return pytest.param(b, id=b.id, marks=[pytest.mark.slow] if "slow" in b.markers else [])


def _run(argv: list[str], block: Block, cwd: Path) -> None:
    for name in LINKED:
        if (ROOT / name).is_dir():
            (cwd / name).symlink_to(ROOT / name)
    env = dict(os.environ, MUJOCO_GL="egl", PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    timeout = SLOW_TIMEOUT if "slow" in block.markers else TIMEOUT
    try:
        done = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        pytest.fail(f"{block.id} took longer than {timeout} s")
    assert done.returncode == 0, (
        f"{block.id} exited with {done.returncode}\n--- block\n{block.text}--- stdout\n{done.stdout[-3000:]}"
        f"--- stderr\n{done.stderr[-3000:]}")


@pytest.mark.parametrize("block", [_param(b) for b in _all("bash")])
def test_bash_block_runs(block: Block, tmp_path: Path) -> None:
    script = without_pip(block.text)
    assert script.strip(), f"{block.id} is only pip install"
    _run(["bash", "-euo", "pipefail", "-c", script], block, tmp_path)


@pytest.mark.parametrize("block", [_param(b) for b in _all("python")])
def test_python_block_runs(block: Block, tmp_path: Path) -> None:
    (tmp_path / "snippet.py").write_text(block.text)
    _run([sys.executable, "snippet.py"], block, tmp_path)


def test_readme_set_up_commands_are_the_contract() -> None:
    readme = blocks(ROOT / "README.md")
    bash = [b for b in readme if b.lang == "bash"]
    assert bash[0].text.strip() == SETUP_COMMAND
    ci = [b for b in readme if "test-command" in b.markers]
    assert [b.text.strip() for b in ci] == [TEST_COMMAND]
    # .ci/run's own extraction: the marker alone on its line, then the fence, then the command
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    at = lines.index("<!-- test-command -->")
    assert lines[at + 1] == "```bash" and lines[at + 2] == TEST_COMMAND


def test_pip_lines_are_left_out_but_what_follows_runs() -> None:
    assert without_pip(SETUP_COMMAND + "\n").strip() == "python scripts/transfer_arms.py"
    assert without_pip("pip install -e '.[cluster]'\nls\n").split("\n")[:2] == ["", "ls"]


def test_readme_reads_in_two_minutes() -> None:
    assert len((ROOT / "README.md").read_text(encoding="utf-8").splitlines()) <= 200


PATH_LIKE = re.compile(r"(?<![\w./-])((?:src/armtransfer|armtransfer|scripts|research|benchmarks|examples|docs|tests|dev)"
                       r"/[\w./-]*\.(?:py|md|toml|json|xml|png|txt))\b")
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")
MODULE = re.compile(r"`(armtransfer(?:\.\w+)+)")

def _doc_and_model_pages() -> list[Path]:
    return [*PAGES, *sorted((ROOT / "src" / "armtransfer" / "models").glob("*/README.md"))]


@pytest.mark.parametrize("page", _doc_and_model_pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_every_path_and_link_exists(page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    named = [ROOT / p for p in PATH_LIKE.findall(text)]
    named += [(page.parent / t).resolve() for t in LINK.findall(text) if not re.match(r"[a-z]+:", t)]
    absent = sorted({str(t.relative_to(ROOT)) for t in named if not t.exists()})
    assert not absent, f"{page.relative_to(ROOT)} names paths that do not exist: {absent}"


def test_every_path_in_the_code_exists() -> None:
    """Docstrings and comments name files by their path; every one must still be there."""
    files = [p for d in ("src", *LINKED, "tests") for p in sorted((ROOT / d).rglob("*.py"))
             if p != Path(__file__).resolve()]
    missing = sorted({f"{f.relative_to(ROOT)}: {p}" for f in files
                      for p in PATH_LIKE.findall(f.read_text(encoding="utf-8")) if not (ROOT / p).exists()})
    assert not missing, f"paths named in the code that do not exist: {missing}"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_module_named_exists(page: Path) -> None:
    """A `armtransfer.x.y` in a page is a module, or a name in one."""
    wrong = []
    for dotted in sorted(set(MODULE.findall(page.read_text(encoding="utf-8")))):
        parts = dotted.split(".")
        for cut in range(len(parts), 0, -1):
            try:
                obj = importlib.import_module(".".join(parts[:cut]))
                break
            except ModuleNotFoundError:
                continue
        for name in parts[cut:]:
            if not hasattr(obj, name):
                wrong.append(dotted)
                break
            obj = getattr(obj, name)
    assert not wrong, f"{page.relative_to(ROOT)} names modules or attributes that do not exist: {wrong}"
