"""Where sweep runs execute: a local process pool, or Ray (a cluster or a local instance).

Both executors hand finished runs back to the driver, which alone writes the store, so
a run is recorded exactly once. A run whose worker crashes (or is killed) is retried up to
``retries`` more times, then recorded as failed; it is never lost silently. The driver's
``on_done`` may answer a finished run with the runs that waited for it (a benchmark's trials
wait for robot 1's path): they are run too, by the same workers.
"""

from __future__ import annotations

import ipaddress
import re
import os
import socket
from collections import deque
from collections.abc import Callable, Sequence
from typing import Any, cast

from armtransfer.experiments.benchmark_runs import robot_key
from armtransfer.experiments.execute import execute
from armtransfer.experiments.run import Run
from armtransfer.checks import integer_text
from armtransfer.errors import ArmTransferError
from armtransfer.cpus import ENV as CPUS_ENV
from armtransfer.parallel.pool import DONE, Pool
from armtransfer.parallel.reaper import Reaper, children_of
from armtransfer.tasks.robot import DiscreteRobot

Done = Callable[[Any, dict, float], "list | None"]  # (run, result, seconds) -> runs it releases
Failed = Callable[[Any, str, int], None]  # (run, error, attempts)


class ExecutorError(ArmTransferError):
    """An executor cannot start (e.g. Ray is not installed or unreachable)."""


def _execute_in_ray(run: Run, robots, fn: Callable = execute):
    """``fn`` (a sweep's ``execute``) in a Ray worker, its trials on one thread: Ray's tasks are
    the parallelism."""
    os.environ.setdefault(CPUS_ENV, "1")
    return fn(run, robots)


def run_local(
    runs: Sequence[Run], robots: dict[str, DiscreteRobot], workers: int, on_done: Done, on_failed: Failed,
    retries: int = 2, fn: Callable = execute,
) -> None:
    """A process pool over this machine's cores (:class:`~armtransfer.parallel.pool.Pool`).

    Each worker holds one run at a time, so when a worker dies (at any moment, its start-up
    included) the run it held is known: that run is given to a fresh worker, up to
    ``retries`` more times, then recorded as failed. ``fn(run, robots) -> (result, seconds)``
    is what a worker runs (tests inject faults here, a benchmark its own runs). The runs that
    ``on_done`` releases need only the robots of ``runs``. Workers start as runs are handed
    out, so no more than the runs need ever start.
    """
    queue = deque(runs)
    attempts = {r.key(): 0 for r in runs}
    with Pool(max(1, workers), _robots_for(runs, robots), fn) as pool:
        while queue or pool.busy():
            while queue and (worker := pool.idle()) is not None:
                pool.give(worker, queue.popleft())
            _, run, answer = pool.next_event()
            if run is None:  # an idle worker died: a new one starts when there is work
                continue
            if answer is None:
                attempts[run.key()] += 1
                if attempts[run.key()] > retries:
                    on_failed(run, "worker process died", attempts[run.key()])
                else:
                    queue.appendleft(run)
            elif answer[0] == DONE:
                result, secs = cast(tuple, answer[1])  # fn's answer is (result, seconds)
                while queue and (worker := pool.idle()) is not None:  # it works while the store is written
                    pool.give(worker, queue.popleft())
                for more in on_done(run, result, secs) or ():
                    attempts[more.key()] = 0
                    queue.append(more)
            else:
                on_failed(run, str(answer[1]), attempts[run.key()] + 1)


def _robots_for(runs: Sequence[Run], robots: dict[str, DiscreteRobot]) -> dict[str, DiscreteRobot]:
    """The robots ``runs`` read, by either key a worker may look them up by: the spec (a sweep's
    robots, resolved in the sweep's one world) and the spec in the run's world (a benchmark's,
    whose cases may each name a world)."""
    needed = {key for r in runs for spec in (r.source, r.target)
              for key in (spec, robot_key(spec, _world_name(r)))}
    return {k: v for k, v in robots.items() if k in needed}


def _world_name(run: Run) -> str | None:
    """A benchmark run's world name (a sweep's robots are all in its one world: None)."""
    world = getattr(run, "world", None)
    return world if isinstance(world, str) else None


def import_ray():
    try:
        import ray  # the cluster extra
    except ImportError:
        raise ExecutorError(
            "--executor ray needs Ray: pip install -e \".[cluster]\" (or pip install ray)"
        ) from None
    return ray


RAY_CONNECT_TIMEOUT = 10.0
"""Seconds to wait for a Ray address to answer before saying it cannot be reached."""


_LABEL = re.compile(r"(?!-)[A-Za-z0-9-]{1,63}(?<!-)")


def check_address(address: object) -> tuple[str, int] | None:
    """``address`` (``HOST:PORT`` or ``ray://HOST:PORT``, or ``auto``) as (host, port), checked
    before anything uses it: a host name of dot-separated labels of 1 to 63 letters, digits and
    '-' (at most 253 characters), an IPv4 address or a bracketed IPv6 one; a port 1..65535. None
    for ``auto``. Anything else is one line."""
    usage = "a Ray address is HOST:PORT, ray://HOST:PORT or auto"
    if not isinstance(address, str):
        raise ExecutorError(f"{usage}, got {address!r}")
    shown = address if len(address) <= 100 else f"{address[:60]}... ({len(address)} characters)"
    if address == "auto":
        return None
    target = address[len("ray://"):] if address.startswith("ray://") else address
    host, colon, port = target.rpartition(":")
    number = integer_text(port, signed=False)
    if not colon or number is None or not 1 <= number <= 65535:
        raise ExecutorError(f"{usage}, with a port 1..65535, got {shown!r}")
    if host.startswith("[") and host.endswith("]"):
        try:
            ipaddress.IPv6Address(host[1:-1])
        except ValueError:
            raise ExecutorError(f"{usage}; {host[:60]!r} is not an IPv6 address") from None
        return host[1:-1], number
    if host == "":
        return "127.0.0.1", number
    labels = host.rstrip(".").split(".")
    if len(host) > 253 or not all(_LABEL.fullmatch(label) for label in labels):
        long = next((label for label in labels if len(label) > 63), None)
        why = (f"its part {long[:20]}... has {len(long)} characters (at most 63)" if long is not None else
               "a host name is dot-separated parts of 1 to 63 letters, digits and '-' (at most 253 characters)")
        raise ExecutorError(f"{usage}; the host of {shown!r} is not a host name: {why}")
    return host, number


def check_reachable(address: str) -> None:
    """Fail in one line within ``RAY_CONNECT_TIMEOUT`` when nothing answers at ``address``
    (``host:port`` or ``ray://host:port``, checked first by :func:`check_address`); ``ray.init``
    alone would retry for minutes."""
    found = check_address(address)
    if found is None:
        return
    host, port_number = found
    try:
        with socket.create_connection((host, port_number), timeout=RAY_CONNECT_TIMEOUT) as conn:
            answer = _http2_answer(conn)
    except (OSError, UnicodeError, ValueError) as err:
        raise ExecutorError(f"cannot reach Ray at {address[:100]!r}: {getattr(err, 'strerror', None) or err}") from None
    if answer is not None:
        raise ExecutorError(f"what answers at {address!r} is not Ray ({answer}); give the address of a Ray "
                            "head node (HOST:6379, or ray://HOST:10001 for Ray Client)")


HTTP2_PREFACE = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n" + b"\x00\x00\x00\x04\x00\x00\x00\x00\x00"
"""What an HTTP/2 client sends first: the connection preface and an empty SETTINGS frame."""


def _http2_answer(conn) -> str | None:
    """None when the server on ``conn`` speaks HTTP/2 (gRPC, as Ray's head node and Ray Client
    do: its first frame is a SETTINGS frame), else what it said instead, in a few words."""
    conn.settimeout(RAY_ANSWER_TIMEOUT)
    try:
        conn.sendall(HTTP2_PREFACE)
        head = b""
        while len(head) < 9:
            chunk = conn.recv(9 - len(head))
            if not chunk:
                break
            head += chunk
    except TimeoutError:
        return f"it said nothing within {RAY_ANSWER_TIMEOUT:g} s"
    except OSError as err:
        return f"it closed the connection: {err.strerror or err}"
    if len(head) == 9 and head[3] == 0x04:  # a frame header whose type is SETTINGS
        return None
    if not head:
        return "it closed the connection without a word"
    text = "".join(ch if ch.isprintable() else " " for ch in head.decode("latin-1")).strip()
    return f"it answered {text!r}..." if text else "it answered in bytes that are not HTTP/2"


RAY_ANSWER_TIMEOUT = 5.0
"""Seconds to wait for the server at a Ray address to answer an HTTP/2 preface."""


def run_ray(
    runs: Sequence[Run], robots: dict[str, DiscreteRobot], workers: int | None, address: str | None,
    on_done: Done, on_failed: Failed, retries: int = 2, fn: Callable = execute,
) -> None:
    """Ray tasks on the cluster at ``address``, or on a local instance with ``workers`` CPUs,
    each running ``fn(run, robots)``.

    Each robot is put in Ray's object store once and shared by every task that needs it."""
    ray = import_ray()
    started_here = False
    reaper = None
    if not ray.is_initialized():
        try:
            if address:
                check_reachable(address)
                ray.init(address=address, log_to_driver=False, configure_logging=False)
            else:  # a local instance: its processes are stopped with the sweep, even a killed one
                reaper = Reaper()
                before = children_of(os.getpid())
                ray.init(num_cpus=workers or os.cpu_count(), include_dashboard=False,
                         log_to_driver=False, configure_logging=False)
                reaper.watch(children_of(os.getpid()) - before)
        except Exception as err:  # noqa: BLE001 - one line for the user
            if reaper is not None:  # whatever the failed start left running goes
                reaper.watch(children_of(os.getpid()) - {reaper.proc.pid})
                reaper.close(stop=True)
            raise ExecutorError(f"cannot start or reach Ray ({address or 'local'}): {err}".splitlines()[0]) from None
        started_here = True
    try:
        remote_execute = ray.remote(max_retries=retries, retry_exceptions=False)(_execute_in_ray)
        refs = {spec: ray.put(robot) for spec, robot in robots.items()}
        futures = {}

        def submit(run: Run):
            needed = {key: refs[key] for key in _robots_for([run], robots)}
            ref = remote_execute.remote(run, _RobotRefs(needed), fn)
            futures[ref] = run
            return ref

        not_done = [submit(run) for run in runs]
        while not_done:
            finished, not_done = ray.wait(not_done, num_returns=1)
            for ref in finished:
                run = futures[ref]
                try:
                    result, secs = ray.get(ref)
                except Exception as err:  # noqa: BLE001 - recorded, not lost
                    cause = getattr(err, "cause", None) or err
                    # a benchmark run's failure is its one line, then its traceback (the store keeps both)
                    said = str(cause) if "\nTraceback" in str(cause) else \
                        f"{type(cause).__name__}: {cause}".splitlines()[0]
                    on_failed(run, said, retries + 1)
                    continue
                not_done += [submit(more) for more in on_done(run, result, secs) or ()]
    finally:
        if started_here:
            ray.shutdown()
        if reaper is not None:
            reaper.close()


class _RobotRefs(dict):
    """A dict of robot ObjectRefs that a Ray worker resolves on first access."""

    def __getitem__(self, key):
        value = super().__getitem__(key)
        if not isinstance(value, DiscreteRobot):
            import ray  # the cluster extra: only a Ray run's robots are references

            value = ray.get(value)
            super().__setitem__(key, value)
        return value
