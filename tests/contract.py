"""What the tests of the error contract share: a command refused in one line, and the
processes of a session (to check that a kill leaves none behind)."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

from armtransfer.cli import main


def refused(argv: list[str], tmp_path: Path, monkeypatch, capsys) -> str:
    """Run the command in ``tmp_path``: it must exit 2 with one line on stderr, no traceback,
    and nothing new in the folder. Returns the line."""
    monkeypatch.chdir(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's own usage errors
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2, f"{argv}: exit {code}: {err}"
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, f"{argv}: {err}"
    assert sorted(p.name for p in tmp_path.iterdir()) == before, f"{argv} wrote something"
    return err


def session(sid: int) -> list[int]:
    """Live processes of session ``sid`` (field 6 of /proc/PID/stat)."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[3]) == sid and fields[0] != "Z":
            out.append(int(stat.parent.name))
    return out


def settle(sid: int, seconds: float = 60.0) -> list[int]:
    """The session's processes left once they had ``seconds`` to end; any left are killed,
    so that a failing check leaves nothing behind either."""
    deadline = time.time() + seconds
    while time.time() < deadline and session(sid):
        time.sleep(0.2)
    left = session(sid)
    for pid in left:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    return left
