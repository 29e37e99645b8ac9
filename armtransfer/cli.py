"""The ``armtransfer`` command: one subcommand per module in ``armtransfer/commands``.

Every error a user can cause is an ``ArmTransferError`` (or an argparse error) and ends as
one line on stderr with exit code 2; anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from armtransfer import script as _script
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


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="armtransfer", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name, module_name in COMMANDS.items():
        module = importlib.import_module(f"armtransfer.commands.{module_name}")
        p = sub.add_parser(name, help=module.HELP, description=module.HELP)
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
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
    # Offscreen rendering needs the GL backend chosen before mujoco is first imported.
    os.environ.setdefault("MUJOCO_GL", "egl")
    argv = sys.argv[1:] if argv is None else list(argv)
    command = next((a for a in argv if a in COMMANDS), "")
    try:
        return _main(argv)
    except KeyboardInterrupt:  # Ctrl-C anywhere, start-up (imports, parsing) included
        print(f"armtransfer{' ' + command if command else ''}: interrupted", file=sys.stderr)
        return 130


def _main(argv: list[str]) -> int:
    from armtransfer.errors import ArmTransferError

    parser = build_parser()
    args = parser.parse_args(_join_xy_values(argv))
    try:
        return int(args._run(args) or 0)
    except ArmTransferError as err:
        print(f"armtransfer {args.command}: error: {err}", file=sys.stderr)
        return 2


def run() -> None:
    """The console script and ``python -m armtransfer.cli``: ``main``, then exit with its code
    (``script.exit_with``: quiet when stdout's reader goes away; 130 after Ctrl-C)."""
    _script.exit_with(main)


if __name__ == "__main__":
    run()
