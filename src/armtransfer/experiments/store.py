"""A result store that loses nothing: one JSON file per finished run, written atomically.

    DIR/sweep.json          the sweep this directory belongs to (its normalised spec and key)
    DIR/runs/<key>.json     one finished run: its full configuration and its result
    DIR/failed/<key>.json   a run that failed every attempt, with the error
    DIR/timings/<key>.json  how long the finished run took (wall clock, kept out of its run
                            file so that the same sweep writes the same run files, byte for byte)

A benchmark's store (``armtransfer benchmark``) is the same: its sweep.json names the suite and
seed, and its runs are robot 1's learning and single trials (``experiments.benchmark_runs``).

A run file appears only by ``os.replace`` of a complete temporary file, so after a crash
(even ``kill -9``) every run file present is whole, and a run without one is simply not
done. Temporary files a crash leaves behind start with '.' and are removed on open.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, cast

from armtransfer.errors import ArmTransferError
from armtransfer.io import OutputError, check_writable, parse_json_bytes, read_input, write_json_atomic
from armtransfer.experiments import frames
from armtransfer.experiments.run import Run
from armtransfer.experiments.sweep import Sweep, SweepFileError, check_stored, content_key, expand
from armtransfer.learning.config import LearnerConfig

if TYPE_CHECKING:
    import pandas as pd

STORE_FORMAT = "armtransfer-store/1"
LOCK = ".lock"


class StoreError(ArmTransferError):
    """The output directory cannot hold this sweep."""


class ResultStore:
    def __init__(self, root: str | os.PathLike) -> None:
        self.root = Path(root)
        self.runs_dir = self.root / "runs"
        self.failed_dir = self.root / "failed"
        self.timings_dir = self.root / "timings"

    # -- opening -----------------------------------------------------------------------
    @classmethod
    def open_for(cls, root: str | os.PathLike, sweep: Sweep) -> "ResultStore":
        """Open ``root`` for ``sweep``: create it, or resume it if it holds the same sweep."""
        store = cls(root)
        meta_path = store.root / "sweep.json"
        if store.root.exists() and not store.root.is_dir():
            raise StoreError(f"output {str(store.root)!r} exists and is not a directory")
        if meta_path.exists():
            meta = store._read_meta()
            if meta.get("key") != sweep.key:
                raise StoreError(
                    f"output directory {str(store.root)!r} holds another sweep "
                    f"({meta.get('name')!r}); choose a new --out"
                )
        elif store.root.exists() and any(p.name != LOCK for p in store.root.iterdir()):
            raise StoreError(
                f"output directory {str(store.root)!r} is not empty and holds no sweep; choose a new --out"
            )
        created = _highest_missing(store.root)  # removed again if the store cannot be opened
        had_lock = os.path.lexists(store.root / LOCK)
        store.lock()
        try:
            if not meta_path.exists():
                write_json_atomic(meta_path, {"format": STORE_FORMAT, "name": sweep.name, "key": sweep.key,
                                              "spec": sweep.spec})
            for d in (store.runs_dir, store.failed_dir, store.timings_dir):
                try:
                    d.mkdir(parents=True, exist_ok=True)
                except OSError as err:
                    raise OutputError(f"cannot write {str(d)!r}: {err.strerror}") from None
                check_writable(d / "probe.json")  # before any run: a run's result is never lost to it
                for tmp in d.glob(".*.tmp"):
                    tmp.unlink(missing_ok=True)
        except BaseException:
            store.unlock(remove=not had_lock)  # a lock file that was there before stays, as everything else
            if created is not None:
                shutil.rmtree(created, ignore_errors=True)
            elif not had_lock:
                (store.root / LOCK).unlink(missing_ok=True)
            raise
        return store

    def lock(self) -> None:
        """Take the store for this process (an exclusive ``flock`` on DIR/.lock, held until the
        process ends or :meth:`unlock`), so two sweeps never write one store; the second is
        refused in one line. Temporary files are cleared only once the lock is held, so a live
        writer's files are never deleted. :meth:`unlock` removes the lock file, so a finished
        store has none; a lock taken on a file another process has just removed is taken again."""
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise OutputError(f"cannot write {str(self.root)!r}: {err.strerror}") from None
        def create() -> int:
            try:
                return os.open(self.root / LOCK, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as err:
                raise OutputError(f"cannot write {str(self.root)!r}: {err.strerror}") from None

        self._lock_fd: int | None = _flocked(
            self.root / LOCK, create, fcntl.LOCK_EX,
            f"store {str(self.root)!r} is in use by another sweep or summarize; wait for it or choose another --out")

    def unlock(self, remove: bool = True) -> None:
        """Release the store, and (``remove``) delete its lock file first, while it is held."""
        fd = getattr(self, "_lock_fd", None)
        if fd is not None:
            try:
                if remove:
                    (self.root / LOCK).unlink(missing_ok=True)  # removed while held: nobody else holds it
            except OSError:
                pass  # a store on a disk gone read-only keeps its lock file; it is taken again
            os.close(fd)  # closing the descriptor releases the flock
            self._lock_fd = None

    @contextmanager
    def reading(self) -> Iterator[None]:
        """Hold the store against writers while the block reads it (and writes its summary): a
        store a running sweep or benchmark holds is refused in one line (its report would race the
        writer's); a writer starting meanwhile is refused until the block ends."""
        path = self.root / LOCK

        def existing() -> int | None:
            try:
                return os.open(path, os.O_RDONLY)
            except FileNotFoundError:
                return None  # no writer has it; a writer creating it now is not waited for
            except OSError as err:
                raise StoreError(f"cannot read the lock of store {str(self.root)!r}: {err.strerror}") from None

        fd = _flocked(path, existing, fcntl.LOCK_SH, f"store {str(self.root)!r} is being written by a running sweep "
                      "or benchmark; summarize it when that has finished")
        try:
            yield
        finally:
            if fd is not None:
                os.close(fd)

    @classmethod
    def open_existing(cls, root: str | os.PathLike) -> "ResultStore":
        store = cls(root)
        if not (store.root / "sweep.json").is_file():
            raise StoreError(f"{str(store.root)!r} holds no sweep (no sweep.json)")
        store._read_meta()
        return store

    def _read_meta(self) -> dict:
        path = self.root / "sweep.json"
        try:
            meta = parse_json_bytes(read_input(path, "sweep.json", StoreError))
        except (StoreError, ValueError):
            raise StoreError(f"{str(path)!r} is unreadable; this is not a sweep directory") from None
        if not isinstance(meta, dict) or meta.get("format") != STORE_FORMAT:
            raise StoreError(f"{str(path)!r} is not an armtransfer sweep")
        for field, kind in (("name", str), ("key", str)):
            if not isinstance(meta.get(field), kind) or not meta[field]:
                raise StoreError(f"{str(path)!r}: field {field!r} must be a non-empty string, got "
                                 f"{meta.get(field)!r:.60}")
        if is_benchmark(meta.get("spec")):  # a benchmark's plan: its key below vouches for it
            if not isinstance(meta["spec"]["benchmark"], dict):
                raise StoreError(f"{str(path)!r}: field 'spec': benchmark must be a table")
        else:
            try:
                check_stored(meta.get("spec"), repr(str(path)))
            except SweepFileError as err:
                raise StoreError(str(err)) from None
        if content_key(meta["spec"]) != meta["key"]:
            raise StoreError(f"{str(path)!r}: field 'spec' does not match field 'key' (the file was edited); "
                             "this store cannot be trusted")
        return meta

    @property
    def meta(self) -> dict:
        return self._read_meta()

    # -- runs --------------------------------------------------------------------------
    def run_path(self, key: str) -> Path:
        return self.runs_dir / f"{key}.json"

    def load_run(self, key: str) -> dict | None:
        """A finished run, or None when it is absent. A run file that cannot be read or has
        the wrong shape is reported on stderr and set aside into DIR/bad/ (so the run is
        redone), never fatal."""
        path = self.run_path(key)
        if not os.path.lexists(path):
            return None
        try:
            raw = read_input(path, "run file", StoreError)
        except StoreError as err:  # a FIFO, a device, a folder, no permission, beyond the bound
            self._set_aside(path, f"cannot be read ({str(err).rpartition(repr(str(path)))[2].strip(' :')})")
            return None
        try:
            record = parse_json_bytes(raw)
        except ValueError as err:
            self._set_aside(path, str(err))
            return None
        problem = _run_problem(record, key)
        if problem:
            self._set_aside(path, problem)
            return None
        return cast(dict, record)  # _run_problem found it a whole run record

    def _set_aside(self, path: Path, why: str) -> None:
        bad = self.root / "bad"
        try:
            bad.mkdir(exist_ok=True)
            os.replace(path, bad / path.name)
            where = f"moved to {str(bad / path.name)!r}"
        except OSError:
            where = "left in place"
        print(f"armtransfer: run file {str(path)!r} {why}; {where}, the run will be redone", file=sys.stderr)
        return None

    def is_done(self, key: str) -> bool:
        return self.load_run(key) is not None

    def write_run(self, run: Run, result: dict, elapsed: float) -> None:
        key = run.key()
        write_json_atomic(self.run_path(key), {"key": key, "config": run.stored(), "result": result})
        write_json_atomic(self.timings_dir / f"{key}.json", {"key": key, "elapsed_seconds": round(elapsed, 3)})
        (self.failed_dir / f"{key}.json").unlink(missing_ok=True)

    def write_failure(self, run: Run, error: str, attempts: int) -> None:
        """Record that ``run`` failed: ``error``'s first line, and the rest (a traceback, when the
        worker sent one) under ``traceback``."""
        first, _, rest = error.partition("\n")
        record = {"key": run.key(), "config": run.stored(), "error": first, "attempts": attempts}
        if rest.strip():
            record["traceback"] = rest
        write_json_atomic(self.failed_dir / f"{run.key()}.json", record)

    def records(self) -> list[dict]:
        """Every finished run, sorted by key (so summaries do not depend on finishing order)."""
        out = []
        for path in sorted(self.runs_dir.glob("*.json")):
            rec = self.load_run(path.stem)
            if rec is not None:
                out.append(rec)
        return out

    def to_frame(self) -> "pd.DataFrame":
        """Every finished trial as a tidy pandas DataFrame (a matrix's store too): one row per
        trial of each run, its per-trial metrics (exploration, total and greedy steps,
        convergence, episodes, the K used, the step cap a trial that never reached the goal is
        censored at), then the run's settings (``run`` is its key; task, start and goal cells,
        source, target, method, seed, trials, wind, learner settings, the K asked for). The
        runs that failed or are not done yet are named in ``df.attrs`` (``failed``, ``missing``),
        so a partial store is never mistaken for a whole one. Needs pandas
        (``pip install 'armtransfer[frames]'``)."""
        if is_benchmark(self.meta["spec"]):
            raise StoreError(f"{str(self.root)!r} holds a benchmark, whose trials are in its results.json "
                             "(armtransfer summarize DIR writes it)")
        frames.pandas()
        rows, done = [], set()
        for rec in self.records():
            config, result = rec["config"], rec["result"]  # a stored run, read as the store holds it
            done.add(config["key"])
            settings = {("run" if k == "key" else k): v for k, v in config.items() if k != "format"}
            per_trial = {name: result[name] for name in (*RESULT_LISTS, "episodes") if name in result}
            per_trial["K_used"] = result.get("K")
            per_trial["trajectory_length"] = result.get("trajectory_length")
            per_trial["step_cap"] = int(config.get("max_total_steps", LearnerConfig.max_total_steps))
            rows += frames.trial_rows(config["method"], None, per_trial, settings)
        df = frames.frame(rows)
        failed = sorted(f["key"] for f in self.failures() if f.get("key") not in done)
        every = [run.key() for run in expand(self.meta["spec"])]
        df.attrs.update(runs=len(every), failed=failed,
                        missing=[k for k in every if k not in done and k not in failed])
        return df

    def failures(self) -> list[dict]:
        """Every failed run's record, checked: a record that cannot be read, or whose ``key``,
        ``config`` or ``error`` is missing or of the wrong kind, is a ``StoreError`` naming the
        file and the field."""
        out = []
        for path in sorted(self.failed_dir.glob("*.json")):
            try:
                record = parse_json_bytes(read_input(path, "failed record", StoreError))
            except ValueError as err:
                raise StoreError(f"failed record {str(path)!r} {err}") from None
            problem = _failure_problem(record, path.stem)
            if problem:
                raise StoreError(f"failed record {str(path)!r}: {problem}")
            out.append(cast(dict, record))
        return out


def _highest_missing(path: Path) -> Path | None:
    """The highest folder of ``path`` that does not exist yet (None: ``path`` exists)."""
    if os.path.lexists(path):
        return None
    top = path
    while not os.path.lexists(top.parent) and top.parent != top:
        top = top.parent
    return top
def is_benchmark(spec: object) -> bool:
    """Whether a store's spec is a benchmark's (``armtransfer benchmark``), not a sweep's."""
    return isinstance(spec, dict) and "benchmark" in spec


RESULT_LISTS = ("exploration_steps", "total_steps", "greedy_steps", "converged")


def _failure_problem(record: object, key: str) -> str | None:
    """What is wrong with a failed record (None: a failure record of run ``key``)."""
    if not isinstance(record, dict):
        return f"is not a table but {type(record).__name__}"
    if record.get("key") != key:
        return f"field 'key' must be the file's name {key!r}, got {record.get('key')!r:.60}"
    if not isinstance(record.get("config"), dict) or record["config"].get("key") != key:
        return "field 'config' must be the run's configuration, with its key"
    if not isinstance(record.get("error"), str):
        return f"field 'error' must be a string, got {type(record.get('error')).__name__}"
    return None


def _run_problem(record: object, key: str) -> str | None:
    """What is wrong with a run file's content (None: it is a whole run of ``key``)."""
    if not isinstance(record, dict) or record.get("key") != key:
        return f"is not a run record of {key}"
    if not isinstance(record.get("config"), dict) or record["config"].get("key") != key:
        return "has no configuration of its run"
    if content_key({k: v for k, v in record["config"].items() if k != "key"}) != key:
        return "has a configuration that does not match its key (it was edited)"
    result = record.get("result")
    if not isinstance(result, dict):
        return "has no result"
    if str(record["config"].get("format", "")).startswith("armtransfer-benchmark-"):
        from armtransfer.experiments.benchmark_runs import result_problem  # start-up: reading a store loads no kernel

        return result_problem(record["config"], result)
    lengths = set()
    for name in RESULT_LISTS:
        values = result.get(name)
        if not isinstance(values, list) or not all(v is None or isinstance(v, (int, float)) for v in values):
            return f"has no list of numbers {name!r}"
        lengths.add(len(values))
    if len(lengths) != 1:
        return "has result lists of different lengths"
    return None


def _flocked(path: Path, opener: Callable[[], int | None], mode: int, busy: str) -> int | None:
    """A descriptor ``opener`` opens on ``path``, flocked with ``mode`` without waiting and still
    the file at ``path`` (one its holder removed as this process opened it is opened again); None
    when ``opener`` finds no file. Held by another process: ``busy``, in one line."""
    while True:
        fd = opener()
        if fd is None:
            return None
        try:
            fcntl.flock(fd, mode | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise StoreError(busy) from None
        if _same_file(fd, path):
            return fd
        os.close(fd)


def _same_file(fd: int, path: Path) -> bool:
    """Whether ``fd`` is still the file at ``path`` (not one removed since it was opened)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return False
    here = os.fstat(fd)
    return (st.st_dev, st.st_ino) == (here.st_dev, here.st_ino)
