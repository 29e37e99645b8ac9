"""On-disk cache of compiled arm robots.

Location: ``$ARMTRANSFER_CACHE``, else ``$XDG_CACHE_HOME/armtransfer``, else
``~/.cache/armtransfer``. One ``.npz`` per robot, named by the robot and its key; the key
is a SHA-256 over everything the result depends on (the arm's MJCF bytes, mounting, action
model, workspace and the source of the compiling modules). Each file stores its full key
and a checksum of its arrays; a file that cannot be read, has another key (stale) or a
wrong checksum (corrupt) is rebuilt. Writes go to a temporary file that is then renamed
over the entry (``os.replace``), so readers never see half a file. A process that builds an
entry holds its lock (:func:`building`), so processes that want the same entry at once (sweep
workers, test workers, two runs) build it once: the others wait, then load it.
"""

from __future__ import annotations

import fcntl
import hashlib
import io
import json
import os
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

# the compiling modules, beside this one: a change to any of them is a new key
_SOURCES = ("compile.py", "seeds.py", "solve.py", "scene.py", "labels.py", "workspace.py", "tool.py", "mount.py",
            "quick.py", "sweep.py", "voxels.py")
_HERE = Path(__file__).resolve().parent


def cache_dir() -> Path:
    if os.environ.get("ARMTRANSFER_CACHE"):
        return Path(os.environ["ARMTRANSFER_CACHE"])
    if os.environ.get("XDG_CACHE_HOME"):
        return Path(os.environ["XDG_CACHE_HOME"]) / "armtransfer"
    return Path.home() / ".cache" / "armtransfer"


def cache_key(parts: dict) -> str:
    """SHA-256 of ``parts`` (JSON-able) plus the source of the compiling modules."""
    h = hashlib.sha256(json.dumps(parts, sort_keys=True, default=str).encode())
    for name in _SOURCES:
        h.update((_HERE / name).read_bytes())
    return h.hexdigest()


def entry_path(name: str, key: str) -> Path:
    safe = "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in name)
    return cache_dir() / f"{safe}-{key[:16]}.npz"


def _checksum(arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(name.encode())
        h.update(str(a.dtype).encode())
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def read_regular(path: Path) -> bytes | None:
    """The bytes of ``path`` when it is a regular file (symlinks followed), None otherwise:
    a directory, a FIFO (which would hang a reader), a device, or nothing."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        with os.fdopen(fd, "rb", closefd=False) as f:
            return f.read()
    except OSError:
        return None
    finally:
        os.close(fd)


def clear(path: Path) -> None:
    """Remove whatever is at ``path`` that is not a regular file (a directory, a FIFO, a
    dangling link), so a new entry can be renamed onto it."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    if stat.S_ISDIR(mode):
        shutil.rmtree(path, ignore_errors=True)
    elif not stat.S_ISREG(mode):
        path.unlink(missing_ok=True)


def load(name: str, key: str, check: Callable[[dict[str, np.ndarray]], bool] | None = None,
         ) -> tuple[dict[str, np.ndarray] | None, str]:
    """(arrays, status): status is "hit", "miss" (no entry) or "stale"/"corrupt". An entry
    that is not a regular file, or whose arrays ``check`` refuses, is "corrupt"."""
    path = entry_path(name, key)
    if not os.path.lexists(path):
        return None, "miss"
    raw = read_regular(path)
    if raw is None:
        return None, "corrupt"
    try:
        with np.load(io.BytesIO(raw), allow_pickle=False) as f:
            arrays = {k: f[k] for k in f.files}
        stored_key = str(arrays.pop("__key__"))
        stored_sum = str(arrays.pop("__checksum__"))
    except Exception:  # noqa: BLE001 - any unreadable entry is simply rebuilt
        return None, "corrupt"
    if stored_key != key:
        return None, "stale"
    if stored_sum != _checksum(arrays):
        return None, "corrupt"
    try:
        if check is not None and not check(arrays):
            return None, "corrupt"
    except Exception:  # noqa: BLE001 - arrays of the wrong kind are as corrupt as wrong bytes
        return None, "corrupt"
    return arrays, "hit"


def save(name: str, key: str, arrays: dict[str, np.ndarray]) -> Path:
    path = entry_path(name, key)
    path.parent.mkdir(parents=True, exist_ok=True)
    clear(path)
    payload: dict[str, Any] = dict(arrays)  # np.savez's keywords are arrays, not its own options
    payload["__key__"] = np.array(key)
    payload["__checksum__"] = np.array(_checksum(arrays))
    fd, tmp = tempfile.mkstemp(prefix=path.stem + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            np.savez(f, **payload)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


@contextmanager
def building(entry: Path) -> Iterator[None]:
    """Hold the build lock of cache entry ``entry`` (a file ``<entry>.lock`` beside it) for as
    long as the block runs; another process asking for the same lock waits until then."""
    entry.parent.mkdir(parents=True, exist_ok=True)
    lock_path = entry.with_name(entry.name + ".lock")
    clear(lock_path)  # a FIFO there would hang the open
    with open(lock_path, "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)
