"""The HDF5 layout of schema ``scenegen/1``, defined once.

Every dataset of a sequence file and of a tracker result file is one :class:`Field` of
:data:`SEQUENCE_FIELDS` or :data:`RESULT_FIELDS`: its path, dtype, symbolic shape,
description and units. The writer (:mod:`scenegen.io.hdf5`) creates the datasets from this
table and stores ``description`` and ``units`` as attributes of each, the reader and the
validator (:mod:`scenegen.io.validate`) take shapes and dtypes from it, and
``docs/format.md`` is rendered from it (:func:`render_markdown`), so a reader with plain
h5py and no scenegen can understand a file.

Shape symbols: ``T`` frames, ``H`` x ``W`` pixels, ``K`` entities, ``M`` tracked targets,
``L`` depth orderings, ``h`` x ``w`` a template's size; numbers are literal sizes.

Older files: ``gt/path_center`` was added after the first files of ``scenegen/1`` were
written. It is :attr:`Field.optional`: a file without it is still valid, and reading it
gives a NaN-filled array (the noise-free path cannot be recovered from the stored boxes).
Files written before the ``description``/``units`` attributes existed read the same way.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, get_args

import numpy as np

from scenegen.config import MAX_TEMPLATE_PIXELS, Role

__all__ = [
    "ATTRIBUTES",
    "CONVENTIONS",
    "GT_FIELDS",
    "RESULT_FIELDS",
    "ROLES",
    "SCHEMA",
    "SEQUENCE_FIELDS",
    "Attribute",
    "Field",
    "dataset_attrs",
    "field",
    "gt_fields",
    "render_markdown",
    "schema_problem",
    "template_size_problem",
]

SCHEMA = "scenegen/1"
"""The value of the root attribute ``schema``."""

ROLES: tuple[str, ...] = tuple(get_args(Role))
"""The values ``entities/role`` may take (the roles of :class:`scenegen.config.EntitySpec`
plus ``clutter``)."""

STRING = "string"
"""The dtype of string datasets: fixed-length UTF-8 (read as bytes; files written before
scenegen stored strings that way hold variable-length UTF-8, which reads as str)."""

CONVENTIONS: tuple[str, ...] = (
    "x = column, y = row; pixel (row r, column c) covers [c, c+1) x [r, r+1).",
    "A box is [x, y, w, h]: left, top, width, height, in pixels (float32).",
    "A centre is (x, y) in pixels.",
    "The box of a pixel mask is [c_min, r_min, c_max + 1 - c_min, r_max + 1 - r_min].",
    "NaN where absent: box and centre rows are NaN where the entity is not present; "
    "visible_box rows are NaN where none of its pixels is visible.",
    "Depth rank 0 = nearest the camera.",
    "Entity ids are >= 1; 0 in labels is the background.",
)
"""Conventions shared by every dataset; stored as the root attribute ``conventions``."""


@dataclass(frozen=True)
class Field:
    """One dataset of the layout.

    Attributes
    ----------
    path : str
        Path inside its group (``/sequences/<name>/`` or ``/results/<tracker>/``);
        ``<id>`` stands for each entity id.
    dtype : str
        A numpy dtype name, or ``"string"`` (fixed-length UTF-8; see :data:`STRING`).
    shape : tuple of str or int
        Symbolic shape, e.g. ``("T", "K", 4)``.
    description : str
        What the values mean, with the conventions that apply.
    units : str
        ``px``, ``fraction``, ``id``, ``rank``, ``flag``, ``RGB 0-255``, ...
    optional : bool
        A valid file may lack the dataset (see the module docstring).
    """

    path: str
    dtype: str
    shape: tuple[str | int, ...]
    description: str
    units: str
    optional: bool = False

    @property
    def name(self) -> str:
        """The last component of :attr:`path` (``gt/box`` -> ``box``)."""
        return self.path.rsplit("/", 1)[-1]

    @property
    def numpy_dtype(self) -> Any:
        """The numpy dtype, or ``str`` for string datasets."""
        return str if self.dtype == STRING else np.dtype(self.dtype).type

    def shape_for(self, **sizes: int) -> tuple[int, ...]:
        """The concrete shape given the symbol sizes, e.g. ``shape_for(T=8, K=3)``.

        Parameters
        ----------
        **sizes : int
            Size of each symbol of :attr:`shape` (``T``, ``K``, ``H``, ...); extra ones are
            ignored.

        Returns
        -------
        tuple of int
            One size per axis: the given size of a symbol, a fixed size as is
            (``("T", "K", 4)`` with T=8, K=3 gives ``(8, 3, 4)``).

        Raises
        ------
        KeyError
            If a symbol of the shape is not given.
        """
        return tuple(s if isinstance(s, int) else int(sizes[s]) for s in self.shape)

    @property
    def shape_text(self) -> str:
        """The symbolic shape as text: ``(T, K, 4)``, ``(K,)``."""
        parts = [str(s) for s in self.shape]
        return "(" + ", ".join(parts) + ("," if len(parts) == 1 else "") + ")"


@dataclass(frozen=True)
class Attribute:
    """One HDF5 attribute of a group: where, name, type and meaning.

    Attributes
    ----------
    group : str
        Where it is: ``"/"``, ``"/sequences/<name>/"``, ``"/results/<tracker>/"`` or
        ``"every dataset"``.
    name : str
        Attribute name.
    type : str
        Value type: ``"str"`` or ``"int"``.
    description : str
        What the value means.
    """

    group: str
    name: str
    type: str
    description: str


SEQUENCE_FIELDS: tuple[Field, ...] = (
    Field("frames", "uint8", ("T", "H", "W", 3), "RGB frames, one frame per chunk.",
          "RGB 0-255"),
    Field("labels", "uint16", ("T", "H", "W"),
          "Entity id of the visible surface of each pixel; 0 = background.", "id"),
    Field("entities/id", "int32", ("K",), "Entity ids (>= 1), as used in labels; entity k "
          "of every (T, K) array is the one with id entities/id[k].", "id"),
    Field("entities/role", STRING, ("K",), "Role of each entity: " + " | ".join(ROLES) + ".",
          "role"),
    Field("entities/name", STRING, ("K",), "Name of each entity (unique in the sequence).",
          "name"),
    Field("gt/box", "float32", ("T", "K", 4), "Amodal box [x, y, w, h] of the whole entity as "
          "drawn (x = column, y = row of the top-left corner); NaN where absent.", "px"),
    Field("gt/visible_box", "float32", ("T", "K", 4), "Box [x, y, w, h] of the entity's pixels "
          "in labels (x = column); NaN where none is visible.", "px"),
    Field("gt/center", "float32", ("T", "K", 2), "Amodal centre (x, y) = centre of gt/box "
          "(x = column); NaN where absent.", "px"),
    Field("gt/path_center", "float32", ("T", "K", 2), "Centre (x, y) of the noise-free motion "
          "path (the AR2 path before the per-frame position noise, not rounded to pixels; "
          "x = column); NaN where absent. Files written before this field existed lack it "
          "and read as NaN.", "px", optional=True),
    Field("gt/visibility", "float32", ("T", "K"), "Visible pixels / amodal pixels (pixels "
          "outside the frame count as not visible); 0 where absent.", "fraction"),
    Field("gt/present", "bool", ("T", "K"), "The entity exists at that frame and one pixel "
          "of its shape (its amodal mask, not merely its box's rectangle) is inside the "
          "frame.", "flag"),
    Field("gt/depth", "int16", ("T", "K"), "Depth rank per frame, 0 = nearest the camera.",
          "rank"),
    Field("templates/<id>", "uint8", ("h", "w", 4), "The entity drawn alone (RGBA; alpha 0 "
          "outside its shape): the reference model of entity <id>.", "RGBA 0-255"),
)  # fmt: skip
"""Datasets of ``/sequences/<name>/``."""

RESULT_FIELDS: tuple[Field, ...] = (
    Field("target_ids", "int32", ("M",), "The entity ids tracked, in this order.", "id"),
    Field("boxes", "float32", ("T", "M", 4), "Estimated box [x, y, w, h] per frame and target "
          "(x = column); NaN where the tracker gives none.", "px"),
    Field("orderings", "int16", ("L", "M"), "SHM trackers: each row lists target positions "
          "(indices into target_ids), nearest the camera first.", "index", optional=True),
    Field("order_prob", "float32", ("T", "L"), "SHM trackers: probability of each ordering "
          "per frame.", "probability", optional=True),
)  # fmt: skip
"""Datasets of ``/results/<tracker>/`` (``orderings`` and ``order_prob`` come together)."""

ATTRIBUTES: tuple[Attribute, ...] = (
    Attribute("/", "schema", "str", f'"{SCHEMA}"'),
    Attribute("/", "generator_version", "str", "scenegen version that wrote the file"),
    Attribute("/", "conventions", "str", "the conventions above, one per line (optional)"),
    Attribute("/sequences/<name>/", "seed", "int", "the generation seed"),
    Attribute("/sequences/<name>/", "config", "str", "JSON of the fully resolved config"),
    Attribute("/sequences/<name>/", "preset", "str", 'the preset name, "" if none'),
    Attribute("/sequences/<name>/", "n_frames", "int", "T"),
    Attribute("/sequences/<name>/", "height", "int", "H"),
    Attribute("/sequences/<name>/", "width", "int", "W"),
    Attribute("/results/<tracker>/", "tracker", "str", "the tracker name"),
    Attribute("/results/<tracker>/", "params", "str", "JSON of the tracker parameters"),
    Attribute("/results/<tracker>/", "seed", "int", "the tracker seed"),
    Attribute("/results/<tracker>/", "sequence", "str", "the name of the sequence tracked"),
    Attribute("every dataset", "description", "str", "what the values mean (optional)"),
    Attribute("every dataset", "units", "str", "px, fraction, id, rank, ... (optional)"),
)
"""Attributes of the file, its groups and datasets."""

_BY_PATH = {f.path: f for f in SEQUENCE_FIELDS} | {f"results/{f.path}": f for f in RESULT_FIELDS}


def field(path: str) -> Field:
    """The field at ``path`` (``gt/box``, ``templates/<id>``, ``results/boxes``).

    Parameters
    ----------
    path : str
        Path of a sequence dataset inside its group, or ``results/`` and the path of a
        result dataset.

    Returns
    -------
    Field

    Raises
    ------
    KeyError
        If no field has that path.

    Examples
    --------
    >>> field("gt/box").shape_text, field("results/boxes").units
    ('(T, K, 4)', 'px')
    """
    return _BY_PATH[path]


def gt_fields() -> tuple[Field, ...]:
    """The ``gt/*`` fields, in layout order.

    Returns
    -------
    tuple of Field
    """
    return tuple(f for f in SEQUENCE_FIELDS if f.path.startswith("gt/"))


GT_FIELDS: dict[str, Any] = {f.name: f.numpy_dtype for f in gt_fields()}
"""Ground-truth dataset name (under ``gt/``) -> numpy dtype, in layout order."""


def schema_problem(value: Any) -> str | None:
    """What is wrong with a file's ``schema`` attribute ``value`` (None: it is
    :data:`SCHEMA`); the text follows the file's path in a problem line.

    Parameters
    ----------
    value : object
        The attribute as read (str, bytes, a 0-d array of either, or None when it is
        missing).

    Returns
    -------
    str or None
        The problem, or None.

    Examples
    --------
    >>> schema_problem("scenegen/1") is None
    True
    >>> schema_problem(b"scenegen/2")
    "schema is 'scenegen/2', expected 'scenegen/1'"
    """
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, (bytes, np.bytes_)):
        value = bytes(value).decode(errors="replace")
    if value is None:
        return f"missing schema attribute (expected {SCHEMA!r})"
    if not isinstance(value, str):
        shape = getattr(value, "shape", None)
        what = f"an array of shape {shape}" if shape is not None else type(value).__name__
        return f"schema attribute is {what}, expected the string {SCHEMA!r}"
    if value != SCHEMA:
        return f"schema is {value!r}, expected {SCHEMA!r}"
    return None


def template_size_problem(shapes: list[tuple[int, ...]]) -> str | None:
    """What is wrong with the sizes of a sequence's templates (their ``shapes``) before
    they are read (None: nothing): together they may not exceed the generator's
    :data:`scenegen.config.MAX_TEMPLATE_PIXELS`, so a damaged or foreign file cannot ask a
    reader for terabytes.

    Parameters
    ----------
    shapes : list of tuple of int
        Shape of each template dataset, (h, w, 4); only the first two sizes count, and a
        shape of fewer than 2 axes is ignored.

    Returns
    -------
    str or None
        The problem, or None.
    """
    pixels = sum(int(np.prod(s[:2], dtype=np.float64)) for s in shapes if len(s) >= 2)
    if pixels > MAX_TEMPLATE_PIXELS:
        return (
            f"templates hold {pixels} pixels, more than the generator ever writes "
            f"({MAX_TEMPLATE_PIXELS})"
        )
    return None


def dataset_attrs(f: Field) -> dict[str, str]:
    """The attributes the writer stores on the dataset of ``f``.

    Parameters
    ----------
    f : Field
        The dataset's field.

    Returns
    -------
    dict of str to str
        ``description`` and ``units``.
    """
    return {"description": f.description, "units": f.units}


def _cell(text: str) -> str:
    return text.replace("|", "\\|")  # a literal bar inside a Markdown table cell


def _table(fields: tuple[Field, ...]) -> list[str]:
    rows = ["| dataset | dtype | shape | units | description |", "|---|---|---|---|---|"]
    for f in fields:
        text = _cell(f.description + (" Optional." if f.optional else ""))
        rows.append(f"| `{f.path}` | {f.dtype} | {f.shape_text} | {_cell(f.units)} | {text} |")
    return rows


def render_markdown() -> str:
    """``docs/format.md``: the layout as Markdown, for readers with plain h5py.

    Returns
    -------
    str
        The whole document, ending with a newline.
    """
    attrs = ["| where | attribute | type | meaning |", "|---|---|---|---|"]
    attrs += [f"| `{a.group}` | `{a.name}` | {a.type} | {a.description} |" for a in ATTRIBUTES]
    lines = [
        "# File format (schema `scenegen/1`)",
        "",
        "<!-- Generated from scenegen/io/schema.py by scenegen.io.schema.render_markdown(); "
        "tests/scenegen/io/test_schema.py checks that this file is up to date. -->",
        "",
        "scenegen writes HDF5 files. A *sequence file* holds one or more sequences under "
        "`/sequences/<name>/`; a *tracker result file* holds one group per tracker under "
        "`/results/<tracker>/`. Every dataset carries the attributes `description` and "
        "`units` (files written by older versions may lack them; they read the same).",
        "",
        "Shape symbols: `T` frames, `H` x `W` pixels (height x width), `K` entities, "
        "`M` tracked targets, `L` depth orderings, `h` x `w` a template's size.",
        "",
        "## Conventions",
        "",
        *(f"- {c}" for c in CONVENTIONS),
        "",
        "## Attributes",
        "",
        *attrs,
        "",
        "## Sequence datasets (`/sequences/<name>/`)",
        "",
        *_table(SEQUENCE_FIELDS),
        "",
        "Every dataset is stored with the Fletcher-32 checksum filter, so a damaged chunk "
        "fails to read instead of returning wrong values, and carries `sha256`, the SHA-256 "
        "of its values as stored (C order, stored dtype); the root and each sequence or "
        "result group carry `attrs_sha256`, a digest of their other attributes, and the root "
        '`integrity = "sha256"` says every dataset has a digest and the filter (`scenegen '
        "validate` checks them all; files of older versions lack them and stay valid).",
        "",
        "Strings (attributes and `entities/role`, `entities/name`) are fixed-length UTF-8, "
        "outside HDF5's unchecksummed global heap; h5py reads them as `bytes` "
        "(`.decode()`). Files of older versions hold variable-length strings (read as `str`).",
        "",
        "## Tracker result datasets (`/results/<tracker>/`)",
        "",
        *_table(RESULT_FIELDS),
        "",
        "`orderings` and `order_prob` are written together, by trackers that estimate a depth "
        "order, or not at all.",
        "",
        "## Reading with plain h5py",
        "",
        "```python",
        "import h5py",
        "",
        'with h5py.File("scene.h5", "r") as f:',
        '    name = next(iter(f["sequences"]))',
        '    g = f["sequences"][name]',
        '    frame0 = g["frames"][0]              # (H, W, 3) uint8',
        '    boxes = g["gt/box"][()]              # (T, K, 4) float32, NaN where absent',
        '    ids = g["entities/id"][()]           # entity k has id ids[k]',
        '    roles = g["entities/role"].asstr()[()]',
        '    print(g["gt/box"].attrs["description"].decode())',
        "```",
        "",
    ]
    return "\n".join(lines)
