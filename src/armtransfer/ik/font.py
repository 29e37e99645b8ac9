"""A tiny bitmap font drawn with numpy: captions on video frames without a text library.

Each glyph is 5 pixels wide and 8 high (7 above the baseline, one row for descenders), drawn
at an integer ``scale`` into a ``[height, width, 3]`` uint8 image. :func:`draw_lines` puts a
few lines of text on a darkened box in a corner of the image, so they read on any background.
Drawing is integer arithmetic only: the same text on the same image gives the same bytes.
A character without a glyph is drawn as ``?``.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache

import numpy as np

from armtransfer.errors import InvalidParameterError

GLYPH_WIDTH, GLYPH_HEIGHT = 5, 8
ADVANCE, LINE = GLYPH_WIDTH + 1, GLYPH_HEIGHT + 2
"""Pixels (at scale 1) from one character to the next, and from one line to the next."""

_GLYPHS = {
    # rows top to bottom, '#' is ink; 7 rows sit above the baseline, an 8th hangs below it
    "A": ".###. #...# #...# ##### #...# #...# #...#",
    "B": "####. #...# #...# ####. #...# #...# ####.",
    "C": ".###. #...# #.... #.... #.... #...# .###.",
    "D": "####. #...# #...# #...# #...# #...# ####.",
    "E": "##### #.... #.... ####. #.... #.... #####",
    "F": "##### #.... #.... ####. #.... #.... #....",
    "G": ".###. #...# #.... #.### #...# #...# .####",
    "H": "#...# #...# #...# ##### #...# #...# #...#",
    "I": ".###. ..#.. ..#.. ..#.. ..#.. ..#.. .###.",
    "J": "..### ...#. ...#. ...#. ...#. #..#. .##..",
    "K": "#...# #..#. #.#.. ##... #.#.. #..#. #...#",
    "L": "#.... #.... #.... #.... #.... #.... #####",
    "M": "#...# ##.## #.#.# #.#.# #...# #...# #...#",
    "N": "#...# #...# ##..# #.#.# #..## #...# #...#",
    "O": ".###. #...# #...# #...# #...# #...# .###.",
    "P": "####. #...# #...# ####. #.... #.... #....",
    "Q": ".###. #...# #...# #...# #.#.# #..#. .##.#",
    "R": "####. #...# #...# ####. #.#.. #..#. #...#",
    "S": ".#### #.... #.... .###. ....# ....# ####.",
    "T": "##### ..#.. ..#.. ..#.. ..#.. ..#.. ..#..",
    "U": "#...# #...# #...# #...# #...# #...# .###.",
    "V": "#...# #...# #...# #...# #...# .#.#. ..#..",
    "W": "#...# #...# #...# #.#.# #.#.# #.#.# .#.#.",
    "X": "#...# #...# .#.#. ..#.. .#.#. #...# #...#",
    "Y": "#...# #...# .#.#. ..#.. ..#.. ..#.. ..#..",
    "Z": "##### ....# ...#. ..#.. .#... #.... #####",
    "a": "..... ..... .###. ....# .#### #...# .####",
    "b": "#.... #.... #.##. ##..# #...# #...# ####.",
    "c": "..... ..... .###. #.... #.... #...# .###.",
    "d": "....# ....# .##.# #..## #...# #...# .####",
    "e": "..... ..... .###. #...# ##### #.... .###.",
    "f": "..##. .#..# .#... ###.. .#... .#... .#...",
    "g": "..... ..... .#### #...# #...# .#### ....# .###.",
    "h": "#.... #.... #.##. ##..# #...# #...# #...#",
    "i": "..#.. ..... .##.. ..#.. ..#.. ..#.. .###.",
    "j": "...#. ..... ..##. ...#. ...#. ...#. #..#. .##..",
    "k": "#.... #.... #..#. #.#.. ##... #.#.. #..#.",
    "l": ".##.. ..#.. ..#.. ..#.. ..#.. ..#.. .###.",
    "m": "..... ..... ##.#. #.#.# #.#.# #.#.# #.#.#",
    "n": "..... ..... #.##. ##..# #...# #...# #...#",
    "o": "..... ..... .###. #...# #...# #...# .###.",
    "p": "..... ..... ####. #...# #...# ####. #.... #....",
    "q": "..... ..... .#### #...# #...# .#### ....# ....#",
    "r": "..... ..... #.##. ##..# #.... #.... #....",
    "s": "..... ..... .###. #.... .###. ....# ####.",
    "t": ".#... .#... ###.. .#... .#... .#..# ..##.",
    "u": "..... ..... #...# #...# #...# #..## .##.#",
    "v": "..... ..... #...# #...# #...# .#.#. ..#..",
    "w": "..... ..... #...# #...# #.#.# #.#.# .#.#.",
    "x": "..... ..... #...# .#.#. ..#.. .#.#. #...#",
    "y": "..... ..... #...# #...# #...# .#### ....# .###.",
    "z": "..... ..... ##### ...#. ..#.. .#... #####",
    "0": ".###. #...# #..## #.#.# ##..# #...# .###.",
    "1": "..#.. .##.. ..#.. ..#.. ..#.. ..#.. .###.",
    "2": ".###. #...# ....# ...#. ..#.. .#... #####",
    "3": "##### ...#. ..#.. ...#. ....# #...# .###.",
    "4": "...#. ..##. .#.#. #..#. ##### ...#. ...#.",
    "5": "##### #.... ####. ....# ....# #...# .###.",
    "6": "..##. .#... #.... ####. #...# #...# .###.",
    "7": "##### ....# ...#. ..#.. .#... .#... .#...",
    "8": ".###. #...# #...# .###. #...# #...# .###.",
    "9": ".###. #...# #...# .#### ....# ...#. .##..",
    " ": "..... ..... ..... ..... ..... ..... .....",
    ":": "..... .##.. .##.. ..... .##.. .##.. .....",
    ".": "..... ..... ..... ..... ..... .##.. .##..",
    ",": "..... ..... ..... ..... .##.. ..#.. .#...",
    "/": "..... ....# ...#. ..#.. .#... #.... .....",
    "_": "..... ..... ..... ..... ..... ..... #####",
    "-": "..... ..... ..... ##### ..... ..... .....",
    "+": "..... ..#.. ..#.. ##### ..#.. ..#.. .....",
    "=": "..... ..... ##### ..... ##### ..... .....",
    ">": ".#... ..#.. ...#. ....# ...#. ..#.. .#...",
    "<": "...#. ..#.. .#... #.... .#... ..#.. ...#.",
    "(": "...#. ..#.. .#... .#... .#... ..#.. ...#.",
    ")": ".#... ..#.. ...#. ...#. ...#. ..#.. .#...",
    "[": ".###. .#... .#... .#... .#... .#... .###.",
    "]": ".###. ...#. ...#. ...#. ...#. ...#. .###.",
    "%": "##... ##..# ...#. ..#.. .#... #..## ...##",
    "#": ".#.#. .#.#. ##### .#.#. ##### .#.#. .#.#.",
    "!": "..#.. ..#.. ..#.. ..#.. ..#.. ..... ..#..",
    "'": "..#.. ..#.. .#... ..... ..... ..... .....",
    "?": ".###. #...# ....# ...#. ..#.. ..... ..#..",
}


def _bitmap(rows: str) -> np.ndarray:
    lines = rows.split()
    lines += ["." * GLYPH_WIDTH] * (GLYPH_HEIGHT - len(lines))
    return np.array([[c == "#" for c in line] for line in lines], dtype=bool)


GLYPHS: dict[str, np.ndarray] = {c: _bitmap(rows) for c, rows in _GLYPHS.items()}
"""Each character's [8, 5] ink mask."""


@cache
def text_mask(text: str, scale: int = 1) -> np.ndarray:
    """The ink of one line of ``text`` as a bool array [8 * scale, 6 * len(text) * scale]."""
    out = np.zeros((GLYPH_HEIGHT, ADVANCE * max(len(text), 1)), dtype=bool)
    for i, ch in enumerate(text):
        out[:, i * ADVANCE:i * ADVANCE + GLYPH_WIDTH] = GLYPHS.get(ch, GLYPHS["?"])
    return np.kron(out, np.ones((scale, scale), dtype=bool)) if scale > 1 else out


def text_size(lines: Sequence[str], scale: int = 1, pad: int = 2) -> tuple[int, int]:
    """(height, width) in pixels of the box :func:`draw_lines` draws for ``lines``."""
    width = max((len(t) for t in lines), default=0) * ADVANCE - 1
    height = len(lines) * LINE - 2
    return height * scale + 2 * pad, width * scale + 2 * pad


def draw_lines(image: np.ndarray, lines: Sequence[str], *, corner: str = "top-left", scale: int = 1,
               color: tuple[int, int, int] = (255, 255, 255), box_alpha: float = 0.6, pad: int = 2) -> np.ndarray:
    """Draw ``lines`` into ``image`` (in place, and returned) on a box darkened by ``box_alpha``
    in ``corner`` (``top-left``, ``top-right``, ``bottom-left``, ``bottom-right``); text that
    does not fit the image is cut at its edge."""
    if not (isinstance(scale, int) and scale >= 1):
        raise InvalidParameterError(f"scale must be a whole number from 1 up, got {scale!r}")
    if corner not in ("top-left", "top-right", "bottom-left", "bottom-right"):
        raise InvalidParameterError(f"unknown corner {corner!r}; valid corners: top-left, top-right, bottom-left, bottom-right")
    lines = [t for t in lines]
    if not lines:
        return image
    h, w = image.shape[:2]
    bh, bw = text_size(lines, scale, pad)
    bh, bw = min(bh, h), min(bw, w)
    y0 = 0 if corner.startswith("top") else h - bh
    x0 = 0 if corner.endswith("left") else w - bw
    box = image[y0:y0 + bh, x0:x0 + bw]
    keep = int(round((1.0 - box_alpha) * 256))
    box[...] = ((box.astype(np.uint16) * keep) >> 8).astype(np.uint8)
    ink = np.array(color, dtype=np.uint8)
    for i, text in enumerate(lines):
        mask = text_mask(text, scale)
        top = pad + i * LINE * scale
        mh, mw = min(mask.shape[0], bh - top), min(mask.shape[1], bw - pad)
        if mh > 0 and mw > 0:
            box[top:top + mh, pad:pad + mw][mask[:mh, :mw]] = ink
    return image


__all__ = ["GLYPHS", "draw_lines", "text_mask", "text_size"]
