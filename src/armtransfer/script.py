"""What the scripts under ``scripts/`` share with the ``armtransfer`` command: its error contract.

Every error a user can cause (an ``ArmTransferError`` or a bad argument) ends as one line on
stderr with exit code 2, and nothing is left half-written; anything else is a bug and keeps
its traceback."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable
from typing import NoReturn

from armtransfer.environment import check_environment
from armtransfer.errors import ArmTransferError


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (the usage is in --help)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message}\n")


def parser(doc: str | None) -> OneLineParser:
    """A script's argument parser, described by the first line of its docstring ``doc``."""
    return OneLineParser(description=doc.strip().splitlines()[0] if doc and doc.strip() else None)


def run(body: Callable[..., int | None], *args) -> int:
    """``body(*args)``'s exit code, or 2 after one line on stderr for an ``ArmTransferError``."""
    try:
        check_environment()  # before anything is written, as the command does
        return int(body(*args) or 0)
    except ArmTransferError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


def stdout_closed() -> int:
    """The reader of stdout went away (``... | head``): nothing more can be shown, and that is
    not the program's error. Later writes, and the interpreter's last flush, go to /dev/null so
    that no traceback follows; the exit code is a shell's for a write to a closed pipe, 141."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
    return 141


class StdoutError(Exception):
    """stdout cannot be written (a full disk, ``>/dev/full``, an I/O error); the one line."""


class GuardedStdout:
    """sys.stdout for :func:`exit_with`: a write or flush that fails with an OS error other
    than a closed pipe raises :class:`StdoutError` once (one line, not a traceback; argparse's
    --help and --version would swallow an OSError and exit 0 with their text lost), and every
    later write is dropped. Characters the stream cannot encode (``PYTHONIOENCODING=ascii``)
    are written escaped (``\xe9``) instead of raising."""

    def __init__(self, stream) -> None:
        self._stream = stream
        self.failed: StdoutError | None = None
        try:
            stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError, OSError):
            pass

    def _guard(self, call, *args):
        if self.failed is not None:
            return None
        try:
            return call(*args)
        except BrokenPipeError:
            raise
        except OSError as err:
            self.failed = StdoutError(f"cannot write to stdout: {err.strerror or err}")
            _discard_stdout(self._stream)
            raise self.failed from None

    def write(self, text: str) -> int:
        result = self._guard(self._stream.write, text)
        return len(text) if result is None else result

    def flush(self) -> None:
        self._guard(self._stream.flush)

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


def _discard_stdout(stream) -> None:
    """Point fd 1 at /dev/null and drop ``stream``'s buffer, so that the interpreter's last
    flush does not fail again (with a second message) at exit."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, stream.fileno())
        os.close(devnull)
        stream.flush()
    except (OSError, ValueError, AttributeError):
        pass


def exit_with(main: Callable[[], int | None]) -> NoReturn:
    """A script's (and the command's) ``__main__``: ``sys.exit(main())``, quiet when its
    reader stops reading.

    After Ctrl-C (``main`` returned 130) the exit is ``os._exit(130)``: a KeyboardInterrupt
    raised while a C extension runs Python code marks the interpreter, which then ends itself
    with SIGINT at shutdown even though ``main`` caught it, and the shell would see a signal
    instead of code 130."""
    prog = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] not in ("", "-c", "-m") else "armtransfer"
    if prog in ("__main__.py", "cli.py"):
        prog = "armtransfer"
    if sys.stdout is None:  # started with stdout closed (>&-): fd 1 may be any file opened later
        print(f"{prog}: error: stdout is closed; run it with stdout open (e.g. >/dev/null)", file=sys.stderr)
        sys.exit(2)
    stdout = sys.stdout = GuardedStdout(sys.stdout)
    code: str | int | None
    try:
        try:
            code = main()
        except SystemExit as e:  # --help, a usage error
            code = e.code
        sys.stdout.flush()  # inside the try: a closed pipe shows here, not at shutdown
    except BrokenPipeError:
        code = stdout_closed()
    except StdoutError as err:
        print(f"{prog}: error: {err}", file=sys.stderr)
        code = 2
    if stdout.failed is not None and code in (0, None):  # failed, and the failure was swallowed
        print(f"{prog}: error: {stdout.failed}", file=sys.stderr)
        code = 2
    if code == 130:
        sys.stderr.flush()
        os._exit(130)
    sys.exit(code)


def experiment_options(p: argparse.ArgumentParser, fast: str) -> None:
    """The options every experiment script takes: --trials (20), --seed (0), --out DIR for its
    .md and .json, and --fast (``fast`` says what its smoke run is)."""
    p.add_argument("--trials", type=int, default=20)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", required=True, help="an absent or empty directory for the .md and .json")
    p.add_argument("--fast", action="store_true", help=fast)


def check_trials_seed(trials: int, seed: int) -> None:
    """The trial count and seed every experiment script takes."""
    if trials < 1 or seed < 0:
        raise ArmTransferError("--trials must be >= 1 and --seed >= 0")
