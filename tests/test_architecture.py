"""The project's one-way data flow: transfer/ sees only compiled robots, never MuJoCo."""

import pkgutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_transfer_and_tasks_never_import_mujoco():
    modules = [f"transfer.{m.name}" for m in pkgutil.iter_modules([str(ROOT / "transfer")])]
    modules += [f"tasks.{m.name}" for m in pkgutil.iter_modules([str(ROOT / "tasks")]) if m.name != "workspace"]
    code = (
        "import importlib, sys\n"
        f"for m in {modules!r}: importlib.import_module(m)\n"
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in ('mujoco', 'dm_control', 'mink'))\n"
        "print(','.join(bad))\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert len(modules) > 10
    assert proc.stdout.strip() == "", f"imported: {proc.stdout.strip()}"
