"""Writing results so that nothing half-written is ever taken for a result."""

from __future__ import annotations

import fcntl
import json
import math
import os
import shutil
import stat
import tempfile
import time
import tomllib
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
    try:
        os.stat(out)
    except FileNotFoundError:
        pass
    except OSError as err:
        raise path_error(err, out, "write") from None
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise OutputError(f"output directory {str(out)!r} exists and is not empty; choose a new {flag}")
    check_writable(out / "results.json")


STAGING_SUFFIX = ".tmp"
"""A staging directory is ``.<out name>.<random>.tmp`` beside ``out``."""


@contextmanager
def staged_directory(out: str | os.PathLike, flag: str = "--out") -> Iterator[Path]:
    """A hidden temporary directory beside ``out`` to write every output into; renamed onto
    ``out`` when the block ends without an error, deleted otherwise. So an output directory
    exists only complete, whatever stops the run (an error, Ctrl-C, a kill before the rename).

    ``out`` is resolved first (a symlink to an empty folder is written through, into that
    folder's place). While the block runs, ``out`` exists, empty and locked: a second run into
    the same ``out`` is refused in one line at once, not after all its work. Staging
    directories of runs that were killed are removed (see :func:`clean_stale_staging`)."""
    out = Path(os.path.realpath(Path(out).expanduser()))
    check_output_dir(out, flag)
    created = out  # the highest directory this creates, removed again if the run fails
    while not created.parent.exists():
        created = created.parent
    made = not created.exists()
    try:
        out.mkdir(parents=True, exist_ok=True)
        fd = os.open(out, os.O_RDONLY | os.O_DIRECTORY)
    except OSError as err:
        raise OutputError(f"cannot write {str(out)!r}: {err.strerror}") from None
    tmp: Path | None = None
    done = False
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            made = False  # it is the other run's
            raise OutputError(f"another run is writing into {str(out)!r}; choose a new {flag}") from None
        check_output_dir(out, flag)  # a run that finished while this one waited filled it
        clean_stale_staging(out)
        try:
            tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=STAGING_SUFFIX, dir=out.parent))
        except OSError as err:
            raise OutputError(f"cannot write {str(out)!r}: {err.strerror}") from None
        _mark_owner(tmp)
        yield tmp
        try:
            (tmp / OWNER).unlink()
            os.chmod(tmp, 0o777 & ~_UMASK)  # as a directory made by mkdir, not mkdtemp's 0700
            os.replace(tmp, out)  # onto the empty, locked directory: atomic
        except OSError as err:
            raise OutputError(f"cannot write {str(out)!r}: {err.strerror or err}") from None
        done = True
    finally:
        os.close(fd)
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
        if made and not done:
            shutil.rmtree(created, ignore_errors=True)


OWNER = ".owner"
"""A staging directory's file naming the process that writes it (its pid and start time)."""


def _process_start(pid: int) -> str | None:
    """The start time of process ``pid`` (field 22 of /proc/PID/stat), None when it is gone."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return stat.rpartition(")")[2].split()[19]


def _running(pid: int, start: str) -> bool:
    """Whether process ``pid`` that started at ``start`` still runs (a pid taken again by a
    later process does not count; without /proc the pid alone is asked)."""
    if start != "None":
        return _process_start(pid) == start
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def _mark_owner(tmp: Path) -> None:
    pid = os.getpid()
    (tmp / OWNER).write_text(f"{pid} {_process_start(pid)}\n")


def clean_stale_staging(out: str | os.PathLike) -> list[Path]:
    """Remove the staging directories beside ``out`` whose run is gone (killed before it could
    clean up); returns them. A staging directory names its owner (:data:`OWNER`): one of any
    output whose owner is no longer running is removed, one whose owner runs is left alone,
    and one of ``out`` itself without an owner file (a run killed before it wrote it) is
    removed once it is :data:`STALE_SECONDS` old."""
    out = Path(out)
    removed = []
    for tmp in out.parent.glob(f".*{STAGING_SUFFIX}"):
        if not tmp.is_dir() or tmp.is_symlink():
            continue
        try:
            pid, start = (tmp / OWNER).read_text().split()
            stale = not _running(int(pid), start)
        except (OSError, ValueError):
            try:
                stale = tmp.name.startswith(f".{out.name}.") and time.time() - tmp.stat().st_mtime > STALE_SECONDS
            except OSError:
                stale = False
        if stale:
            shutil.rmtree(tmp, ignore_errors=True)
            removed.append(tmp)
    return removed


STALE_SECONDS = 60.0
"""A staging directory without an owner file is taken for a killed run's after this long."""


def check_distinct_outputs(files: dict[str, object], dirs: dict[str, object] | None = None) -> None:
    """Before any work: no two outputs on one path, and no output file inside an output
    directory (whose staging would replace it, or which it would keep from being renamed into
    place). ``files``/``dirs`` map a flag to its path (None: not given); paths are resolved,
    symlinks included, so two spellings of one file are one file."""
    resolved: list[tuple[str, Path, bool]] = []
    for is_dir, group in ((False, files), (True, dirs or {})):
        for flag, value in group.items():
            if value is not None:
                resolved.append((flag, Path(os.path.realpath(Path(str(value)).expanduser())), is_dir))
    for i, (flag, path, is_dir) in enumerate(resolved):
        for other, opath, other_dir in resolved[i + 1:]:
            if path == opath:
                raise OutputError(f"{flag} and {other} name the same path {str(path)!r}; give each its own")
            for (f1, p1, d1), (f2, p2) in (((flag, path, is_dir), (other, opath)),
                                           ((other, opath, other_dir), (flag, path))):
                if d1 and p1 in p2.parents:
                    raise OutputError(f"{f2} {str(p2)!r} is inside the output directory {f1} {str(p1)!r}; "
                                      "put it elsewhere")


def path_error(err: OSError, path: str | os.PathLike | None = None, verb: str = "use") -> OutputError:
    """An OS error on a path (a name too long, a full or read-only disk, no permission, a file
    where a folder belongs, ...) as one line naming the path: ``cannot use 'PATH': REASON``."""
    where = path if path is not None else err.filename
    if where is None:
        return OutputError(f"cannot {verb} a file: {err.strerror or err}")
    shown = os.fsdecode(where) if isinstance(where, bytes) else str(where)
    if len(shown) > 120:  # a name too long to use is too long to show whole
        shown = f"{shown[:60]}...{shown[-40:]} ({len(shown)} characters)"
    return OutputError(f"cannot {verb} {shown!r}: {err.strerror or err}")


def check_writable(path: str | os.PathLike) -> None:
    """Fail early (before any work) when ``path`` cannot be created: its nearest existing
    directory must take a new file (tried for real: permission bits say nothing for root or
    for special file systems such as /proc)."""
    p = Path(path)
    try:
        os.stat(p)  # a name too long, a loop of links, ... (a missing file is fine)
    except FileNotFoundError:
        pass
    except OSError as err:
        raise path_error(err, p, "write") from None
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


MAX_DIGITS = 40
"""The most digits an integer in a file may have (Python refuses 4,300 with a bare ValueError)."""

MAX_FILE_INT = 2**64
"""The largest integer magnitude a user's file may hold: every count and seed of the project is
far below it; a larger one is refused as the file is read, before any check sees it."""


def _int_of(text: str) -> int:
    digits = len(text.lstrip("+-"))
    if digits > MAX_DIGITS:
        raise ValueError(f"holds an integer of {digits} digits; no value of this project has more than {MAX_DIGITS}")
    return int(text)


def parse_json_bytes(raw: bytes) -> object:
    """JSON from a file's bytes; ValueError with the reason (not UTF-8, not JSON, nested too
    deeply, an integer of more than :data:`MAX_DIGITS` digits) for anything else. Every JSON file
    this project reads goes through here."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError("is not UTF-8 text") from None
    try:
        return json.loads(text, parse_int=_int_of)
    except json.JSONDecodeError as err:
        raise ValueError(f"is not valid JSON (line {err.lineno}: {err.msg})") from None
    except RecursionError:
        raise ValueError("nests too deeply to be a file of this project") from None
    except ValueError as err:  # an integer too long, from _int_of or Python's own limit
        raise ValueError(str(err).splitlines()[0] if str(err).startswith("holds") else
                         f"holds a number that cannot be read ({str(err).splitlines()[0]})") from None


def parse_toml_bytes(raw: bytes) -> dict:
    """TOML from a file's bytes, as :func:`parse_json_bytes` does JSON (the same reasons), and
    its numbers checked as a user's file's (:func:`check_user_numbers`)."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError("is not UTF-8 text") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ValueError(f"is not valid TOML: {str(err).splitlines()[0]}") from None
    except RecursionError:
        raise ValueError("nests too deeply to be a file of this project") from None
    except ValueError as err:  # Python's limit on the digits of an integer
        raise ValueError(f"holds a number that cannot be read ({str(err).splitlines()[0]})") from None
    check_user_numbers(data)
    return data


def parse_user_file_bytes(raw: bytes, suffix: str) -> object:
    """A user's TOML (``suffix`` ``.toml``) or JSON file from its bytes, by the readers above,
    its numbers checked (:func:`check_user_numbers`); ValueError with the reason."""
    if suffix.lower() == ".toml":
        return parse_toml_bytes(raw)
    data = parse_json_bytes(raw)
    check_user_numbers(data)
    return data


def check_user_numbers(data: object) -> None:
    """ValueError naming the first number of a user's parsed file that no value of the project
    can be: an integer of magnitude above :data:`MAX_FILE_INT` or more than :data:`MAX_DIGITS`
    digits, a float that is not finite (inf, nan, 1e999)."""
    stack = [data]
    while stack:
        item = stack.pop()
        if isinstance(item, dict):
            stack.extend(item.values())
        elif isinstance(item, list):
            stack.extend(item)
        elif isinstance(item, bool):
            continue
        elif isinstance(item, int) and abs(item) > MAX_FILE_INT:
            digits = len(str(abs(item))) if abs(item) < 10**MAX_DIGITS else f"more than {MAX_DIGITS}"
            raise ValueError(f"holds an integer of {digits} digits, beyond any value of this project "
                             f"(at most {MAX_FILE_INT})")
        elif isinstance(item, float) and not math.isfinite(item):
            raise ValueError(f"holds the number {item!r}; every number in it must be finite")


def read_json(path: str | os.PathLike, what: str, error: type[ArmTransferError]) -> object:
    """Parse a JSON file; an unreadable or malformed one raises ``error`` with one line
    naming ``what`` ("trajectory file", "mapping file", ...) and the problem."""
    p = Path(path)
    raw = read_input(p, what, error)
    try:
        return parse_json_bytes(raw)
    except ValueError as err:
        raise error(f"{what} {str(p)!r} {err}") from None


MAX_INPUT_BYTES = 16 * 2**20
"""The largest input file read (a trajectory, a mapping, a sweep file, an arm file): 16 MiB,
far above any real one; a larger file is refused before it is read."""

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _refuse_unless_regular(st: os.stat_result, p: Path, what: str, error: type[ArmTransferError], limit: int) -> None:
    if not stat.S_ISREG(st.st_mode):
        kind = next((name for test, name in _KINDS if test(st.st_mode)), "not a regular file")
        raise error(f"{what} {str(p)!r} is {kind}, not a regular file")
    if st.st_size > limit:
        raise error(f"{what} {str(p)!r} is {st.st_size:,} bytes, over the bound of {limit:,} bytes for an input file")


def check_input(path: str | os.PathLike, what: str, error: type[ArmTransferError], limit: int = MAX_INPUT_BYTES) -> Path:
    """``path`` when it is a regular file (links followed) of at most ``limit`` bytes, for a
    reader that opens it itself (MuJoCo's); else ``error``, one line naming ``what``, the path
    and the problem: a FIFO would hang the reader, a device or a padded file read without
    bound. Nothing is opened."""
    p = Path(path)
    try:
        st = os.stat(p)
    except OSError as err:
        raise error(f"cannot read {what} {str(p)!r}: {err.strerror or err}") from None
    _refuse_unless_regular(st, p, what, error, limit)
    return p


def read_input(path: str | os.PathLike, what: str, error: type[ArmTransferError], limit: int = MAX_INPUT_BYTES) -> bytes:
    """The bytes of the input file ``path``: opened only when it is a regular file (without
    blocking, so a FIFO is refused, not waited on) and read only up to ``limit`` bytes. Every
    input file this project reads goes through here (or :func:`check_input`); anything else is
    ``error``, one line naming ``what`` ("trajectory file", "sweep file", ...) and the path."""
    p = Path(path)
    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as err:
        raise error(f"cannot read {what} {str(p)!r}: {err.strerror or err}") from None
    try:
        _refuse_unless_regular(os.fstat(fd), p, what, error, limit)
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(limit + 1)
    except OSError as err:
        raise error(f"cannot read {what} {str(p)!r}: {err.strerror or err}") from None
    finally:
        os.close(fd)
    if len(data) > limit:  # it grew after the check
        raise error(f"{what} {str(p)!r} is over the bound of {limit:,} bytes for an input file")
    return data
