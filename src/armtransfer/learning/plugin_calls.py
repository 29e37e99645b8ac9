"""How the package calls code it did not write (a method's potential or bonus, a learner's
``make``, ``learn`` and ``predict``): whatever that code raises or returns, and however long it
takes, the user reads one line naming the plugin and the call.

* :func:`fault` says an exception in one line, whatever it is: an exception whose ``__str__``
  raises, or a ``BaseException`` that is not an ``Exception`` (``GeneratorExit``) included.
* :func:`call` calls plugin code and turns anything it raises (but Ctrl-C) into a
  :class:`~armtransfer.errors.PluginError`.
* :func:`within` runs a probe of plugin code under a time limit, in a child process (``fork``)
  that is killed, with everything it started, when the limit passes or the probe ends, so that
  nothing is left running; the error names the call that overran (:func:`call` reports each call
  it enters to the parent). Where ``fork`` is missing the probe runs in a thread with a deadline,
  which is abandoned when it overruns.
"""

from __future__ import annotations

import numbers
import os
import select
import signal
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

from armtransfer.errors import ArmTransferError, InvalidParameterError, PluginError

PROBE_SECONDS = 60.0
"""The default time limit of a plugin's probe (``--probe-timeout``, ``probe_timeout=``)."""

MAX_PROBE_SECONDS = 86_400.0
"""The largest time limit a probe takes (a day)."""

TIMEOUT_OPTION = "--probe-timeout SECONDS"

_LONGEST = 300  # characters of a plugin's own message kept in the one line

_stage_fd: int | None = None  # in a probe's child process: where it says which call it enters


def probe_seconds(value: object, what: str = "probe_timeout") -> float:
    """``value`` as a probe's time limit: a real number in (0, :data:`MAX_PROBE_SECONDS`]."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InvalidParameterError(f"{what} must be a number of seconds, got {value!r}")
    seconds = float(value)
    if not (0 < seconds <= MAX_PROBE_SECONDS):  # nan fails too
        raise InvalidParameterError(f"{what} must be a number of seconds in (0, {MAX_PROBE_SECONDS:g}], got {value!r}")
    return seconds


def fault(err: BaseException) -> str:
    """``err`` in one line, ``Name: message``, even when its message cannot be made."""
    name = getattr(type(err), "__name__", "an exception")
    try:
        text = str(err)
    except BaseException:  # noqa: BLE001 - an exception whose __str__ raises is still said
        text = "(its message cannot be printed: str() of it raised)"
    if not isinstance(text, str):
        text = "(its message is not text)"
    lines = text.strip().splitlines()
    text = lines[0] if lines else ""
    if len(text) > _LONGEST:
        text = text[:_LONGEST] + "..."
    return f"{name}: {text}" if text else name


def call(said: str, what: str, fn: Any, *args: Any, **kwargs: Any) -> Any:
    """``fn(*args, **kwargs)``, plugin code; whatever it raises but Ctrl-C is a one-line
    :class:`PluginError` ``"{said}: its {what} raised Name: message"``."""
    stage(f"{said}: its {what}")
    try:
        return fn(*args, **kwargs)
    except KeyboardInterrupt:
        raise
    except ArmTransferError as err:  # raised by the package on the plugin's behalf (a nested check)
        if isinstance(err, PluginError):
            raise
        raise PluginError(f"{said}: its {what} raised: {_line(err)}") from None
    except BaseException as err:  # noqa: BLE001 - a plugin's bug, said in one line
        raise PluginError(f"{said}: its {what} raised {fault(err)}") from None


def _line(err: BaseException) -> str:
    said = fault(err)
    return said.split(": ", 1)[1] if ": " in said else said


def stage(text: str) -> None:
    """In a probe's child process, tell the parent which plugin call starts (what an overrun names)."""
    if _stage_fd is not None:
        data = ("S" + text.replace("\n", " ") + "\n").encode("utf-8", "replace")
        try:
            os.write(_stage_fd, data)
        except OSError:
            pass


def within(seconds: float, said: str, work: Callable[[], None]) -> None:
    """``work()`` (a probe: it calls plugin code through :func:`call` and raises
    :class:`PluginError` on a fault) run under a time limit of ``seconds``; a fault is re-raised
    here in one line, an overrun is a one-line :class:`PluginError` naming the call that overran.
    Nothing ``work`` starts is left running."""
    if hasattr(os, "fork"):
        _in_child(seconds, said, work)
    else:  # pragma: no cover - platforms without fork
        _in_thread(seconds, said, work)


def _overran(last: str, said: str, seconds: float) -> PluginError:
    who = last or said
    return PluginError(f"{who} did not return within {seconds:g} s, the probe's time limit ({TIMEOUT_OPTION}, or "
                       "probe_timeout= in Python, sets it)")


def _in_child(seconds: float, said: str, work: Callable[[], None]) -> None:
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: run the probe, say how it ended, and leave without cleaning up the parent's state
        try:
            os.close(r)
            os.setpgid(0, 0)
            for sig in (signal.SIGINT, signal.SIGTERM):
                signal.signal(sig, signal.SIG_DFL)
            global _stage_fd
            _stage_fd = w
            _one_thread()
            try:
                work()
                end = b"K\n"
            except PluginError as err:
                end = ("E" + _line(err) + "\n").encode("utf-8", "replace")
            except BaseException as err:  # noqa: BLE001 - said by the parent in one line
                end = ("E" + f"{said} raised {fault(err)}" + "\n").encode("utf-8", "replace")
            for stream in (sys.stdout, sys.stderr):
                try:
                    stream.flush()
                except BaseException:  # noqa: BLE001
                    pass
            os.write(w, end)
        finally:
            os._exit(0)
    os.close(w)
    try:
        os.setpgid(pid, pid)
    except OSError:
        pass  # the child did it first, or has already left
    data = b""
    try:
        deadline = time.monotonic() + seconds
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise _overran(_last_stage(data), said, seconds)
            ready, _, _ = select.select([r], [], [], left)
            if ready:
                chunk = os.read(r, 65536)
                if not chunk:
                    break
                data += chunk
    finally:
        os.close(r)
        _end(pid)
    lines = data.decode("utf-8", "replace").splitlines()
    ends = [line for line in lines if line[:1] in ("K", "E")]
    if not ends:
        raise PluginError(f"{_last_stage(data) or said} ended the probe's process without an answer (it crashed or "
                          "exited)")
    if ends[-1].startswith("E"):
        raise PluginError(ends[-1][1:])


def _one_thread() -> None:
    """In the probe's child: a thread pool the parent started (torch's OpenMP) does not survive
    ``fork``, and entering it could hang the probe; the child computes on one thread."""
    torch = sys.modules.get("torch")
    if torch is not None:
        try:
            torch.set_num_threads(1)
        except Exception:  # noqa: BLE001 - best effort
            pass


def _last_stage(data: bytes) -> str:
    stages = [line[1:] for line in data.decode("utf-8", "replace").splitlines() if line.startswith("S")]
    return stages[-1] if stages else ""


def _end(pid: int) -> None:
    """Kill the probe's process group (the child and whatever it started) and reap the child."""
    try:
        os.killpg(pid, signal.SIGKILL)
    except OSError:
        pass
    try:
        os.waitpid(pid, 0)
    except ChildProcessError:
        pass


def _in_thread(seconds: float, said: str, work: Callable[[], None]) -> None:  # pragma: no cover - no fork
    outcome: list[BaseException | None] = []

    def run() -> None:
        try:
            work()
            outcome.append(None)
        except BaseException as err:  # noqa: BLE001
            outcome.append(err)

    thread = threading.Thread(target=run, daemon=True, name="armtransfer-probe")
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        raise _overran("", said, seconds)
    err = outcome[0] if outcome else None
    if isinstance(err, PluginError):
        raise PluginError(_line(err)) from None
    if err is not None:
        raise PluginError(f"{said} raised {fault(err)}") from None
