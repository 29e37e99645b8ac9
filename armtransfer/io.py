"""Writing results so that nothing half-written is ever taken for a result."""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from armtransfer.errors import ArmTransferError, OutputError


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


_UMASK = _umask()


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to a temporary file beside ``path``, then rename it into place."""
    write_bytes_atomic(path, text.encode())


@contextmanager
def atomic_path(path: str | os.PathLike, suffix: str = ".tmp") -> Iterator[Path]:
    """A temporary path beside ``path`` to write to; on leaving the block without an error it
    is renamed onto ``path`` (readable as a normal new file), otherwise deleted. Every file
    this project writes goes through here, so nothing half-written is ever taken for a result.
    ``suffix`` keeps a file type that a writer infers from the name (``.tmp.mp4``)."""
    p = Path(path)
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=suffix, dir=p.parent)
        os.close(fd)
    except OSError as err:
        raise OutputError(f"cannot write {str(p)!r}: {err.strerror}") from None
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_UMASK)
        os.replace(tmp, p)
    except OSError as err:
        raise OutputError(f"cannot write {str(p)!r}: {err.strerror or err}") from None
    finally:
        Path(tmp).unlink(missing_ok=True)


def write_bytes_atomic(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to a temporary file beside ``path``, then rename it into place."""
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())


def copy_atomic(src: str | os.PathLike, path: str | os.PathLike) -> None:
    """Copy ``src`` to ``path`` through a temporary file beside it."""
    with atomic_path(path) as tmp:
        shutil.copyfile(src, tmp)


def write_json_atomic(path: str | os.PathLike, data: object) -> None:
    write_text_atomic(path, json.dumps(data, indent=2, sort_keys=False) + "\n")


def check_output_dir(out: str | os.PathLike, flag: str = "--out") -> None:
    """Fail early when ``out`` cannot become a new output directory: it must be absent or an
    empty directory, somewhere writable."""
    out = Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise OutputError(f"output directory {str(out)!r} exists and is not empty; choose a new {flag}")
    check_writable(out / "results.json")


@contextmanager
def staged_directory(out: str | os.PathLike, flag: str = "--out") -> Iterator[Path]:
    """A hidden temporary directory beside ``out`` to write every output into; renamed onto
    ``out`` when the block ends without an error, deleted otherwise. So an output directory
    exists only complete, whatever stops the run (an error, Ctrl-C, a kill before the rename)."""
    out = Path(out)
    check_output_dir(out, flag)
    created = out.parent  # the highest directory this creates, removed again if the run fails
    while not created.parent.exists():
        created = created.parent
    made = not created.exists()
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".tmp", dir=out.parent))
    except OSError as err:
        raise OutputError(f"cannot write {str(out)!r}: {err.strerror}") from None
    done = False
    try:
        yield tmp
        if out.exists():
            out.rmdir()  # empty, checked before
        os.replace(tmp, out)
        done = True
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        if made and not done:
            shutil.rmtree(created, ignore_errors=True)


def check_writable(path: str | os.PathLike) -> None:
    """Fail early (before any work) when ``path`` cannot be created: its nearest existing
    directory must take a new file (tried for real: permission bits say nothing for root or
    for special file systems such as /proc)."""
    p = Path(path)
    if p.is_dir():
        raise OutputError(f"cannot write {str(p)!r}: it is a directory")
    probe = p.parent if str(p.parent) else Path(".")
    while not probe.exists():
        probe = probe.parent
    if not probe.is_dir():
        raise OutputError(f"cannot write {str(p)!r}: {str(probe)!r} is not a directory")
    try:
        with tempfile.TemporaryFile(dir=probe):
            pass
    except OSError as err:
        raise OutputError(f"cannot write {str(p)!r}: {str(probe)!r} does not take new files "
                          f"({err.strerror or err})") from None


def parse_json_bytes(raw: bytes) -> object:
    """JSON from a file's bytes; ValueError with the reason (not UTF-8, not JSON, nested too
    deeply) for anything else. Every JSON file this project reads goes through here."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError("is not UTF-8 text") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as err:
        raise ValueError(f"is not valid JSON (line {err.lineno}: {err.msg})") from None
    except RecursionError:
        raise ValueError("nests too deeply to be a file of this project") from None


def read_json(path: str | os.PathLike, what: str, error: type[ArmTransferError]) -> object:
    """Parse a JSON file; an unreadable or malformed one raises ``error`` with one line
    naming ``what`` ("trajectory file", "mapping file", ...) and the problem."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except OSError as err:
        raise error(f"cannot read {what} {str(p)!r}: {err.strerror}") from None
    try:
        return parse_json_bytes(raw)
    except ValueError as err:
        raise error(f"{what} {str(p)!r} {err}") from None
