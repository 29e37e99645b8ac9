"""Processes that end with the sweep that started them, however it ends.

A pool worker started from :func:`guarded_spawn_context` runs :data:`GUARD` first: before
Python imports anything for it, it checks that its parent is still the driver that started
it and asks Linux to send it SIGTERM when that parent dies (``PR_SET_PDEATHSIG``). A driver
killed while its workers are still importing (a few seconds, a few hundred MB each) takes them
with it at once.

A local Ray instance's processes (its GCS server, raylet, agents and workers) are the
sweep's children, but a sweep killed with SIGKILL cannot stop them, and they lived on for
minutes. :class:`Reaper` starts a small watcher process before anything else is started; it
lists every process the sweep starts from then on (and the pids it is told), and waits on a
pipe from the sweep. When the sweep says ``done`` (it stopped them itself) the watcher just
exits; when the pipe closes without it (the sweep died), the watcher kills those processes
and every process they started.

Two races are closed at that moment. A process the sweep started since the watcher's last look,
whose parent then died, belongs to PID 1 and is below no listed process: while the watcher
lives, the sweep's environment carries :data:`MARK` with the watcher's own token, which every
process started from then on inherits, and the watcher kills what carries it. And a listed
process may start another between the watcher's look and its kill (a raylet starting a
worker): the watcher first stops (SIGSTOP) what it found, looks again, stops what is new, until
a look finds nothing new, and only then kills them all.
"""

from __future__ import annotations

import functools
import multiprocessing.context
import os
import selectors
import signal
import subprocess
import sys
import threading
from multiprocessing import popen_spawn_posix, spawn
from typing import IO
from pathlib import Path

DONE = "done"
MARK = "ARMTRANSFER_REAPER"
"""The environment variable that names the watcher whose sweep started a process."""


def _stat(pid: int) -> list[str] | None:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    except OSError:
        return None


def start_time(pid: int) -> str | None:
    """Process ``pid``'s start time (so a pid taken again by a new process is told apart)."""
    fields = _stat(pid)
    return fields[19] if fields else None


def _pids() -> list[int]:
    """The pids in /proc now (a plain listing: nothing is stat'ed, so a process that ends
    meanwhile cannot raise here)."""
    return [int(name) for name in os.listdir("/proc") if name.isdigit()]


def descendants(pids: set[int]) -> set[int]:
    """``pids`` and every living process below them."""
    children: dict[int, list[int]] = {}
    for pid in _pids():
        fields = _stat(pid)
        if fields and fields[0] != "Z":
            children.setdefault(int(fields[1]), []).append(pid)
    out, todo = set(), list(pids)
    while todo:
        pid = todo.pop()
        if pid not in out:
            out.add(pid)
            todo.extend(children.get(pid, ()))
    return out


class Reaper:
    """The watcher of one sweep: :meth:`watch` the pids to stop if the sweep dies; :meth:`close`
    when they were stopped."""

    def __init__(self) -> None:
        self.proc = subprocess.Popen([sys.executable, "-c", "from armtransfer.parallel.reaper import main; main()"],
                                     stdin=subprocess.PIPE, text=True, start_new_session=True,
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        assert self.proc.stdin is not None  # stdin=PIPE always opens it
        self.stdin: IO[str] = self.proc.stdin
        self._before = os.environ.get(MARK)
        os.environ[MARK] = token(self.proc.pid) or ""  # every process started from now on carries it

    def watch(self, pids) -> None:
        for pid in pids:
            start = start_time(pid)
            if start is not None and pid != self.proc.pid:
                self.stdin.write(f"{pid} {start}\n")
        self.stdin.flush()

    def close(self, stop: bool = False) -> None:
        """End the watcher; with ``stop`` it kills the watched processes first."""
        try:
            if not stop:
                self.stdin.write(DONE + "\n")
            self.stdin.close()
        except OSError:
            pass
        if self._before is None:
            os.environ.pop(MARK, None)
        else:
            os.environ[MARK] = self._before
        self.proc.wait()


def token(pid: int) -> str | None:
    """The mark of the watcher ``pid``: its pid and start time."""
    start = start_time(pid)
    return f"{pid}:{start}" if start is not None else None


def carrying(mark: str) -> set[int]:
    """Every process whose environment has ``MARK=mark`` (those of other users are not read)."""
    needle = f"{MARK}={mark}".encode() + b"\0"
    out = set()
    for pid in _pids():
        try:
            environ = Path(f"/proc/{pid}/environ").read_bytes()
        except OSError:
            continue
        if b"\0" + needle in b"\0" + environ:
            out.add(pid)
    return out


def stop_all(pids: set[int], mark: str, me: int) -> None:
    """Kill ``pids``, everything below them and everything carrying ``mark``; first stop each
    one found, and look again until nothing new is found, so that none can start another
    unseen."""
    stopped: dict[int, str] = {}
    for _ in range(100):  # each look finds what the last one's processes started before they stopped
        found = descendants(pids | set(stopped) | carrying(mark)) - set(stopped) - {me}
        if not found:
            break
        for pid in found:
            start = start_time(pid)
            if start is None:
                continue
            try:
                os.kill(pid, signal.SIGSTOP)
            except (ProcessLookupError, PermissionError):
                continue
            stopped[pid] = start
    for pid, start in stopped.items():
        if start_time(pid) == start:
            try:
                os.kill(pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass


def children_of(pid: int) -> set[int]:
    """Every living process below ``pid``."""
    return descendants({pid}) - {pid}


POLL = 1.0
"""Seconds between two looks of the watcher at the sweep's processes."""


def main() -> None:
    """The watcher: while the sweep lives, list every process below it (each look, every
    :data:`POLL` s, adds those started since: Ray starts its agents after ``init`` returns,
    and a raylet that dies first would leave them to PID 1) and the "PID START" lines it is
    sent; when the pipe closes, unless the last line was ``done``, kill each listed process
    that still is the one listed, with everything below it and everything carrying its mark
    (:func:`stop_all`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a Ctrl-C to the sweep's group is the sweep's
    sweep, me = os.getppid(), os.getpid()
    earlier = descendants({sweep})  # what the sweep ran before the watcher is not its to stop
    listed: dict[int, str] = {}
    last, pending = "", b""
    watch = selectors.DefaultSelector()
    watch.register(sys.stdin.fileno(), selectors.EVENT_READ)
    while True:
        if watch.select(timeout=POLL):
            chunk = os.read(sys.stdin.fileno(), 65536)
            if not chunk:
                break
            *lines, pending = (pending + chunk).split(b"\n")
            for line in lines:
                last = line.decode(errors="replace").strip()
                parts = last.split()
                if len(parts) == 2 and parts[0].isdigit():
                    listed[int(parts[0])] = parts[1]
        for pid in descendants({sweep}) - earlier - {me}:
            start = start_time(pid)
            if start is not None:
                listed.setdefault(pid, start)
    if last == DONE:
        return
    alive = {pid for pid, start in listed.items() if start_time(pid) == start}
    stop_all(alive, token(me) or "", me)


GUARD = """import os
if os.getppid() != {driver}: os._exit(1)
try:
    import ctypes
    ctypes.CDLL(None).prctl(1, {signal}, 0, 0, 0)
except Exception:
    pass
if os.getppid() != {driver}: os._exit(1)
"""
"""The first lines a guarded worker runs (``prctl(1, ...)`` is PR_SET_PDEATHSIG; where it does
not exist, the worker's own first code watches its parent instead, ``pool.watch_driver``): the
standard library's ``os`` and ``ctypes`` only, so that nothing is imported before the driver is
known alive."""

_LAUNCH = threading.Lock()


@functools.cache
def _guarded_popen():
    """The POSIX spawn launcher with :data:`GUARD` before its command (made on first use: the
    module it extends exists on POSIX only)."""
    class GuardedPopen(popen_spawn_posix.Popen):
        def _launch(self, process_obj) -> None:
            guard = GUARD.format(driver=os.getpid(), signal=int(signal.SIGTERM))
            with _LAUNCH:
                plain = spawn.get_command_line

                def guarded(**kwds) -> list[str]:
                    cmd = plain(**kwds)
                    at = cmd.index("-c") + 1
                    cmd[at] = guard + cmd[at]
                    return cmd

                spawn.get_command_line = guarded  # read by the launch below, put back after it
                try:
                    super()._launch(process_obj)  # type: ignore[misc]  # typeshed leaves this private method out
                finally:
                    spawn.get_command_line = plain

    return GuardedPopen


class GuardedSpawnProcess(multiprocessing.context.SpawnProcess):
    """A spawned process whose command line starts with :data:`GUARD`."""

    @staticmethod
    def _Popen(process_obj):
        return _guarded_popen()(process_obj)


class GuardedSpawnContext(multiprocessing.context.SpawnContext):
    Process = GuardedSpawnProcess


def guarded_spawn_context() -> multiprocessing.context.SpawnContext:
    """The "spawn" start method with processes that end with their parent from their first
    instruction (a pool's ``mp_context``)."""
    return GuardedSpawnContext()
