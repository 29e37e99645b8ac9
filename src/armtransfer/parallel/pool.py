"""A process pool whose driver sees every worker's death, at any moment, and knows its run.

Each worker has a pipe of its own and holds at most one run. The driver waits on the pipes
and on every worker's sentinel at once, so a worker that dies while it starts, while it
receives the robots, while it learns or while it answers is noticed at once, and the run it
held is known exactly. The driver starts no thread that it must join and shares no queue
with its workers: no worker's death can leave it waiting on a pipe that nobody reads, which
the standard library's pool can (a worker killed while it started left a sweep waiting for
good).

Workers start from :func:`~armtransfer.parallel.reaper.guarded_spawn_context`, so they end
with the driver whatever the moment; they ignore Ctrl-C, which is the driver's to handle.
"""

from __future__ import annotations

import ctypes
import os
import signal
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait
from multiprocessing.process import BaseProcess
from typing import Any

from armtransfer.cpus import ENV as CPUS_ENV
from armtransfer.errors import ArmTransferError
from armtransfer.parallel.reaper import guarded_spawn_context

Task = Callable[[Any, dict], object]  # (run, robots) -> answer
"""What a worker runs: ``fn(run, robots)``, its answer sent back to the driver."""

DONE, FAILED = "done", "failed"


def serve(conn: Connection, driver: int) -> None:
    """A worker: receive the robots, then answer each ``(fn, run)`` with ``("done", answer)`` or
    ``("failed", message)`` until the pipe closes or says ``None``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C reaches the whole group: the driver decides
    watch_driver(driver)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS", CPUS_ENV):
        os.environ.setdefault(var, "1")  # one thread per worker: the workers are the parallelism
    try:
        robots = conn.recv()
        while (task := conn.recv()) is not None:
            fn, run = task
            try:
                reply: tuple[str, object] = (DONE, fn(run, robots))
            except ArmTransferError as err:
                reply = (FAILED, str(err))
            except Exception as err:  # noqa: BLE001 - reported to the driver, which records it
                reply = (FAILED, f"{type(err).__name__}: {err}")
            try:
                conn.send(reply)
            except (OSError, EOFError):
                return
            except Exception as err:  # noqa: BLE001 - an answer that cannot be sent is a failure
                conn.send((FAILED, f"its result cannot be sent back: {type(err).__name__}: {err}"))
    except (EOFError, OSError):  # the driver is gone or closed the pipe
        return


def watch_driver(driver: int) -> None:
    """End this worker when ``driver`` (its parent's pid, as the driver gave it) is gone, even
    after a SIGKILL: Linux's PR_SET_PDEATHSIG (the command line's guard set it already), else a
    thread that looks at the parent's pid each second."""
    if os.getppid() != driver:
        os._exit(1)
    try:
        if ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGTERM), 0, 0, 0) == 0:  # 1: PR_SET_PDEATHSIG
            if os.getppid() != driver:  # the parent died before the call
                os._exit(1)
            return
    except (OSError, AttributeError):
        pass

    def watch() -> None:
        while os.getppid() == driver:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


@dataclass(eq=False)
class Worker:
    """One worker process, its end of the pipe, and the run it holds (None when idle)."""

    process: BaseProcess
    conn: Connection
    run: Any = None
    handover: threading.Thread | None = field(default=None, repr=False)


class Pool:
    """Up to ``size`` guarded workers, each given ``robots`` once when it starts.

    :meth:`give` hands a run to a worker; :meth:`next_event` waits for the next answer or
    death. Leaving the ``with`` block ends every worker, waiting at most a few seconds."""

    def __init__(self, size: int, robots: dict, fn: Task) -> None:
        self.size, self.robots, self.fn = size, robots, fn
        self.ctx = guarded_spawn_context()
        self.workers: list[Worker] = []

    def __enter__(self) -> Pool:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def idle(self) -> Worker | None:
        """An idle worker, a new one if there is room, or None."""
        for worker in self.workers:
            if worker.run is None:
                return worker
        if len(self.workers) < self.size:
            return self._start()
        return None

    def _start(self) -> Worker:
        mine, theirs = self.ctx.Pipe(duplex=True)
        process = self.ctx.Process(target=serve, args=(theirs, os.getpid()), daemon=True)
        process.start()
        theirs.close()  # the worker's end lives in the worker only: its death closes the pipe
        worker = Worker(process, mine)
        self.workers.append(worker)
        return worker

    def give(self, worker: Worker, run: Any) -> None:
        """Hand ``run`` to ``worker``. A new worker is sent the robots first, from a thread that
        a death of the worker ends (the robots may be larger than the pipe holds, and the worker
        reads them only once it has started)."""
        worker.run = run
        if worker.handover is None:
            worker.handover = threading.Thread(target=_send_all, args=(worker.conn, [self.robots, (self.fn, run)]),
                                               daemon=True)
            worker.handover.start()
        else:  # the worker has answered, so it is reading and the handover is over
            _send_all(worker.conn, [(self.fn, run)])

    def busy(self) -> bool:
        return any(w.run is not None for w in self.workers)

    def next_event(self) -> tuple[Worker, Any, tuple[str, object] | None]:
        """Wait for the next worker that answers or dies: ``(worker, run, answer)``, with the run
        it held and its answer, or None as the answer when it died (it has then left the pool;
        ``run`` is None when it died idle)."""
        by_conn = {w.conn: w for w in self.workers if w.run is not None}
        by_sentinel = {w.process.sentinel: w for w in self.workers}
        ready = wait(list(by_conn) + list(by_sentinel))
        for conn in (c for c in ready if c in by_conn):  # answers first: a worker may answer, then die
            worker, run = by_conn[conn], by_conn[conn].run
            try:
                answer = worker.conn.recv()
            except (EOFError, OSError):  # it died before its answer was whole
                self._bury(worker)
                return worker, run, None
            worker.run = None
            return worker, run, answer
        sentinel = ready[0]  # only sentinels are left in ready
        assert isinstance(sentinel, int)
        worker = by_sentinel[sentinel]
        run, worker.run = worker.run, None
        self._bury(worker)
        return worker, run, None

    def _bury(self, worker: Worker) -> None:
        """Remove a dead (or dying) worker; its pipe is closed once its handover has ended."""
        self.workers.remove(worker)
        worker.process.kill()
        worker.process.join()
        self._close_pipe(worker)

    @staticmethod
    def _close_pipe(worker: Worker) -> None:
        if worker.handover is not None:
            worker.handover.join(5.0)  # its worker is gone, so its send fails at once
            if worker.handover.is_alive():  # never seen; closing under a writing thread is worse
                return
        worker.conn.close()

    def close(self) -> None:
        """Ask each idle worker to stop and end each busy one (its run is nobody's now); kill
        whatever has not ended within two seconds."""
        for worker in self.workers:
            if worker.run is None:
                _send_all(worker.conn, [None])
            else:
                worker.process.terminate()
        deadline = time.monotonic() + 2.0
        for worker in self.workers:
            worker.process.join(max(0.0, deadline - time.monotonic()))
            if worker.process.exitcode is None:
                worker.process.kill()
                worker.process.join()
            self._close_pipe(worker)
        self.workers = []


def _send_all(conn: Connection, messages: list) -> None:
    """Send ``messages`` in order; a closed pipe (the worker died) ends it quietly: the driver
    learns of the death from the worker's sentinel."""
    try:
        for message in messages:
            conn.send(message)
    except (OSError, ValueError):  # ValueError: the driver closed the pipe meanwhile
        pass
