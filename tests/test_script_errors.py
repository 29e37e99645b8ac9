"""Every script (scripts/, examples/, benchmarks/, research/) keeps the command's error contract for bad arguments: one line
on stderr, exit code 2, no traceback (``armtransfer.script``)."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ALL = sorted(p for d in ("scripts", "examples", "benchmarks", "research") for p in (ROOT / d).glob("*.py"))
WITH_OPTIONS = [str(p.relative_to(ROOT)) for p in ALL if "script.parser(" in p.read_text()]


def test_every_script_with_options_uses_the_one_line_parser():
    for path in ALL:
        text = path.read_text()
        assert "argparse.ArgumentParser(" not in text, f"{path.name} builds its own parser"
    assert len(WITH_OPTIONS) >= 10


@pytest.mark.parametrize("name", WITH_OPTIONS)
def test_a_bad_option_is_one_line_and_exit_2(name, tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / name), "--no-such-option", "1"], capture_output=True,
                          text=True, timeout=120, cwd=tmp_path)
    assert proc.returncode == 2, (proc.stdout[-500:], proc.stderr[-500:])
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and f"{Path(name).name}: error: " in lines[0] and "Traceback" not in proc.stderr
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_an_unknown_method_to_select_defaults_is_one_line_naming_the_valid_ones(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "research" / "select_defaults.py"), "--method", "guided-tips"],
                          capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "'guided-tips'" in lines[0] and "'guided-tip'" in lines[0] and "'dense'" in lines[0]


def _into_a_closed_pipe(argv, cwd) -> subprocess.CompletedProcess:
    """Run ``argv`` with stdout a pipe whose reader is gone before the first write (as after
    ``| head``: Python starts far slower than the close below)."""
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd)
    proc.stdout.close()
    err = proc.communicate(timeout=120)[1]
    return subprocess.CompletedProcess(proc.args, proc.returncode, "", err)


@pytest.mark.parametrize("size", [10, 1_000_000])  # left in the buffer until the end; written at once
def test_a_reader_that_stops_reading_ends_a_script_quietly(size, tmp_path):
    body = tmp_path / "prints.py"
    body.write_text(f"from armtransfer import script\nscript.exit_with(lambda: print('x' * {size}))\n")
    proc = _into_a_closed_pipe([sys.executable, str(body)], tmp_path)
    assert (proc.returncode, proc.stderr) == (141, "")  # no traceback, no "Exception ignored"


def test_a_reader_that_stops_reading_ends_the_command_quietly(tmp_path):
    argv = [sys.executable, "-m", "armtransfer.cli", "rooms", "--trials", "1", "--no-controls", "--method", "none",
            "--max-episodes", "2"]
    assert subprocess.run(argv, capture_output=True, timeout=120, cwd=tmp_path).returncode == 0
    proc = _into_a_closed_pipe(argv, tmp_path)
    assert (proc.returncode, proc.stderr) == (141, "")


def test_every_script_ends_through_the_quiet_exit():
    for path in ALL:
        text = path.read_text()
        if '__name__ == "__main__"' in text:
            assert "script.exit_with(" in text.split('__name__ == "__main__"')[1], path.name
