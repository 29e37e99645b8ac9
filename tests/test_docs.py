"""The documentation runs: every ```bash block of README.md and docs/*.md, and every ```python
block of the pages whose snippets stand alone (PYTHON_PAGES), is executed, and every file,
link and module it names exists.

A block runs in a fresh temporary directory that links the repository's script folders, so
relative paths (`scripts/...`, `examples/sweeps/...`) work and every output (`--out runs/x`,
`runs/<timestamp>`) lands in the temporary directory. `pip install` is left out of a command
(the package is installed already). A block whose line before the fence is `<!-- slow -->` runs
only under `-m slow`; one whose markers also hold `<!-- hours -->` (a whole held-out suite) is
marked `hours` as well, so that CI's slow run, `-m "slow and not hours"`, spends its time on
tests that can end in it. One marked `<!-- needs-sb3 -->` runs only where the sb3 extra is
installed; the block after `<!-- test-command -->` is what CI runs (`.ci/run`) and is checked
word for word instead of run.

What a block prints, where a page shows it, is checked too: a ```text block marked
`<!-- output -->`, directly after the bash or python block, is that block's standard output
(`expected_output`). The comparison (`output_matches`) is line by line, exact but for three
things: trailing spaces and blank lines at the end are ignored; a line `...` stands for any
number of lines; and a wall-clock time, a number followed by a unit of time (`12 s`, `3.5 ms`,
`2 min`, `1 h`), stands for any time (`TIME`). Every other number is compared as written, so
a run that prints a different number fails (`test_every_number_shown_is_compared`).
"""

from __future__ import annotations

import importlib
import importlib.util
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
LINKED = ("scripts", "research", "benchmarks", "examples", "dev", "tests", "docs")
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


NO_SB3 = importlib.util.find_spec("stable_baselines3") is None


def _param(b: Block):
    marks = [pytest.mark.slow] if "slow" in b.markers else []
    if "hours" in b.markers:
        assert "slow" in b.markers, f"{b.id}: a block marked hours must be marked slow too"
        marks.append(pytest.mark.hours)
    if "needs-sb3" in b.markers:  # the dqn and ppo learners: only where the sb3 extra is installed
        marks.append(pytest.mark.skipif(NO_SB3, reason="needs the sb3 extra (pip install -e '.[sb3]')"))
    return pytest.param(b, id=b.id, marks=marks)


def _run(argv: list[str], block: Block, cwd: Path) -> str:
    """Run ``argv`` for ``block`` in ``cwd`` (with the repository's folders linked); its stdout."""
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
    return done.stdout


TIME = re.compile(r"(?<![\w.,])\d+(?:[.,]\d+)*(?:\.\d+)?\s?(?:s|ms|min|h)\b")
"""A wall-clock time as a run prints it: any such number compares equal to any other."""
ANY_LINES = "..."
"""An output line that stands for any number of lines."""


def _normal(text: str) -> list[str]:
    lines = [TIME.sub("<time>", line.rstrip()) for line in text.splitlines()]
    while lines and not lines[-1]:
        lines.pop()
    return lines


def output_matches(expected: str, printed: str) -> bool:
    """Whether ``printed`` is what ``expected`` shows, by the rules of the module's docstring."""
    parts = [r"(?:[^\n]*\n)*?" if line == ANY_LINES else re.escape(line) + r"\n" for line in _normal(expected)]
    return re.fullmatch("".join(parts), "".join(line + "\n" for line in _normal(printed))) is not None


def expected_output(block: Block) -> str | None:
    """The text of the `<!-- output -->` block right after ``block`` on its page, if any."""
    found = blocks(ROOT / block.page)
    at = next(i for i, b in enumerate(found) if b.line == block.line)
    after = found[at + 1] if at + 1 < len(found) else None
    if after is None or "output" not in after.markers:
        return None
    lines = (ROOT / block.page).read_text(encoding="utf-8").splitlines()
    between = lines[block.line + block.text.count("\n") + 1:after.line - 1]  # after the closing fence
    if any(line.strip() and not line.strip().startswith("<!--") for line in between):
        return None  # prose between the two: the output block belongs to no block
    return after.text


def _check_output(block: Block, printed: str) -> None:
    expected = expected_output(block)
    if expected is not None and not output_matches(expected, printed):
        import difflib

        diff = "\n".join(difflib.unified_diff(_normal(expected), _normal(printed), "the page shows", "the run printed",
                                              lineterm=""))
        pytest.fail(f"{block.id} printed other than its output block shows:\n{diff}")


@pytest.mark.parametrize("block", [_param(b) for b in _all("bash")])
def test_bash_block_runs(block: Block, tmp_path: Path) -> None:
    script = without_pip(block.text)
    assert script.strip(), f"{block.id} is only pip install"
    _check_output(block, _run(["bash", "-euo", "pipefail", "-c", script], block, tmp_path))


@pytest.mark.parametrize("block", [_param(b) for b in _all("python")])
def test_python_block_runs(block: Block, tmp_path: Path) -> None:
    (tmp_path / "snippet.py").write_text(block.text)
    _check_output(block, _run([sys.executable, "snippet.py"], block, tmp_path))


def _output_blocks() -> list[Block]:
    return [b for page in PAGES for b in blocks(page) if "output" in b.markers]


def test_every_output_block_follows_a_block_that_runs() -> None:
    run = {b.id for b in [*_all("bash"), *_all("python")]}
    orphans = []
    for page in PAGES:
        found = blocks(page)
        for i, b in enumerate(found):
            if "output" in b.markers:
                before = found[i - 1] if i else None
                if b.lang != "text" or before is None or before.id not in run or expected_output(before) != b.text:
                    orphans.append(b.id)
    assert not orphans, f"output blocks that are not ```text right after a block the tests run: {orphans}"


def _numbers(text: str) -> list[re.Match]:
    """The numbers of an output block that are not wall-clock times."""
    times = [m.span() for m in TIME.finditer(text)]
    return [m for m in re.finditer(r"\d+", text) if not any(a <= m.start() < b for a, b in times)]


@pytest.mark.parametrize("block", _output_blocks(), ids=lambda b: b.id)
def test_every_number_shown_is_compared(block: Block) -> None:
    """The checker itself: the page's output compared with itself matches, and with any one of
    its numbers changed (as a changed result would print it) no longer does."""
    text = block.text
    assert output_matches(text, text)
    numbers = _numbers(text)
    for m in numbers:
        digit = str((int(text[m.end() - 1]) + 1) % 10)
        edited = text[:m.end() - 1] + digit + text[m.end():]
        assert not output_matches(edited, text), f"{block.id}: {m.group(0)} at {m.start()} is not compared"


def test_the_output_checker_on_a_run(tmp_path: Path) -> None:
    """A block's real output passes, a changed number fails, and only times are normalised."""
    block = Block("docs/example.md", 1, "bash", "printf 'distance 20\\nwrote runs/x in 3.2 s\\n  \\n'\n", frozenset())
    printed = _run(["bash", "-c", block.text], block, tmp_path)
    assert output_matches("distance 20\nwrote runs/x in 12 s\n", printed)
    assert not output_matches("distance 21\nwrote runs/x in 12 s\n", printed)
    assert not output_matches("distance 20\nwrote runs/y in 12 s\n", printed)
    assert not output_matches("distance 20\n", printed)
    assert output_matches("distance 20\n...\n", printed) and output_matches("...\nwrote runs/x in 1 h\n", printed)
    assert not output_matches("distance 20 steps\nwrote runs/x in 3.2 s\n", "distance 20 s\nwrote runs/x in 3.2 s\n")
    assert TIME.sub("T", "62,651 steps/s, 20 seeds, 1,192 s, 0.5 ms, 14 min") == "62,651 steps/s, 20 seeds, T, T, T"


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
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) < 150
    assert lines.index("<!-- test-command -->") > next(i for i, line in enumerate(lines) if "python3 -m venv" in line)


PATH_LIKE = re.compile(r"(?<![\w./-])((?:src/armtransfer|armtransfer|scripts|research|benchmarks|examples|docs|tests|dev)"
                       r"/[\w./-]*\.(?:py|md|toml|json\.gz|json|xml|png|txt))\b")
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


def _linked_pages(page: Path) -> set[Path]:
    """The Markdown pages of the repository a page links to."""
    found = set()
    for target in LINK.findall(page.read_text(encoding="utf-8")):
        if re.match(r"[a-z]+:", target):
            continue
        path = (page.parent / target).resolve()
        if path.suffix == ".md" and path.is_file() and path.is_relative_to(ROOT):
            found.add(path)
    return found


def reachable_from_readme() -> set[Path]:
    """Every page a reader gets to from README.md by following links, README.md included."""
    seen, todo = set(), [ROOT / "README.md"]
    while todo:
        page = todo.pop()
        if page not in seen:
            seen.add(page)
            todo.extend(_linked_pages(page) - seen)
    return seen


def test_every_docs_page_is_reachable_from_the_readme() -> None:
    pages = set((ROOT / "docs").rglob("*.md"))
    orphans = sorted(str(p.relative_to(ROOT)) for p in pages - reachable_from_readme())
    assert not orphans, f"docs pages no link leads to from README.md: {orphans}"


def test_reachability_follows_links_only(tmp_path: Path) -> None:
    """The checker itself: a page linked from nowhere is not reached."""
    reached = reachable_from_readme()
    assert ROOT / "docs" / "api.md" in reached and ROOT / "BENCHMARKS.md" in reached
    assert _linked_pages(ROOT / "docs" / "setup.md") <= reached
    orphan = tmp_path / "orphan.md"
    orphan.write_text("# Linked from nowhere\n\n[the README](README.md)\n")
    assert orphan.resolve() not in reached


ISSUE_NUMBER = re.compile(r"\bissues?\s*#?\d+|(?<![\w&/])#\d+\b|\bthe issue's\b", re.IGNORECASE)
"""What a reader of the docs cannot look up: the tracker's numbers, and "the issue's" target."""


def _reader_pages() -> list[Path]:
    return [ROOT / "README.md", ROOT / "BENCHMARKS.md", *sorted((ROOT / "docs").rglob("*.md"))]


@pytest.mark.parametrize("page", _reader_pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_page_names_an_issue(page: Path) -> None:
    found = [(n, m.group(0)) for n, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1)
             for m in ISSUE_NUMBER.finditer(line)]
    assert not found, f"{page.relative_to(ROOT)} names issues a reader cannot look up (line, text): {found}"


def test_issue_pattern_catches_the_forms_seen() -> None:
    for text in ("on the scene (issue 11).", "see #36", "Issue #4 says", "The issue's target"):
        assert ISSUE_NUMBER.search(text), text
    for text in ("a known issue", "results.md#menagerie-arms", "colour &#8212;", "step 36"):
        assert not ISSUE_NUMBER.search(text), text


def test_the_quick_subset_names_only_test_modules_that_exist() -> None:
    from conftest import HEAVY

    assert HEAVY and all((ROOT / "tests" / name).is_file() for name in HEAVY)
    assert 'python -m pytest -m "not slow and not heavy"' in (ROOT / "docs" / "setup.md").read_text()
