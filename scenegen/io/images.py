"""Whether the bytes of a figure or preview are a whole, readable PNG or GIF image.

The experiments and the benchmark write PNG figures, and ``scenegen demo`` PNG contact
sheets and GIF previews, that nothing reads back, so a check of their folder cannot
compare them with anything; it can refuse a file that is not an image any more. A
signature alone says "valid" for a file cut short or with a flipped byte (measured: a
figure missing its last 10 bytes passed). Pillow decodes the pixels (``load``, every
frame of a GIF): a truncated stream or compressed data that does not inflate is refused.
For a PNG it also checks every chunk's CRC (``verify``), so any flipped bit is found. A
GIF has no checksum: a flipped bit inside its compressed pixels can decode to other
pixels and is not found; its structure (blocks, trailer) is checked. Pillow stops reading
at a PNG's IEND chunk type and at a GIF's last frame, so each file must also end with its
format's last bytes (the IEND chunk, the GIF trailer). An image beyond Pillow's
decompression-bomb limit is refused, so a damaged size field cannot make the check
allocate gigabytes.
"""

from __future__ import annotations

import io
import re
import warnings

__all__ = ["GIF_SIGNATURES", "PNG_SIGNATURE", "gif_problem", "png_problem"]

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
GIF_SIGNATURES = (b"GIF87a", b"GIF89a")
# The last bytes of every file of the format: a PNG's IEND chunk (length 0, type, CRC), a
# GIF's trailer.
_PNG_END = b"\x00\x00\x00\x00IEND\xaeB`\x82"
_GIF_END = b";"


def png_problem(data: bytes) -> str | None:
    """What is wrong with ``data`` as a PNG image, or None for a whole, decodable one.

    Parameters
    ----------
    data : bytes
        The file's contents.

    Returns
    -------
    str or None
        ``"not a PNG file"`` when the signature is wrong; ``"not a whole PNG image (...)"``
        naming the reason (Pillow's) when the file does not end with the IEND chunk,
        or a chunk's CRC, the stream's end or the pixel data is wrong; None when the
        image decodes.
    """
    if data[:8] != PNG_SIGNATURE:
        return "not a PNG file"
    return _decode_problem(data, "PNG", _PNG_END, "the IEND chunk")


def gif_problem(data: bytes) -> str | None:
    """What is wrong with ``data`` as a GIF image, or None for one whose every frame
    decodes.

    Parameters
    ----------
    data : bytes
        The file's contents.

    Returns
    -------
    str or None
        ``"not a GIF file"`` when the signature is wrong; ``"not a whole GIF image
        (...)"`` naming the reason when the file does not end with the GIF trailer or a
        frame does not decode; None otherwise (GIF has no checksum: see the module).
    """
    if data[:6] not in GIF_SIGNATURES:
        return "not a GIF file"
    return _decode_problem(data, "GIF", _GIF_END, "the GIF trailer")


def _decode_problem(data: bytes, fmt: str, end: bytes, end_name: str) -> str | None:
    """Pillow's reason why ``data`` (signature checked) does not decode as ``fmt``."""
    if not data.endswith(end):
        return f"not a whole {fmt} image (it does not end with {end_name})"
    from PIL import Image, ImageSequence

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            if fmt == "PNG":
                with Image.open(io.BytesIO(data), formats=[fmt]) as im:
                    im.verify()  # every chunk's CRC, up to IEND
            with Image.open(io.BytesIO(data), formats=[fmt]) as im:
                for frame in ImageSequence.Iterator(im):
                    frame.load()  # the pixels inflate to the declared size
    except (OSError, SyntaxError, ValueError, EOFError, Image.DecompressionBombWarning,
            Image.DecompressionBombError) as err:
        text = str(err).splitlines()[0] if str(err) else type(err).__name__
        reason = re.sub(r" <[^>]*>", "", text)  # no object address in the message
        return f"not a whole {fmt} image ({reason})"
    return None
