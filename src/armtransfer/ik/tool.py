"""The tool point: where on an arm the tip that labels each configuration with a cell is.

An arm file says nothing of the tool a user means: MuJoCo Menagerie arms have a flange site
(``attachment_site``) or no site at all. A :class:`Tool` names a site or a body of the file
and an offset in that site's or body's own frame, in metres:

- ``Tool(site="tip")``: the built-in arms' convention, the site itself;
- ``Tool(site="attachment_site", offset=(0, 0, 0.12))``: 12 cm past a UR5e's flange;
- ``Tool(body="hand", offset=(0, 0, 0.1034))``: between a Panda's fingertips.

The tool's axis, which spatial arms keep pointing down, is the offset's direction when there
is an offset, else the site's z axis (a body without offset: the body's z axis).

A hand can also hold a tool of the scene's own, :class:`Stylus` (``--tool stylus:LENGTH[:RADIUS]``):
a thin round pen, a capsule of collision geometry along the tool axis from the tool point. The
cell is then read at the pen's end, and a gripper's fingers ride the pen's length above the
table, over its walls.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import armtransfer.checks as checks
from armtransfer.errors import ArmModelError


STYLUS_LENGTH = 0.05
"""The default pen's length past the tool point (m). The walls stand 2 cm; a closed gripper's
fingertips reach up to about 2 cm past its TCP (a Panda's 2 cm, the test grippers' 1.5 and 2),
so 5 cm holds them 1 cm or more above the wall tops with the pen's end at the table."""
STYLUS_RADIUS = 0.0015
"""The default pen's radius (m): the built-in planar arms' stylus, a tenth of a 1 cm door."""
MAX_STYLUS_LENGTH = 0.5


@dataclass(frozen=True)
class Stylus:
    """A round pen held along the tool axis: ``length`` metres past the tool point, ``radius``
    metres thick. It collides like the arm's own geometry."""
    length: float = STYLUS_LENGTH
    radius: float = STYLUS_RADIUS

    def __post_init__(self) -> None:
        length = checks.real(self.length, "the stylus length (metres)", 0.0, MAX_STYLUS_LENGTH, lo_open=True,
                             error=ArmModelError)
        radius = checks.real(self.radius, "the stylus radius (metres)", 0.0, length, lo_open=True,
                             error=ArmModelError)
        object.__setattr__(self, "length", length)
        object.__setattr__(self, "radius", radius)

    def spec(self) -> str:
        """The text that :func:`parse_held` reads back."""
        return f"stylus:{self.length:g}:{self.radius:g}"


def parse_held(text: object) -> Stylus:
    """``'stylus'``, ``'stylus:LENGTH'`` or ``'stylus:LENGTH:RADIUS'`` (metres) -> :class:`Stylus`;
    a :class:`Stylus` is returned as it is. One line naming the problem otherwise."""
    if isinstance(text, Stylus):
        return text
    if not isinstance(text, str):
        raise ArmModelError(f"a held tool must be 'stylus[:LENGTH[:RADIUS]]' (metres), got {text!r}")
    kind, _, rest = text.strip().partition(":")
    if kind != "stylus":
        raise ArmModelError(f"unknown held tool {kind!r}; valid tools: stylus (as stylus[:LENGTH[:RADIUS]], metres)")
    parts = rest.split(":") if rest else []
    if len(parts) > 2:
        raise ArmModelError(f"a held tool is stylus[:LENGTH[:RADIUS]] (metres), got {text!r}")
    values = []
    for what, part in zip(("length", "radius"), parts):
        try:
            values.append(float(part))
        except ValueError:
            raise ArmModelError(f"the stylus {what} must be a number of metres, got {part!r} in {text!r}") from None
    return Stylus(*values)


@dataclass(frozen=True)
class Tool:
    site: str | None = "tip"
    body: str | None = None
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    held: Stylus | None = None
    """A pen the hand holds past the tool point (the cell is read at its end), or none."""

    def __post_init__(self) -> None:
        if (self.site is None) == (self.body is None):
            raise ArmModelError("the tool point needs exactly one of a tip site or a tip body")
        offset = checks.point(self.offset, "a tip offset (metres)", limit=checks.MAX_METRES, error=ArmModelError)
        object.__setattr__(self, "offset", offset)
        if self.held is not None:
            object.__setattr__(self, "held", parse_held(self.held))

    @property
    def has_offset(self) -> bool:
        return any(v != 0.0 for v in self.offset)

    def key(self) -> dict:
        """What the compiled arrays depend on (for the cache key)."""
        key: dict = {"site": self.site, "body": self.body, "offset": list(self.offset)}
        if self.held is not None:  # without one, the keys of every cached arm stay as they were
            key["held"] = {"stylus": [self.held.length, self.held.radius]}
        return key

    def axis_hint(self) -> str:
        """For errors when the tool cannot reach the table: without an offset its axis, kept
        pointing down, is the site's (or body's) z axis, which may not be the tool's."""
        if self.has_offset:
            return ""
        return (f"the tool's axis, kept pointing down, is the {'site' if self.site is not None else 'body'}'s "
                "z axis: if the tool points another way, give --tip-offset along it")

    def describe(self) -> str:
        where = f"site {self.site}" if self.site is not None else f"body {self.body}"
        if self.has_offset:
            where += " + (" + ", ".join(f"{v:g}" for v in self.offset) + ") m"
        if self.held is not None:
            where += f", holding a {1000 * self.held.length:g} mm stylus {2000 * self.held.radius:g} mm wide"
        return where


def parse_offset(text: str) -> tuple[float, float, float]:
    """'0,0,0.12' -> (0.0, 0.0, 0.12); one line naming the problem otherwise."""
    parts = [p.strip() for p in str(text).split(",")]
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise ArmModelError(f"--tip-offset must be three finite numbers X,Y,Z in metres, got {text!r}")
    return values  # type: ignore[return-value]


__all__ = ["STYLUS_LENGTH", "STYLUS_RADIUS", "Stylus", "Tool", "parse_held", "parse_offset"]
