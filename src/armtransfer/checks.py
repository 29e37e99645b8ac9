"""Checks of values a user hands the library, each a one-line ``ArmTransferError`` on failure.

Numbers are checked by kind, not by Python type: numpy's integers and floats count as
integers and reals (``np.float32(0.1)`` is a learning rate), booleans count as neither, and
booleans are strictly ``True``/``False`` (``"no"`` is not false). Every count has an upper
bound, so a value far past any sensible run is refused before anything is built from it.
This module imports nothing of the project but its errors, so every layer can use it.
"""

from __future__ import annotations

import math
import numbers
import os
import re

from armtransfer.errors import ArmTransferError, InvalidParameterError

MAX_COUNT = 10**12
"""The largest count (steps, episodes, trials, ...) any argument may name: far past any run
this machine finishes, and well inside a 64-bit integer, so no count overflows downstream."""

MAX_TRIALS = 100_000
"""The most trials one run may have (each trial's results are kept in memory)."""
MAX_METRES = 100.0
"""The largest length in metres an arm's scene takes (a cell size, tool offset or base
position): far past any arm on a table, small enough that the scene's numbers stay well
inside MuJoCo's and mink's range (a tool offset of 1e300 overflowed in the IK)."""

ErrorType = type[ArmTransferError]

MAX_DIGITS = 40
"""The most digits an integer written in a spec or on a command line may have."""

_INTEGER = re.compile(r"[+-]?[0-9]{1,%d}" % MAX_DIGITS)


def integer_text(text: object, signed: bool = True) -> int | None:
    """The integer ``text`` writes, by the one grammar every spec of the project uses for an
    integer (a seed, a side, a task number, a cell's x and y): an optional sign (when
    ``signed``), then 1 to :data:`MAX_DIGITS` ASCII digits, nothing around them. None for
    anything else: what ``int()`` would refuse (a superscript '²') or read otherwise than it
    looks (Arabic-Indic digits, '1_000', spaces) is never accepted."""
    if not isinstance(text, str) or not _INTEGER.fullmatch(text) or (not signed and text[0] in "+-"):
        return None
    return int(text)


def whole(value: object, what: str, lo: int = 0, hi: int = MAX_COUNT,
          error: ErrorType = InvalidParameterError) -> int:
    """``value`` as a Python int in [lo, hi]; numpy integers accepted, booleans and floats refused."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not lo <= int(value) <= hi:
        raise error(f"{what} must be an integer >= {lo} and <= {hi}, got {value!r}")
    return int(value)


def real(value: object, what: str, lo: float = -math.inf, hi: float = math.inf, *, lo_open: bool = False,
         error: ErrorType = InvalidParameterError) -> float:
    """``value`` as a finite Python float in [lo, hi] (``(lo, hi]`` with ``lo_open``)."""
    f: float | None = None
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        f = float(value)
        if not (math.isfinite(f) and (f > lo if lo_open else f >= lo) and f <= hi):
            f = None
    if f is None:
        if math.isfinite(lo) and math.isfinite(hi):
            want = f"in {'(' if lo_open else '['}{lo:g}, {hi:g}]"
        elif math.isfinite(lo):
            want = f"a finite number {'>' if lo_open else '>='} {lo:g}"
        else:
            want = "a finite number"
        raise error(f"{what} must be {want}, got {value!r}")
    return f


def probability(value: object, what: str, error: ErrorType = InvalidParameterError) -> float:
    """``value`` as a probability, a float in [0, 1]."""
    try:
        return real(value, what, 0.0, 1.0, error=error)
    except ArmTransferError:
        raise error(f"{what} must be a probability in [0, 1], got {value!r}") from None


def flag(value: object, what: str, error: ErrorType = InvalidParameterError) -> bool:
    """``value`` as a bool; only ``True``, ``False`` and numpy's booleans are booleans."""
    if isinstance(value, bool) or (type(value).__module__ == "numpy" and type(value).__name__ in ("bool", "bool_")):
        return bool(value)
    raise error(f"{what} must be True or False, got {value!r}")


def point(value: object, what: str, n: int = 3, limit: float = math.inf,
          error: ErrorType = InvalidParameterError) -> tuple[float, ...]:
    """``value`` as ``n`` finite floats, each at most ``limit`` in size."""
    if isinstance(value, (str, bytes)):
        items = None
    else:
        try:
            items = list(value)  # type: ignore[call-overload]
        except TypeError:
            items = None
    if items is None or len(items) != n or not all(
            isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(float(v))
            and abs(float(v)) <= limit for v in items):
        bound = f" of size at most {limit:g}" if math.isfinite(limit) else ""
        count = {2: "two", 3: "three"}.get(n, str(n))
        raise error(f"{what} must be {count} finite numbers{bound}, got {value!r}")
    return tuple(float(v) for v in items)


def path(value: object, what: str, error: ErrorType = InvalidParameterError) -> str:
    """``value`` as a non-empty path string (a ``str`` or ``os.PathLike``)."""
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if not isinstance(value, str) or not value.strip():
        raise error(f"{what} must be a file path, got {value!r}")
    return value


def name(value: object, what: str, error: ErrorType = InvalidParameterError) -> str:
    """``value`` as a non-empty string."""
    if not isinstance(value, str) or not value.strip():
        raise error(f"{what} must be a non-empty string, got {value!r}")
    return value
