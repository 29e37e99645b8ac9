"""What the tests of the error contract share: a command refused in one line, the
processes of a session (to check that a kill leaves none behind), an arm file that includes
another (to check what the arm cache's key covers), and a sweep with an arm table."""

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
    # os.listdir, not Path.glob: glob stats each entry, and a process that ends between the
    # listing and the stat raises ProcessLookupError from inside glob.
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            fields = Path(f"/proc/{name}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[3]) == sid and fields[0] != "Z":
            out.append(int(name))
    return out


def cmdline(pid: int) -> bytes:
    """Process ``pid``'s command line (NUL-separated), empty when it has ended meanwhile."""
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


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


INCLUDING = """<mujoco model="inc_scara"><compiler angle="radian" meshdir="{meshdir}"/><worldbody>
  <body name="upper" pos="0.05 0.02 0.15">
    <joint name="shoulder" type="hinge" axis="0 0 1" range="-3 3"/>
    <geom name="upper_geom" type="capsule" size="0.01" fromto="0 0 0 0.24 0 0"/>
    <include file="fore.xml"/>
  </body></worldbody></mujoco>"""
FORE = """<mujoco><body name="fore" pos="0.24 0 -0.03">
      <joint name="elbow" type="hinge" axis="0 0 1" range="-2.9 2.9"/>
      <geom name="fore_geom" type="capsule" size="0.01" fromto="0 0 0 {length} 0 0"/>
      <site name="pen_tip" pos="{length} 0 -0.116"/>
    </body></mujoco>"""
"""An arm file (``INCLUDING.format(meshdir=...)``) whose forearm is in ``fore.xml``
(``FORE.format(length=...)``)."""


SWEEP_WITH_ARM = """[sweep]
name = "s"
tasks = [1]
pairs = [["coarse", "fine"]{extra_pair}]
methods = ["none"]
trials = 1
max_episodes = 3

[arms.{name}]
xml = "{xml}"
tip_site = "pen_tip"
"""
"""A sweep with an ``[arms.NAME]`` table (the arm file ``xml``) and maybe a pair more."""
