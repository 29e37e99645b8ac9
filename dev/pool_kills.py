"""Put loky's reusable executor (and psutil for the process tree) through the kill tests that
our pool (``parallel/pool.py``, ``parallel/reaper.py``) passes, side by side, and print a table.

The cases are those of ``tests/test_hostile_kills.py`` and ``tests/test_sweep_guards.py``:

- a worker SIGKILLed while it starts (16 MB of robots, 8 runs, 2 workers) at 0 s ten times in a
  row and at 0.01 to 3 s: the driver must finish all 8 runs and leave nothing behind;
- a worker that dies on its first run: a retry, all runs done;
- a run that raises and one whose result cannot be pickled back: two failures, one attempt each,
  and the other runs done;
- Ctrl-C to a working sweep's whole group: exit 130, the one line ``armtransfer sweep:
  interrupted``, no process left after 10 s;
- the driver SIGKILLed while its workers start, and at 0.05 to 4 s of a sweep: no process left
  after 10 s;
- psutil in place of the reaper's /proc walk: a process the sweep started, orphaned before the
  sweep is killed, goes with it.

``loky`` here is :func:`loky_run_local`, ``executors.run_local``'s contract on
``loky.get_reusable_executor``, configured through its public API only (an initializer that
holds the robots and ignores Ctrl-C, one thread per worker): no guard, no reaper. A sweep runs
it by replacing ``run_local`` in ``armtransfer.commands.sweep``.

    python dev/pool_kills.py            # 12 min on 2 cores (most of it loky's 120 s waits)
    python dev/pool_kills.py --quick    # one moment per case; --only TEXT: the cases named so
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from contract import cmdline, session, settle  # noqa: E402  the kill tests' own helpers

HERE = Path(__file__).resolve().parent
BACKENDS = ("ours", "loky", "loky-per-task")
"""Our pool; loky with the robots given once per worker (its initializer's arguments); loky with
the robots sent with every run (no initializer arguments)."""
WORKER_MARK = {"ours": b"spawn_main", "loky": b"popen_loky_posix", "loky-per-task": b"popen_loky_posix"}


# --- the candidate: run_local on loky's reusable executor ------------------------------------

_ROBOTS: dict = {}


def _hold(robots: dict) -> None:
    """loky's initializer: keep the robots (sent once per worker) and leave Ctrl-C to the driver."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _ROBOTS.clear()
    _ROBOTS.update(robots)


def _quiet() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _call(fn: Callable, run: dict, robots: dict | None = None):
    from armtransfer.errors import ArmTransferError

    try:
        return ("done", fn(run, _ROBOTS if robots is None else robots))
    except ArmTransferError as err:
        return ("failed", str(err))
    except Exception as err:  # noqa: BLE001 - reported to the driver, as our pool does
        return ("failed", f"{type(err).__name__}: {err}")


def loky_run_local(runs: list[dict], robots: dict, workers: int, on_done, on_failed, retries: int = 2,
                   fn: Callable | None = None, per_task: bool = False) -> None:
    """``executors.run_local`` on loky: at most ``workers`` runs in flight; a run whose future
    ends with a dead worker (loky cannot say which in-flight run's worker died, so each in-flight
    run is charged) is retried up to ``retries`` more times. The robots go to each worker once,
    as the initializer's arguments, or (``per_task``) with every run. On any error or Ctrl-C the
    executor is shut down and its workers killed, as our pool's ``close`` does."""
    from loky import get_reusable_executor
    from loky.process_executor import TerminatedWorkerError

    from armtransfer.cpus import ENV as CPUS_ENV
    from armtransfer.parallel.executors import _robots_for

    if fn is None:
        from armtransfer.experiments.execute import execute as fn
    one_thread = {v: "1" for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                                   "NUMBA_NUM_THREADS", CPUS_ENV)}
    size = max(1, min(workers, len(runs)))
    held = _robots_for(runs, robots) if robots else {}
    queue = deque(runs)
    attempts = {r["key"]: 0 for r in runs}
    flying: dict = {}
    executor = None
    try:
        while queue or flying:
            executor = (get_reusable_executor(max_workers=size, initializer=_quiet, env=one_thread) if per_task else
                        get_reusable_executor(max_workers=size, initializer=_hold, initargs=(held,), env=one_thread))
            _loky_step(executor, fn, held if per_task else None, queue, flying, size, attempts, retries, on_done,
                       on_failed, TerminatedWorkerError)
    except BaseException:
        if executor is not None:
            executor.shutdown(wait=True, kill_workers=True)
        raise


def _loky_step(executor, fn, robots, queue, flying, size, attempts, retries, on_done, on_failed,
               TerminatedWorkerError) -> None:
    """Fill the free workers, then handle the runs that finished."""
    from concurrent.futures import FIRST_COMPLETED, wait

    while queue and len(flying) < size:
        run = queue.popleft()
        flying[executor.submit(_call, fn, run, robots)] = run
    finished, _ = wait(list(flying), return_when=FIRST_COMPLETED)
    for future in finished:
        run = flying.pop(future)
        try:
            kind, answer = future.result()
        except (TerminatedWorkerError, OSError, EOFError) as err:  # a worker died
            attempts[run["key"]] += 1
            if attempts[run["key"]] > retries:
                on_failed(run, f"worker process died ({type(err).__name__})", attempts[run["key"]])
            else:
                queue.appendleft(run)
            continue
        except Exception as err:  # noqa: BLE001 - e.g. a result that cannot be pickled back
            on_failed(run, f"its result cannot be sent back: {type(err).__name__}: {err}".splitlines()[0],
                      attempts[run["key"]] + 1)
            continue
        if kind == "done":
            result, secs = answer
            on_done(run, result, secs)
        else:
            on_failed(run, answer, attempts[run["key"]] + 1)


def run_local_of(backend: str):
    if backend.startswith("loky"):
        import functools

        return functools.partial(loky_run_local, per_task=backend == "loky-per-task")
    from armtransfer.parallel.executors import run_local

    return run_local


def cli(backend: str) -> int:
    """``armtransfer`` with the sweep's local pool from ``backend``."""
    import armtransfer.commands.sweep as sweep
    from armtransfer.cli import run

    sweep.run_local = run_local_of(backend)  # type: ignore[assignment]
    return run()


# --- what the workers run --------------------------------------------------------------------

def slow_answer(run, robots):
    time.sleep(0.8)  # the workers outlive the latest kill
    return {"robots_bytes": len(robots["big"])}, 0.8


def dies_on_first(run, robots):
    marker = Path(os.environ["POOL_KILLS_MARKER"])
    if not marker.exists():
        marker.write_text("died")
        os._exit(9)
    return {"ok": run["key"]}, 0.0


def raises_or_unsendable(run, robots):
    if run["key"] == "raises":
        raise ValueError("no such thing")
    if run["key"] == "unsendable":
        import threading

        return {"lock": threading.Lock()}, 0.0  # pickle (and loky's cloudpickle) cannot send a lock
    return {"ok": True}, 0.0


def starting_driver(backend: str) -> None:
    runs = [{"key": f"r{i}", "source": "big", "target": "big"} for i in range(8)]
    done: list = []
    failed: list = []
    run_local_of(backend)(runs, {"big": bytes(16_000_000)}, 2, lambda run, result, secs: done.append(result),
                          lambda run, error, attempts: failed.append(error), retries=2, fn=slow_answer)
    print(len(done), len(failed), done[0]["robots_bytes"] if done else 0, flush=True)


# --- process helpers (as tests/contract.py) --------------------------------------------------

def _stat(pid: int) -> list[str] | None:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None


def _env(**extra: str) -> dict[str, str]:
    path = os.pathsep.join(p for p in (str(HERE), os.environ.get("PYTHONPATH", "")) if p)
    return dict(os.environ, PYTHONPATH=path, **extra)


def _python(code: str, cwd: Path, env: dict[str, str] | None = None, **kw) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", code], cwd=cwd, env=env or _env(), start_new_session=True,
                            text=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL), **kw)


def _sweep(backend: str, argv: list[str], cwd: Path, **kw) -> subprocess.Popen:
    code = f"import sys, pool_kills; sys.argv[0] = 'armtransfer'; sys.exit(pool_kills.cli({backend!r}))"
    return subprocess.Popen([sys.executable, "-c", code, *argv], cwd=cwd, env=_env(), start_new_session=True,
                            text=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL), **kw)


# --- the cases: each returns None when it passed, else what went wrong ------------------------

def kill_a_starting_worker(backend: str, delay: float, folder: Path) -> str | None:
    driver = _python(f"import pool_kills; pool_kills.starting_driver({backend!r})", folder,
                     stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        deadline = time.time() + 60
        workers: list[int] = []
        while time.time() < deadline and not workers and driver.poll() is None:
            workers = [p for p in session(driver.pid) if WORKER_MARK[backend] in cmdline(p)]
            time.sleep(0.005)
        if not workers:
            return "no worker started"
        time.sleep(delay)
        os.kill(workers[0], signal.SIGKILL)
        try:
            out, err = driver.communicate(timeout=120)
        except subprocess.TimeoutExpired:
            return "the driver waited for good (no answer in 120 s)"
    finally:
        left = settle(driver.pid, 10)
    if driver.returncode != 0 or "Traceback" in err:
        return f"exit {driver.returncode}: {err.strip().splitlines()[-1] if err.strip() else ''}"
    if out.split() != ["8", "0", "16000000"]:
        return f"printed {out.split()} (8 done, 0 failed expected)"
    if left:
        return f"{len(left)} processes outlived the driver"
    return None


def in_a_row(backend: str, tries: int, folder: Path) -> str | None:
    """:func:`kill_a_starting_worker` at 0 s ``tries`` times, stopping at the first failure."""
    for k in range(tries):
        (folder / str(k)).mkdir()
        problem = kill_a_starting_worker(backend, 0.0, folder / str(k))
        if problem is not None:
            return f"try {k + 1}: {problem}"
    return None


IN_PROCESS = """
import pool_kills
run_local = pool_kills.run_local_of({backend!r})
done, failed = [], {{}}
if {case!r} == "dies":
    runs = [{{"key": f"r{{i}}", "source": "a", "target": "a"}} for i in range(12)]
    run_local(runs, {{}}, 3, lambda r, res, s: done.append(r["key"]),
              lambda r, e, a: failed.update({{r["key"]: (e, a)}}), retries=2, fn=pool_kills.dies_on_first)
    print("ok" if sorted(done) == sorted(r["key"] for r in runs) and not failed else f"done {{len(done)}}, failed {{failed}}")
else:
    runs = [{{"key": k, "source": "a", "target": "a"}} for k in ("raises", "unsendable", "fine1", "fine2")]
    run_local(runs, {{}}, 1, lambda r, res, s: done.append(r["key"]),
              lambda r, e, a: failed.update({{r["key"]: (e, a)}}), retries=2, fn=pool_kills.raises_or_unsendable)
    good = (sorted(done) == ["fine1", "fine2"] and failed.get("raises") == ("ValueError: no such thing", 1)
            and failed.get("unsendable", ("", 0))[1] == 1)
    print("ok" if good else f"done {{sorted(done)}}, failed {{failed}}")
"""


def in_process(backend: str, case: str, folder: Path) -> str | None:
    proc = _python(IN_PROCESS.format(backend=backend, case=case), folder,
                   env=_env(POOL_KILLS_MARKER=str(folder / "marker")), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        out, err = proc.communicate(timeout=180)
    except subprocess.TimeoutExpired:
        return "no answer in 180 s"
    finally:
        left = settle(proc.pid, 10)
    if out.strip() != "ok":
        return (out.strip() or err.strip().splitlines()[-1])[:160]
    return f"{len(left)} processes left" if left else None


SWEEP = """[sweep]
name = "kills"
tasks = [1]
pairs = [["coarse", "fine"]]
methods = ["none"]
seeds = {seeds}
trials = {trials}
"""


def ctrl_c(backend: str, folder: Path) -> str | None:
    (folder / "s.toml").write_text(SWEEP.format(seeds=list(range(8)), trials=2) + "max_episodes = 400\n")
    proc = _sweep(backend, ["sweep", "s.toml", "--out", "store", "--workers", "2"], folder,
                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.time() + 120
        while time.time() < deadline and proc.poll() is None and not list(folder.glob("store/runs/*.json")):
            time.sleep(0.02)
        if proc.poll() is not None:
            return "the sweep ended before a worker was busy"
        os.killpg(proc.pid, signal.SIGINT)
        try:
            _, err = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            return "the driver did not end within 60 s"
    finally:
        left = settle(proc.pid, 10)
    problems = []
    if proc.returncode != 130 or err.strip() != "armtransfer sweep: interrupted":
        problems.append(f"exit {proc.returncode}, stderr {len(err.strip().splitlines())} lines: "
                        f"{err.strip().splitlines()[0][:80] if err.strip() else ''!r}")
    if left:
        problems.append(f"{len(left)} processes left")
    return "; ".join(problems) or None


def kill_driver(backend: str, moment: float | None, folder: Path) -> str | None:
    """SIGKILL the driver alone (not its group): at ``moment`` s, or (None) as soon as its first
    workers exist."""
    (folder / "s.toml").write_text(SWEEP.format(seeds=list(range(80)), trials=20))
    proc = _sweep(backend, ["sweep", "s.toml", "--out", "store", "--workers", "2"], folder,
                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        if moment is None:
            deadline = time.time() + 120
            while time.time() < deadline and len(session(proc.pid)) < 3:
                time.sleep(0.01)
            if len(session(proc.pid)) < 3:
                return "the workers never started"
        else:
            time.sleep(moment)
            if proc.poll() is not None:
                return "the sweep ended before the kill"
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    finally:
        left = settle(proc.pid, 10)
    return f"{len(left)} processes outlived the driver by 10 s" if left else None


REAPED = """
import subprocess, sys, time
import pool_kills
reaper = pool_kills.reaper({backend!r})
time.sleep(2.0)  # the watcher has started (its imports take 0.2-0.3 s here, more under load)
grandchild = ("import subprocess, sys, time; p = subprocess.Popen([sys.executable, '-c', 'import time; "
              "time.sleep(120)']); print(p.pid, flush=True); time.sleep(120)")
middle = subprocess.Popen([sys.executable, "-c", grandchild], stdout=subprocess.PIPE, text=True)
print(middle.pid, middle.stdout.readline().strip(), flush=True)
time.sleep(120)
"""


def reaper(backend: str):
    """Our reaper, its watcher walking the process tree with /proc (ours) or psutil."""
    import subprocess as sp

    from armtransfer.parallel.reaper import Reaper

    if backend == "ours":
        return Reaper()
    r = Reaper.__new__(Reaper)
    r.proc = sp.Popen([sys.executable, "-c", "import pool_kills; pool_kills.psutil_watcher()"], stdin=sp.PIPE,
                      text=True, start_new_session=True, stdout=sp.DEVNULL, stderr=sp.DEVNULL)
    assert r.proc.stdin is not None
    r.stdin = r.proc.stdin
    return r


def psutil_watcher() -> None:
    """The reaper's watcher with psutil's process tree in place of its /proc walk."""
    import psutil

    from armtransfer.parallel import reaper as module

    def descendants(pids: set[int]) -> set[int]:
        out = set()
        for pid in pids:
            try:
                out.add(pid)
                out.update(c.pid for c in psutil.Process(pid).children(recursive=True)
                           if c.status() != psutil.STATUS_ZOMBIE)
            except psutil.NoSuchProcess:
                out.discard(pid)
        return out

    def start_time(pid: int) -> str | None:
        try:
            return repr(psutil.Process(pid).create_time())
        except psutil.NoSuchProcess:
            return None

    module.descendants = descendants  # type: ignore[assignment]
    module.start_time = start_time  # type: ignore[assignment]
    module.main()


def _gone(pid: int) -> bool:
    fields = _stat(pid)
    return fields is None or fields[0] == "Z"


def orphan(backend: str, folder: Path) -> str | None:
    driver = _python(REAPED.format(backend=backend), folder, stdout=subprocess.PIPE)
    try:
        assert driver.stdout is not None
        middle, child = map(int, driver.stdout.readline().split())
        time.sleep(2.5)  # two of the watcher's looks at least
        os.kill(middle, signal.SIGKILL)
        os.kill(driver.pid, signal.SIGKILL)
        driver.wait()
        deadline = time.time() + 10
        while time.time() < deadline and not _gone(child):
            time.sleep(0.02)
        gone = _gone(child)
    finally:
        left = settle(driver.pid, 5)
    if not gone:
        return "the orphan outlived the killed sweep"
    return f"{len(left)} processes left" if left else None


# --- the table -------------------------------------------------------------------------------

def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="one moment per case")
    parser.add_argument("--only", default="", help="only the cases whose name contains this")
    args = parser.parse_args()
    start_delays = [0.4] if args.quick else [0.01, 0.4, 1.0, 3.0]
    moments = [0.8] if args.quick else [0.05, 0.3, 0.8, 1.5, 2.5, 4.0]
    cases: list[tuple[str, Callable[[str, Path], str | None]]] = []
    tries = 2 if args.quick else 10
    cases.append((f"worker SIGKILLed as it appears (0 s), {tries} times in a row",
                  lambda b, f: in_a_row(b, tries, f)))
    for d in start_delays:
        cases.append((f"worker SIGKILLed {d:g} s after it appears", lambda b, f, d=d: kill_a_starting_worker(b, d, f)))
    cases.append(("a worker dies on its first run", lambda b, f: in_process(b, "dies", f)))
    cases.append(("a run raises, a result cannot be sent back", lambda b, f: in_process(b, "raises", f)))
    cases.append(("Ctrl-C to a working sweep's group", ctrl_c))
    cases.append(("driver SIGKILLed while its workers start", lambda b, f: kill_driver(b, None, f)))
    for m in moments:
        cases.append((f"driver SIGKILLed at {m:g} s of a sweep", lambda b, f, m=m: kill_driver(b, m, f)))
    cases.append(("an orphan goes with a killed sweep (reaper: /proc or psutil)", orphan))

    print("| case | ours (pool.py + reaper.py) | loky 3.7, robots once per worker (+ psutil) "
          "| loky 3.7, robots with every run |")
    print("|---|---|---|---|")
    failures = {b: 0 for b in BACKENDS}
    cases = [(name, case) for name, case in cases if args.only in name]
    for name, case in cases:
        row = []
        for backend in BACKENDS:
            if case is orphan and backend == "loky-per-task":
                row.append("(as the column before)")
                continue
            with tempfile.TemporaryDirectory() as folder:
                t0 = time.monotonic()
                problem = case(backend, Path(folder))
                secs = time.monotonic() - t0
            failures[backend] += problem is not None
            row.append(f"pass ({secs:.1f} s)" if problem is None else f"**fail**: {problem}")
        print(f"| {name} | {' | '.join(row)} |", flush=True)
    print()
    print("failed: " + ", ".join(f"{b} {n} of {len(cases)}" for b, n in failures.items()))


if __name__ == "__main__":
    main()
