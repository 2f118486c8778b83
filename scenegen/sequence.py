"""The in-memory (or lazily read) result of generation: frames, labels and ground truth."""

from __future__ import annotations

import operator
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from scenegen.config import SceneConfig

__all__ = ["Entities", "GroundTruth", "Sequence"]


def __getattr__(name: str) -> Any:
    # GT_FIELDS (HDF5 name -> dtype of every ground-truth array) is defined by the layout,
    # scenegen.io.schema; imported lazily because scenegen.io imports this module.
    if name == "GT_FIELDS":
        from scenegen.io.schema import GT_FIELDS

        return GT_FIELDS
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass
class Entities:
    """The K entities of a sequence.

    Attributes
    ----------
    id : ndarray of shape (K,), int32
        Ids as used in ``labels`` (>= 1).
    role : ndarray of shape (K,), str
        ``target``, ``distractor``, ``occluder`` or ``clutter``.
    name : ndarray of shape (K,), str
    """

    id: NDArray[np.int32]
    role: NDArray[np.str_]
    name: NDArray[np.str_]

    def __len__(self) -> int:
        return int(self.id.shape[0])

    def index_of(self, name: str) -> int:
        """Index (into K) of the entity called ``name``.

        Parameters
        ----------
        name : str
            The entity's name (an entry of :attr:`name`).

        Returns
        -------
        int
            Its index into K; the first one if several share the name.

        Raises
        ------
        KeyError
            If no entity is called ``name``.
        """
        hits = np.flatnonzero(self.name == name)
        if hits.size == 0:
            raise KeyError(f"no entity named {name!r}")
        return int(hits[0])


@dataclass
class GroundTruth:
    """Per-frame ground truth: the ``gt/*`` datasets of the file layout.

    Each attribute is the dataset ``gt/<attribute>``; what its values mean is defined once,
    in :data:`scenegen.io.schema.SEQUENCE_FIELDS` (rendered in ``docs/format.md``). Boxes
    are [x, y, w, h] with x = column, in pixels; NaN (or 0, False) where absent.

    Attributes
    ----------
    box : ndarray of shape (T, K, 4), float32
        Amodal box (``gt/box``).
    visible_box : ndarray of shape (T, K, 4), float32
        Box of the entity's pixels in ``labels`` (``gt/visible_box``).
    center : ndarray of shape (T, K, 2), float32
        Amodal centre (``gt/center``).
    visibility : ndarray of shape (T, K), float32
        Visible fraction (``gt/visibility``).
    present : ndarray of shape (T, K), bool
        Present at that frame (``gt/present``).
    depth : ndarray of shape (T, K), int16
        Depth rank, 0 = nearest the camera (``gt/depth``).
    path_center : ndarray of shape (T, K, 2), float32
        Centre of the noise-free motion path (``gt/path_center``); NaN everywhere when
        read from a file written before this field existed.
    """

    box: NDArray[np.float32]
    visible_box: NDArray[np.float32]
    center: NDArray[np.float32]
    visibility: NDArray[np.float32]
    present: NDArray[np.bool_]
    depth: NDArray[np.int16]
    path_center: NDArray[np.float32]

    def as_dict(self) -> dict[str, NDArray[Any]]:
        """Every array keyed by its name under ``gt/``.

        Returns
        -------
        dict of str to ndarray
            The seven arrays (not copies), keyed ``box``, ``visible_box``, ``center``,
            ``visibility``, ``present``, ``depth``, ``path_center``; shapes (T, K, 4),
            (T, K, 2) or (T, K) as in the attributes.
        """
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass
class Sequence:
    """A generated (or read) sequence.

    Attributes
    ----------
    name : str
    seed : int
    config : SceneConfig
        The fully resolved configuration.
    preset : str
        The preset name, "" if none.
    frames : array-like of shape (T, H, W, 3), uint8
        RGB frames (a numpy array, or a lazy array when read from a file).
    labels : array-like of shape (T, H, W), uint16
        Entity id of the visible surface; 0 is the background.
    entities : Entities
    gt : GroundTruth
    templates : dict of int to ndarray of shape (h, w, 4)
        Each entity drawn alone (RGBA), keyed by entity id.
    """

    name: str
    seed: int
    config: SceneConfig
    preset: str
    frames: Any
    labels: Any
    entities: Entities
    gt: GroundTruth
    templates: dict[int, NDArray[np.uint8]] = field(default_factory=dict)

    @property
    def n_frames(self) -> int:
        """Number of frames T, an int (``frames.shape[0]``)."""
        return int(self.frames.shape[0])

    @property
    def height(self) -> int:
        """Frame height H in pixels, an int (``frames.shape[1]``)."""
        return int(self.frames.shape[1])

    @property
    def width(self) -> int:
        """Frame width W in pixels, an int (``frames.shape[2]``)."""
        return int(self.frames.shape[2])

    def target_indices(self) -> NDArray[np.intp]:
        """Indices (into K) of the entities whose role is ``target``, in id order.

        Returns
        -------
        ndarray of shape (M,), intp
            Ascending indices into K of the M targets (whether present or not).
        """
        return np.flatnonzero(self.entities.role == "target")

    def target_ids(self) -> NDArray[np.int32]:
        """Ids of the targets, shape (M,).

        Returns
        -------
        ndarray of shape (M,), int32
            ``entities.id`` at :meth:`target_indices`.
        """
        return self.entities.id[self.target_indices()]

    def initial_targets(self, frame: int = 0) -> NDArray[np.intp]:
        """Indices (into K) of the targets present at ``frame``: the ones a tracker follows.

        This is the one definition of "which targets are tracked": ``scenegen track``, the
        experiments and the fixtures all start from these.

        Parameters
        ----------
        frame : int, default 0
            The frame index (0 <= frame < T; negative counts from the end).

        Returns
        -------
        ndarray of shape (M,), intp
            Ascending indices into K of the targets with ``gt.present[frame]`` true.

        Raises
        ------
        TypeError
            If ``frame`` is not an integer (a bool is not one).
        IndexError
            If ``frame`` is outside [-T, T - 1]; the message names ``frame`` and the range.
        """
        t = self._frame(frame)
        idx = self.target_indices()
        return idx[np.asarray(self.gt.present[t, idx], dtype=bool)]

    def init_boxes(self, frame: int = 0) -> NDArray[np.float64]:
        """Amodal boxes (M, 4) of :meth:`initial_targets` at ``frame``: what trackers start from.

        Parameters
        ----------
        frame : int, default 0
            The frame index (0 <= frame < T; negative counts from the end).

        Returns
        -------
        ndarray of shape (M, 4), float64
            ``gt.box`` of those targets at ``frame``, [x, y, w, h] in pixels.

        Raises
        ------
        TypeError
            If ``frame`` is not an integer (a bool is not one).
        IndexError
            If ``frame`` is outside [-T, T - 1]; the message names ``frame`` and the range.
        """
        return np.asarray(self.gt.box[self._frame(frame), self.initial_targets(frame)],
                          dtype=np.float64)

    def _frame(self, frame: Any) -> int:
        """``frame`` as an int index into T; else one line naming ``frame`` and the range."""
        t = int(self.gt.present.shape[0])
        try:
            i = None if isinstance(frame, bool) else operator.index(frame)
        except TypeError:
            i = None
        if i is None:
            got = repr(frame)
            got = got if len(got) <= 40 and "\n" not in got else type(frame).__name__
            raise TypeError(f"frame must be an integer in [{-t}, {t - 1}], got {got}")
        if not -t <= i < t:
            raise IndexError(f"frame must be an integer in [{-t}, {t - 1}], got {i}")
        return i

    def __repr__(self) -> str:
        t, h, w = self.n_frames, self.height, self.width
        return (
            f"Sequence(name={self.name!r}, seed={self.seed}, preset={self.preset!r}, "
            f"frames={t}x{h}x{w}, entities={len(self.entities)})"
        )

    def _repr_pretty_(self, p: Any, cycle: bool) -> None:
        # Hypothesis (and IPython) pretty-print dataclasses field by field otherwise.
        p.text(repr(self))
