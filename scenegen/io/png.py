"""Whether the bytes of a figure are a whole, readable PNG image.

The experiments and the benchmark write PNG figures that nothing reads back, so a check
of their folder cannot compare them with anything; it can refuse a file that is not an
image any more. A signature alone says "valid" for a file cut short or with a flipped
byte (measured: a figure missing its last 10 bytes passed). Pillow checks every chunk's
CRC (``verify``) and then decodes the pixels (``load``): a truncated stream, a damaged
chunk or compressed data that does not inflate is refused. An image beyond Pillow's
decompression-bomb limit is refused too, so a damaged size field cannot make the check
allocate gigabytes.
"""

from __future__ import annotations

import io
import re
import warnings

__all__ = ["PNG_SIGNATURE", "png_problem"]

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
# The last chunk of every PNG file: length 0, type IEND, its CRC. Pillow stops reading at
# the chunk's type, so a file missing its last bytes, or with bytes after them, decodes.
_IEND = b"\x00\x00\x00\x00IEND\xaeB`\x82"


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
    if not data.endswith(_IEND):
        return "not a whole PNG image (it does not end with the IEND chunk)"
    from PIL import Image

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            with Image.open(io.BytesIO(data), formats=["PNG"]) as im:
                im.verify()  # every chunk's CRC, up to IEND
            with Image.open(io.BytesIO(data), formats=["PNG"]) as im:
                im.load()  # the pixels inflate to the declared size
    except (OSError, SyntaxError, ValueError, EOFError, Image.DecompressionBombWarning,
            Image.DecompressionBombError) as err:
        text = str(err).splitlines()[0] if str(err) else type(err).__name__
        reason = re.sub(r" <[^>]*>", "", text)  # no object address in the message
        return f"not a whole PNG image ({reason})"
    return None
