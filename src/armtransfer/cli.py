"""The ``armtransfer`` command: a subcommand per job, each defined by a module of
``armtransfer.commands`` (``add_arguments``, ``run``, a one-sentence ``HELP`` and an ``EXAMPLE``).

Every error a user can cause is an ``ArmTransferError`` (or an argparse error) and ends as
one line on stderr with exit code 2; anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import _thread
import argparse
import errno
import importlib
import re
import sys
import textwrap
import threading
import time
import warnings

from armtransfer import __version__, script as _script
from armtransfer.environment import check_environment
from armtransfer.errors import ArmTransferError
from armtransfer.io import path_error
from armtransfer.learning.lazy_registry import PluginWarning
from armtransfer.script import OneLineParser as _Parser  # a usage error is one line

# Subcommand name -> module in armtransfer.commands. Each module has
# ``add_arguments(parser)``, ``run(args) -> int`` and a one-line ``HELP``.
COMMANDS = {
    "rooms": "rooms",
    "reproduce": "reproduce",
    "bench": "bench",
    "sweep": "sweep",
    "summarize": "summarize",
    "arms": "arms",
    "matrix": "matrix",
    "benchmark": "benchmark",
}


DESCRIPTION = ("Transfer learning between robots that cannot imitate each other: a robot that solved a task "
               "hands over its trajectory, and a robot with other actions learns the task faster with it.")


def command_list(modules: dict) -> str:
    """The commands, what each is for and one example each, for the top-level help."""
    width = max(map(len, modules)) + 4
    lines = ["commands:"]
    for name, module in modules.items():
        text = textwrap.wrap(module.HELP, 88 - width)
        lines += [f"  {name:<{width - 2}}{text[0]}", *(" " * width + t for t in text[1:]),
                  " " * width + f"e.g. {module.EXAMPLE}"]
    return "\n".join(lines)


def build_parser() -> argparse.ArgumentParser:
    modules = {name: importlib.import_module(f"armtransfer.commands.{module}") for name, module in COMMANDS.items()}
    parser = _Parser(prog="armtransfer", usage="%(prog)s [-h] [--version] COMMAND ...", description=f"{textwrap.fill(DESCRIPTION, 88)}\n\n{command_list(modules)}",
                     epilog="'armtransfer COMMAND --help' lists a command's options.",
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"armtransfer {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser, help=argparse.SUPPRESS)
    sub.required = True
    for name, module in modules.items():
        p = sub.add_parser(name, description=module.HELP, epilog=f"example:\n  {module.EXAMPLE}",
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        module.add_arguments(p)
        p.set_defaults(_run=module.run, _parser=p)
    return parser


_XY_OPTIONS = ("--start", "--goal")


def _join_xy_values(argv: list[str]) -> list[str]:
    """Let ``--goal -8,12`` through: argparse would take '-8,12' for an option."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        if argv[i] in _XY_OPTIONS and i + 1 < len(argv) and argv[i + 1][:1] == "-" and argv[i + 1][1:2].isdigit():
            out.append(f"{argv[i]}={argv[i + 1]}")
            i += 2
        else:
            out.append(argv[i])
            i += 1
    return out


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    command = next((a for a in argv if a in COMMANDS), "")
    hook = _InterruptAgain(sys.unraisablehook)
    sys.unraisablehook = hook
    try:
        return _main(argv)
    except KeyboardInterrupt:  # Ctrl-C anywhere, start-up (imports, parsing) included
        print(f"armtransfer{' ' + command if command else ''}: interrupted", file=sys.stderr)
        return 130
    finally:
        hook.pending.clear()
        sys.unraisablehook = hook.previous


class _InterruptAgain:
    """An unraisable hook for :func:`main`: a Ctrl-C that lands in Python code a C library
    called back (numba's compiler calls llvmlite's callbacks through ctypes) cannot leave that
    callback; Python would print "Exception ignored" and go on as if nothing had happened.
    Here it is delivered to the main thread again, from a thread, every 50 ms until
    :func:`main` has answered it; anything else goes to the ``previous`` hook."""

    def __init__(self, previous) -> None:
        self.previous = previous
        self.pending = threading.Event()

    def __call__(self, unraisable) -> None:
        if not isinstance(unraisable.exc_value, KeyboardInterrupt):
            self.previous(unraisable)
        elif not self.pending.is_set():
            self.pending.set()
            threading.Thread(target=self._deliver, daemon=True).start()

    def _deliver(self) -> None:
        while True:
            time.sleep(0.05)  # let the main thread leave this hook first: raised in it, it is lost
            if not self.pending.is_set():
                return
            _thread.interrupt_main()


def _main(argv: list[str]) -> int:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PluginWarning)  # said here, in one line each
        try:
            parser = build_parser()
            _warn_left_out(argv)  # a broken plugin breaks only itself: the rest runs, with a warning
        except ArmTransferError as err:
            command = next((a for a in argv if a in COMMANDS), "")
            print(f"armtransfer{' ' + command if command else ''}: error: {err}", file=sys.stderr)
            return 2
        return _run(parser, argv)


def _warn_left_out(argv: list[str]) -> None:
    """One warning line for every installed plugin left out (it cannot be imported or used),
    naming it and how to remove it; none for a plugin the command line names, whose use is then
    its one-line error (unless it took a built-in's name, which names the built-in)."""
    # here, not at the top: main() answers a Ctrl-C while numba and Gymnasium load
    from armtransfer.learning.learners import LEARNERS
    from armtransfer.learning.methods import METHODS

    named = {word for arg in argv for word in re.split(r"[,=\s]+", arg)}
    for registry in (METHODS, LEARNERS):
        registry.ensure_loaded()
        for name, (_, warning) in registry.broken.items():
            if name not in named or name in registry.builtin:  # a built-in's name runs the built-in
                print(f"armtransfer: warning: {warning}", file=sys.stderr)


def _run(parser: argparse.ArgumentParser, argv: list[str]) -> int:
    args = parser.parse_args(_join_xy_values(argv))
    try:
        from armtransfer.commands.common import refuse_empty  # loaded by build_parser, inside main()

        refuse_empty(args)
        check_environment()  # before anything is written
        return int(args._run(args) or 0)
    except ArmTransferError as err:
        print(f"armtransfer {args.command}: error: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        if isinstance(err, BrokenPipeError) or not _on_a_path(err):
            raise  # a bug keeps its traceback
        print(f"armtransfer {args.command}: error: {path_error(err)}", file=sys.stderr)
        return 2


_DISK_ERRNOS = frozenset(getattr(errno, name) for name in ("ENOSPC", "EDQUOT", "EROFS", "EIO", "EFBIG")
                         if hasattr(errno, name))


def _on_a_path(err: OSError) -> bool:
    """Whether ``err`` is the file system's answer about a path the user chose (a name too
    long, no permission, a full or read-only disk, a file where a folder belongs, ...): one
    line naming the path, exit 2. Every path a command writes is checked before its work; this
    catches the ones the file system refuses anyway."""
    return err.filename is not None or err.errno in _DISK_ERRNOS


def run() -> None:
    """The console script and ``python -m armtransfer``: ``main``, then exit with its code
    (``script.exit_with``: quiet when stdout's reader goes away; 130 after Ctrl-C)."""
    _script.exit_with(main)


if __name__ == "__main__":
    run()
