"""The wrapper example script's fast mode: it runs top to bottom and prints the comparison."""

import re
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "examples" / "example_wrapper.py"


def test_example_wrapper_fast_mode_prints_both_variants_and_the_difference():
    proc = subprocess.run([sys.executable, str(SCRIPT), "--fast"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = proc.stdout
    assert "ur5e_like:cartesian hands over 20 (cell, action) pairs for task 1" in out
    without = re.search(r"without transfer: first goal after ([\d,]+) steps", out)
    with_ = re.search(r"with dense: first goal after ([\d,]+) steps", out)
    diff = re.search(r"difference: (-?[\d,]+) fewer steps", out)
    assert without and with_ and diff
    a, b, d = (int(m.group(1).replace(",", "")) for m in (without, with_, diff))
    assert a > 0 and b > 0 and d == a - b
