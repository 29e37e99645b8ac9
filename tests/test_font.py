"""The bitmap font that captions video frames (armtransfer.ik.font)."""

import numpy as np
import pytest

from armtransfer.errors import ArmTransferError
from armtransfer.ik import font


def test_every_glyph_is_5_by_8_and_distinct():
    shapes = {g.shape for g in font.GLYPHS.values()}
    assert shapes == {(font.GLYPH_HEIGHT, font.GLYPH_WIDTH)}
    inks = [g.tobytes() for c, g in font.GLYPHS.items() if c != " "]
    assert len(set(inks)) == len(inks)  # no two characters drawn alike
    for ch in "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789:_/-.()[]":
        assert font.GLYPHS[ch].any(), ch


def test_text_mask_places_glyphs_and_scales():
    mask = font.text_mask("a1")
    assert mask.shape == (8, 12)
    assert np.array_equal(mask[:, 0:5], font.GLYPHS["a"]) and np.array_equal(mask[:, 6:11], font.GLYPHS["1"])
    assert not mask[:, 5].any() and not mask[:, 11].any()
    assert np.array_equal(font.text_mask("a1", 2), np.kron(mask, np.ones((2, 2), dtype=bool)))
    assert np.array_equal(font.text_mask("é"), font.text_mask("?"))  # no glyph: drawn as '?'


def test_draw_lines_darkens_a_box_in_its_corner_and_nothing_else():
    image = np.full((40, 60, 3), 200, np.uint8)
    out = font.draw_lines(image.copy(), ["ab", "12"], corner="bottom-right")
    h, w = font.text_size(["ab", "12"])
    changed = np.any(out != image, axis=-1)
    assert changed[-h:, -w:].all() and changed.sum() == h * w
    ink = np.all(out == 255, axis=-1)
    assert ink.any() and (out[changed & ~ink] < 200).all()  # the box is darker, the text white
    again = font.draw_lines(image.copy(), ["ab", "12"], corner="bottom-right")
    assert np.array_equal(out, again)


def test_text_wider_than_the_image_is_cut_at_its_edge():
    image = np.zeros((12, 20, 3), np.uint8)
    font.draw_lines(image, ["a line far wider than the image", "and a second"], scale=2)
    assert image.any()


@pytest.mark.parametrize("kwargs", [{"corner": "middle"}, {"scale": 0}, {"scale": 1.5}])
def test_bad_corner_or_scale_is_one_line_error(kwargs):
    with pytest.raises(ArmTransferError) as err:
        font.draw_lines(np.zeros((10, 10, 3), np.uint8), ["x"], **kwargs)
    assert "\n" not in str(err.value)
