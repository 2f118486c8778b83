"""``png_problem`` and ``gif_problem``: a figure or preview is a whole image, or one line
says why not."""

from __future__ import annotations

import io
import struct
import zlib

import numpy as np
import pytest

from scenegen.io.images import PNG_SIGNATURE, gif_problem, png_problem


def _figure() -> bytes:
    """A small matplotlib figure, written as the experiments write theirs."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 1.5), dpi=50)
    FigureCanvasAgg(fig)
    fig.add_subplot().plot([0, 1, 2], [2, 0, 1])
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()


def _chunk(kind: bytes, body: bytes) -> bytes:
    return (struct.pack(">I", len(body)) + kind + body
            + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))  # fmt: skip


@pytest.fixture(scope="module")
def figure() -> bytes:
    return _figure()


def test_a_whole_figure_is_sound(figure):
    assert png_problem(figure) is None


@pytest.mark.parametrize("cut", [1, 4, 12, 13, 100])
def test_a_figure_cut_short_is_refused(figure, cut):
    # Pillow alone reads a file missing up to its last 8 bytes without complaint.
    assert png_problem(figure[:-cut]) == ("not a whole PNG image (it does not end with the "
                                          "IEND chunk)")  # fmt: skip


def test_a_figure_cut_in_its_pixels_is_refused(figure):
    problem = png_problem(figure[: len(figure) // 2] + figure[-12:])
    assert problem is not None and problem.startswith("not a whole PNG image (")


def test_bytes_after_the_end_are_refused(figure):
    assert png_problem(figure + b"\0") is not None


def test_every_flipped_bit_of_a_sample_is_refused(figure):
    rng = np.random.default_rng(0)
    for _ in range(60):
        damaged = bytearray(figure)
        at = int(rng.integers(0, len(figure)))
        damaged[at] ^= 1 << int(rng.integers(0, 8))
        problem = png_problem(bytes(damaged))
        assert problem is not None, at
        assert "0x" not in problem  # one stable line: no object address in it


def test_not_a_png(figure):
    assert png_problem(b"GIF89a" + figure) == "not a PNG file"
    assert png_problem(b"") == "not a PNG file"
    assert png_problem(PNG_SIGNATURE) == ("not a whole PNG image (it does not end with the "
                                          "IEND chunk)")  # fmt: skip


def test_a_size_field_of_a_huge_image_is_refused_without_allocating_it():
    # Every CRC right, the size 100000 x 100000 (4e10 bytes of RGBA): refused at the header.
    ihdr = struct.pack(">IIBBBBB", 100_000, 100_000, 8, 6, 0, 0, 0)
    data = (PNG_SIGNATURE + _chunk(b"IHDR", ihdr) + _chunk(b"IDAT", zlib.compress(b"\0" * 64))
            + _chunk(b"IEND", b""))  # fmt: skip
    problem = png_problem(data)
    assert problem is not None and problem.startswith("not a whole PNG image (")


def _gif() -> bytes:
    """A 6-frame GIF written by Pillow, as the demo's previews are."""
    from PIL import Image

    rng = np.random.default_rng(1)
    frames = [Image.fromarray(rng.integers(0, 255, (24, 32, 3), dtype=np.uint8))
              for _ in range(6)]
    buf = io.BytesIO()
    frames[0].save(buf, format="GIF", save_all=True, append_images=frames[1:], duration=40)
    return buf.getvalue()


def test_a_whole_gif_is_sound_and_one_cut_short_is_not():
    gif = _gif()
    assert png_problem(gif) == "not a PNG file"
    assert gif_problem(gif) is None
    for cut in (1, 2, 50):
        assert gif_problem(gif[:-cut]) == ("not a whole GIF image (it does not end with the "
                                           "GIF trailer)")  # fmt: skip
    # The trailer put back after half the file: a frame's pixels are missing.
    problem = gif_problem(gif[: len(gif) // 2] + b";")
    assert problem is not None and problem.startswith("not a whole GIF image (")
    assert gif_problem(b"GIF88a" + gif[6:]) == "not a GIF file"
    assert gif_problem(_figure()) == "not a GIF file"
