"""Integrity data of written files: strings outside the global heap, per-dataset digests.

Strings
    HDF5 keeps variable-length strings in a *global heap*, which has no checksum: a
    damaged heap silently changes them, or sends libhdf5 into an endless loop when they
    are read. scenegen therefore writes every string attribute and string dataset as
    **fixed-length UTF-8** (:func:`put_text`, :func:`text_array`): attribute values then
    live in the object header (checksummed in the file format scenegen writes) and
    dataset values in the dataset's own, digested storage. Fixed-length strings read back
    as ``bytes``; :func:`as_text` turns either kind into ``str``, so files written before
    (variable-length strings) read the same.

Digests
    Fletcher-32 (HDF5's chunk checksum) is 0 for a chunk of zeros, so a zeroed chunk
    passes it; and an edit through HDF5 writes valid checksums. Every dataset scenegen
    writes therefore carries ``sha256``: the SHA-256 of its values as stored (C order,
    the stored dtype), computed while writing; every digested group carries
    ``attrs_sha256`` over its other attributes, and the root ``integrity = "sha256"``
    says that every dataset of the file must have a digest. :mod:`scenegen.io.validate`
    recomputes them.
"""

from __future__ import annotations

import functools
import hashlib
import json
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

__all__ = [
    "ATTRS_DIGEST",
    "DIGEST",
    "INTEGRITY",
    "Hasher",
    "as_text",
    "attrs_digest",
    "digest",
    "put_attrs_digest",
    "put_text",
    "strip",
    "text_array",
    "text_dtype",
]

DIGEST = "sha256"
"""Attribute of every dataset: hex SHA-256 of its stored values."""
ATTRS_DIGEST = "attrs_sha256"
"""Attribute of the root and of each sequence or result group: digest of its attributes."""
INTEGRITY = "integrity"
"""Root attribute: ``"sha256"`` when every dataset of the file carries :data:`DIGEST`."""
_SKIP = {DIGEST, ATTRS_DIGEST}


def text_dtype(n_bytes: int) -> Any:
    """Fixed-length UTF-8 string dtype of ``n_bytes`` (at least 1).

    Parameters
    ----------
    n_bytes : int
        Length of the string in UTF-8 bytes; less than 1 gives 1.

    Returns
    -------
    numpy.dtype
        ``S<n>`` with h5py's UTF-8 string metadata.
    """
    return h5py.string_dtype("utf-8", max(1, int(n_bytes)))


def put_text(obj: Any, key: str, value: str) -> None:
    """Store ``value`` as a fixed-length UTF-8 string attribute ``key`` of ``obj`` (an
    existing one is replaced). The attribute is the one ``obj.attrs.create(key,
    np.bytes_(raw), dtype=text_dtype(len(raw)))`` makes, through h5py's low-level calls:
    a third of the cost, which counts in a file of hundreds of template datasets.

    Parameters
    ----------
    obj : h5py.File, h5py.Group or h5py.Dataset
        The object, open for writing.
    key : str
        Attribute name.
    value : str
        Attribute value, stored as its UTF-8 bytes.
    """
    raw = value.encode("utf-8")
    dtype, tid, space = _text_type(len(raw))
    name = key.encode("utf-8")
    if h5py.h5a.exists(obj.id, name):
        h5py.h5a.delete(obj.id, name)
    attr = h5py.h5a.create(obj.id, name, tid, space)
    attr.write(np.array(raw, dtype=dtype), mtype=tid)


@functools.lru_cache(maxsize=256)
def _text_type(n_bytes: int) -> tuple[Any, Any, Any]:
    """The numpy dtype, HDF5 type and scalar dataspace of :func:`put_text` for a string
    of ``n_bytes`` (cached: building them was 40 % of its cost; a created attribute
    copies both, so one pair serves every file)."""
    dtype = text_dtype(n_bytes)
    return dtype, h5py.h5t.py_create(dtype, logical=True), h5py.h5s.create(h5py.h5s.SCALAR)


def put(obj: Any, key: str, value: Any) -> None:
    """Store an attribute: strings fixed-length (:func:`put_text`), others as given."""
    if isinstance(value, str):
        put_text(obj, key, value)
    else:
        obj.attrs[key] = value


def text_array(values: Any) -> NDArray[np.bytes_]:
    """Strings as a fixed-length UTF-8 byte array (for string datasets).

    Parameters
    ----------
    values : array_like of str, any shape
        The strings (any other value is turned into one with ``str``).

    Returns
    -------
    ndarray of bytes, shape of ``values``
        dtype ``S<width>``, ``width`` the longest UTF-8 encoding (at least 1).

    Examples
    --------
    >>> text_array([["a", "é"]])
    array([[b'a', b'\\xc3\\xa9']], dtype='|S2')
    """
    raw = [str(v).encode("utf-8") for v in np.asarray(values, dtype=object).ravel()]
    width = max([1, *(len(r) for r in raw)])
    return np.array(raw, dtype=f"S{width}").reshape(np.shape(values))


def as_text(value: Any) -> str:
    """An attribute or string value as ``str`` (fixed-length strings read as bytes).

    Parameters
    ----------
    value : bytes, numpy.bytes_, str, 0-d ndarray or object
        The value read; bytes are decoded as UTF-8, a 0-d array is unwrapped, anything
        else goes through ``str``.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        If the bytes are not UTF-8 (a damaged string).
    """
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, (bytes, np.bytes_)):
        return bytes(value).decode("utf-8")
    return str(value)


class Hasher:
    """SHA-256 of a dataset's values, fed in order (a block of frames at a time)."""

    def __init__(self) -> None:
        self._h = hashlib.sha256()

    def update(self, block: NDArray[Any]) -> None:
        """Add the next values (rows in storage order).

        Only the raw bytes are hashed (C order), not the dtype or shape: feeding a
        dataset block by block gives the same digest as feeding it whole.

        Parameters
        ----------
        block : ndarray, any shape and dtype
            The next values, e.g. frames of shape (t, H, W, 3), uint8; an empty one adds
            nothing.
        """
        arr = np.ascontiguousarray(block)
        if arr.size:  # hashed in place: no copy of a block of frames
            self._h.update(memoryview(arr.reshape(-1).view(np.uint8)))

    def hexdigest(self) -> str:
        """SHA-256 of the values fed so far (more may still be added).

        Returns
        -------
        str
            64 lowercase hex digits.
        """
        return self._h.hexdigest()


def digest(arr: NDArray[Any]) -> str:
    """Hex SHA-256 of ``arr``'s values (C order, its dtype).

    Parameters
    ----------
    arr : ndarray, any shape and dtype
        The values, as stored.

    Returns
    -------
    str
        64 lowercase hex digits.
    """
    h = Hasher()
    h.update(np.asarray(arr))
    return h.hexdigest()


def _plain(value: Any) -> Any:
    if isinstance(value, (bytes, np.bytes_)):
        return ["bytes", bytes(value).hex()]
    if isinstance(value, np.ndarray):
        return [str(value.dtype), value.shape, _plain(value.tolist())]
    if isinstance(value, np.generic):
        return [str(value.dtype), value.item()]
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def attrs_digest(attrs: Any) -> str:
    """Hex SHA-256 of a group's attributes (names, types and values), digests excluded.

    Parameters
    ----------
    attrs : mapping of str to object
        The attributes, e.g. an open group's ``attrs``; :data:`DIGEST` and
        :data:`ATTRS_DIGEST` are left out.

    Returns
    -------
    str
        64 lowercase hex digits.

    Raises
    ------
    OSError, KeyError, ValueError, TypeError
        If an attribute cannot be read (a damaged file).
    """
    items = {k: _plain(attrs[k]) for k in sorted(attrs) if k not in _SKIP}
    text = json.dumps(items, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def put_attrs_digest(obj: Any, texts: dict[str, str] | None = None) -> None:
    """Store :data:`ATTRS_DIGEST` of ``obj``'s attributes (after all are written).

    Given ``texts``, the attributes ``obj`` holds besides the digests (each written with
    :func:`put_text`), the digest is computed from them as they read back, instead of
    reading them back: the same value, without a read per attribute.

    Parameters
    ----------
    obj : h5py.File or h5py.Group
        The object, open for writing, its other attributes written.
    texts : dict of str to str, optional
        Every attribute of ``obj`` besides the digests, all written with
        :func:`put_text`; default: read the attributes from ``obj``.
    """
    if texts is None:
        hexdigest = attrs_digest(obj.attrs)
    else:
        hexdigest = _texts_digest(tuple(sorted(texts.items())))
    put_text(obj, ATTRS_DIGEST, hexdigest)


@functools.lru_cache(maxsize=64)
def _texts_digest(items: tuple[tuple[str, str], ...]) -> str:
    """:func:`attrs_digest` of string attributes written with :func:`put_text`, which
    read back as ``np.bytes_`` (cached: every template dataset has the same two)."""
    return attrs_digest({k: np.bytes_(v.encode("utf-8")) for k, v in items})


def strip(f: h5py.File) -> None:
    """Remove every integrity attribute (digests, ``integrity``) from an open file: what
    files written before digests existed look like (tests of old files use it).

    Parameters
    ----------
    f : h5py.File
        The file, open for writing; changed in place.
    """

    def drop(_: str, obj: Any) -> None:
        for key in (DIGEST, ATTRS_DIGEST):
            if key in obj.attrs:
                del obj.attrs[key]

    drop("/", f)
    f.visititems(drop)
    if INTEGRITY in f.attrs:
        del f.attrs[INTEGRITY]
