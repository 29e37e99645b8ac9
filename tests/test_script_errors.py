"""Every script under scripts/ keeps the command's error contract for bad arguments: one line
on stderr, exit code 2, no traceback (``armtransfer.script``)."""

import subprocess
import sys
from pathlib import Path

import pytest

SCRIPTS = Path(__file__).resolve().parents[1] / "scripts"
WITH_OPTIONS = sorted(p.name for p in SCRIPTS.glob("*.py") if "script.parser(" in p.read_text())


def test_every_script_with_options_uses_the_one_line_parser():
    for path in SCRIPTS.glob("*.py"):
        text = path.read_text()
        assert "argparse.ArgumentParser(" not in text, f"{path.name} builds its own parser"
    assert len(WITH_OPTIONS) >= 10


@pytest.mark.parametrize("name", WITH_OPTIONS)
def test_a_bad_option_is_one_line_and_exit_2(name, tmp_path):
    proc = subprocess.run([sys.executable, str(SCRIPTS / name), "--no-such-option", "1"], capture_output=True,
                          text=True, timeout=120, cwd=tmp_path)
    assert proc.returncode == 2, (proc.stdout[-500:], proc.stderr[-500:])
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and f"{name}: error: " in lines[0] and "Traceback" not in proc.stderr
    assert list(tmp_path.iterdir()) == []  # nothing written
