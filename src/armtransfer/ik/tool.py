"""The tool point: where on an arm the tip that labels each configuration with a cell is.

An arm file says nothing of the tool a user means: MuJoCo Menagerie arms have a flange site
(``attachment_site``) or no site at all. A :class:`Tool` names a site or a body of the file
and an offset in that site's or body's own frame, in metres:

- ``Tool(site="tip")``: the built-in arms' convention, the site itself;
- ``Tool(site="attachment_site", offset=(0, 0, 0.12))``: 12 cm past a UR5e's flange;
- ``Tool(body="hand", offset=(0, 0, 0.1034))``: between a Panda's fingertips.

The tool's axis, which spatial arms keep pointing down, is the offset's direction when there
is an offset, else the site's z axis (a body without offset: the body's z axis).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import armtransfer.checks as checks
from armtransfer.errors import ArmModelError


@dataclass(frozen=True)
class Tool:
    site: str | None = "tip"
    body: str | None = None
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        if (self.site is None) == (self.body is None):
            raise ArmModelError("the tool point needs exactly one of a tip site or a tip body")
        offset = checks.point(self.offset, "a tip offset (metres)", limit=checks.MAX_METRES, error=ArmModelError)
        object.__setattr__(self, "offset", offset)

    @property
    def has_offset(self) -> bool:
        return any(v != 0.0 for v in self.offset)

    def key(self) -> dict:
        """What the compiled arrays depend on (for the cache key)."""
        return {"site": self.site, "body": self.body, "offset": list(self.offset)}

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


__all__ = ["Tool", "parse_offset"]
