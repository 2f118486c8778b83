"""Reading a dataset folder lazily: by index, by a query on the drawn parameters, as samples.

Examples
--------
>>> import scenegen                                                 # doctest: +SKIP
>>> ds = scenegen.open_dataset("data/kams")                         # doctest: +SKIP
>>> len(ds), ds.params                                              # doctest: +SKIP
(200, ['preset'])
>>> seq = ds[3]                 # a Sequence; frames stay on disk     # doctest: +SKIP
>>> hard = ds.select(preset="kams-d")                               # doctest: +SKIP
>>> noisy = ds.select(position_noise=(8, None))   # a range: 8 <= value  # doctest: +SKIP
>>> for frames, boxes in ds.samples(clip=16):      # (16, H, W, 3) uint8, (16, M, 4) float32
...     pass                                                        # doctest: +SKIP
"""

from __future__ import annotations

import re
from collections import OrderedDict
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from scenegen.datasets.build import read_manifest
from scenegen.errors import ConfigError

__all__ = ["Dataset", "Samples", "open_dataset"]


def _short_key(name: str) -> str:
    """The last field of a parameter path, without indices: ``clutter[0].count`` -> count."""
    return re.sub(r"\[[^\]]*\]", "", name).rsplit(".", 1)[-1]


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float, np.number)) and not isinstance(value, (bool, np.bool_))


def _plain(value: Any) -> Any:
    """``value`` with tuples as lists (a manifest holds JSON lists), recursively."""
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _equal(value: Any, want: Any) -> bool:
    try:
        return bool(_plain(value) == _plain(want))
    except (TypeError, ValueError):  # e.g. an array, whose == is not one truth value
        return False


def _matches(name: str, value: Any, want: Any) -> bool:
    if callable(want):
        return bool(want(value))
    if isinstance(want, set | frozenset):
        return any(_equal(value, w) for w in want)
    if isinstance(want, tuple) and len(want) == 2 and not isinstance(value, (list, tuple)):
        lo, hi = want
        if not all(b is None or _is_number(b) for b in want):
            raise ConfigError(
                f"select: {name}={_shown(want)}: a range (low, high) takes numbers or None; "
                "give a set for several accepted values"
            )
        if not _is_number(value):
            return False
        return (lo is None or value >= lo) and (hi is None or value <= hi)
    return _equal(value, want)


class Dataset:
    """A dataset folder, opened lazily: only ``manifest.json`` is read up front.

    Attributes
    ----------
    root : Path
    manifest : dict
        The whole manifest (header and every entry).
    entries : list of dict
        The manifest entries of the sequences in this dataset (or selection), in order.
    """

    def __init__(self, root: Path, manifest: dict[str, Any], entries: list[dict[str, Any]]):
        self.root = root
        self.manifest = manifest
        self.entries = entries

    def __len__(self) -> int:
        return len(self.entries)

    def __repr__(self) -> str:
        return (
            f"Dataset({str(self.root)!r}, family={self.manifest.get('family')!r}, "
            f"sequences={len(self)})"
        )

    @property
    def params(self) -> list[str]:
        """Names of the parameters each sequence records (swept and drawn)."""
        return list(self.manifest.get("params", []))

    def _entry(self, i: int) -> dict[str, Any]:
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)):
            raise TypeError(f"dataset indices are integers, got {type(i).__name__}")
        n = len(self.entries)
        if not -n <= i < n:
            raise IndexError(f"index {i} out of range for a dataset of {n} sequences")
        return self.entries[int(i)]

    def __getitem__(self, i: int) -> Any:
        """Sequence ``i`` (:func:`scenegen.read`: ground truth in memory, pixels lazy)."""
        from scenegen.io import read

        e = self._entry(i)
        return read(self.root / e["file"], e["name"])

    def __iter__(self) -> Iterator[Any]:
        for i in range(len(self)):
            yield self[i]

    def path(self, i: int) -> Path:
        """The shard file holding sequence ``i``.

        Parameters
        ----------
        i : int
            Index into this dataset (or selection), ``-len(ds) <= i < len(ds)``.

        Returns
        -------
        Path
            ``root / <its shard file>`` (``shard-NNNNN.h5``); the file is not opened.

        Raises
        ------
        TypeError
            If ``i`` is not an integer.
        IndexError
            If ``i`` is out of range.
        """
        return self.root / self._entry(i)["file"]

    def _param_key(self, key: str) -> str:
        names = self.params
        if key in names:
            return key
        hits = [n for n in names if _short_key(n) == key]
        if len(hits) == 1:
            return hits[0]
        if not hits:
            raise ConfigError(
                f"no parameter {key!r} in dataset {self.root}; parameters: "
                f"{', '.join(names) or 'none'}"
            )
        raise ConfigError(f"parameter {key!r} is ambiguous: {', '.join(hits)}")

    def select(self, where: dict[str, Any] | None = None, **params: Any) -> Dataset:
        """The sequences whose drawn parameters match, as a (lazy) dataset.

        Parameters
        ----------
        where : dict, optional
            Conditions keyed by full parameter name (``{"clutter[0].count": 300}``).
        **params : Any
            Conditions keyed by name or by the last field of a path (``count=300``,
            ``position_noise=(4, 8)``). A value matches by equality (a list or a dict
            matches a parameter of that value, such as a swept size ``[44, 44]``; tuples
            and lists compare alike); a 2-tuple ``(low, high)`` of numbers or None is an
            inclusive range (None: open) for a numeric parameter; a set lists the
            accepted values; a callable is a predicate. Every condition must hold, also
            two on the same parameter (one in ``where``, one here).

        Returns
        -------
        Dataset
            The matching entries, in this dataset's order (same root and manifest); no
            condition: all of them.

        Raises
        ------
        ConfigError
            For a parameter the dataset does not record (or a last field that several
            parameters end with), a ``where`` that is not a mapping, or a range whose
            bounds are not numbers (one line naming the parameter and the value).
        """
        if where is not None and not isinstance(where, dict):
            raise ConfigError(
                f"select: where must be a dict of parameter names to conditions, got "
                f"{_shown(where)}"
            )
        conds = [(self._param_key(k), v) for k, v in [*(where or {}).items(), *params.items()]]
        keep = [
            e for e in self.entries
            if all(_matches(k, e["params"].get(k), v) for k, v in conds)
        ]  # fmt: skip
        return Dataset(self.root, self.manifest, keep)

    def samples(
        self, *, clip: int | None = None, stride: int | None = None, gt: str = "box"
    ) -> Samples:
        """Map-style samples ``(frames, boxes)``, for a PyTorch-style loader.

        See :class:`Samples`.

        Parameters
        ----------
        clip : int, optional
            Window length L (frames), >= 1; None: whole sequences.
        stride : int, optional
            Frames between window starts, >= 1 (default: ``clip``); unused without
            ``clip``.
        gt : {'box', 'visible_box'}, default 'box'
            Amodal or visible boxes.

        Returns
        -------
        Samples
            Samples of (frames of shape (L, H, W, 3), uint8; boxes of shape (L, M, 4),
            float32) over this dataset's sequences.

        Raises
        ------
        ConfigError
            If ``clip`` or ``stride`` is not an integer >= 1 (or None), or ``gt`` is not
            one of the two names.
        """
        return Samples(self, clip=clip, stride=stride, gt=gt)


class Samples:
    """``(frames, boxes)`` pairs read on demand: ``len``, ``[j]`` and iteration.

    Without ``clip`` a sample is a whole sequence; with ``clip=L`` it is a window of L
    frames (windows start every ``stride`` frames, default L). Only the frames indexed
    are read from disk, and at most a few sequences' ground truth is cached per process.
    It is picklable (the cache is not), so a loader's worker processes each open the
    files themselves. It works with ``torch.utils.data.DataLoader`` as is (numpy arrays
    are collated into tensors), and without torch as a plain iterable.

    A sample (``samples[j]``, and each item of the iteration) is a tuple
    ``(frames, boxes)``:

    - ``frames``: ndarray of shape (L, H, W, 3), uint8 (L the sequence's length without
      ``clip``);
    - ``boxes``: ndarray of shape (L, M, 4), float32. The boxes [x, y, w, h] (px) of the
      sequence's M targets; NaN where absent.

    Parameters
    ----------
    dataset : Dataset
        The dataset (:func:`open_dataset`).
    clip : int, optional
        Window length L (frames), >= 1; None: whole sequences. A sequence shorter than
        L gives no window.
    stride : int, optional
        Frames between window starts, >= 1 (default: ``clip``); unused without ``clip``.
    gt : {'box', 'visible_box'}, default 'box'
        Amodal or visible boxes.

    Raises
    ------
    ConfigError
        If ``clip`` or ``stride`` is not an integer >= 1 (or None), or ``gt`` is not one
        of the two names (one line naming the parameter and the value).
    """

    _CACHE = 4

    def __init__(
        self,
        dataset: Dataset,
        *,
        clip: int | None = None,
        stride: int | None = None,
        gt: str = "box",
    ) -> None:
        if not isinstance(gt, str) or gt not in ("box", "visible_box"):
            raise ConfigError(f"gt must be 'box' or 'visible_box', got {_shown(gt)}")
        for label, value in (("clip", clip), ("stride", stride)):
            if value is not None and not (
                isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value >= 1
            ):
                raise ConfigError(f"{label} must be an integer >= 1 or None, got {_shown(value)}")
        clip = None if clip is None else int(clip)
        stride = None if stride is None else int(stride)
        self.dataset = dataset
        self.clip = clip
        self.gt = gt
        step = stride or clip or 1
        self.index: list[tuple[int, int, int]] = []
        for i, e in enumerate(dataset.entries):
            t_n = int(e["n_frames"])
            if clip is None:
                self.index.append((i, 0, t_n))
            else:
                for start in range(0, t_n - clip + 1, step):
                    self.index.append((i, start, start + clip))
        self._cache: OrderedDict[int, Any] = OrderedDict()

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state["_cache"] = OrderedDict()
        return state

    def __len__(self) -> int:
        return len(self.index)

    def _sequence(self, i: int) -> Any:
        if i in self._cache:
            self._cache.move_to_end(i)
            return self._cache[i]
        seq = self.dataset[i]
        self._cache[i] = seq
        while len(self._cache) > self._CACHE:
            self._cache.popitem(last=False)
        return seq

    def __getitem__(self, j: int) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
        i, start, stop = self.index[j]
        seq = self._sequence(i)
        targets = seq.target_indices()
        frames = np.asarray(seq.frames[start:stop])
        boxes = np.asarray(getattr(seq.gt, self.gt)[start:stop][:, targets], dtype=np.float32)
        return frames, boxes

    def __iter__(self) -> Iterator[tuple[NDArray[np.uint8], NDArray[np.float32]]]:
        for j in range(len(self)):
            yield self[j]


def open_dataset(root: str | Path) -> Dataset:
    """Open a dataset folder made by ``scenegen dataset`` (reads only its manifest).

    Parameters
    ----------
    root : str or Path

    Returns
    -------
    Dataset
        ``len(ds)``, ``ds[i]`` (a lazily read Sequence), ``ds.manifest``,
        ``ds.select(**params)`` and ``ds.samples(clip=...)``.

    Raises
    ------
    DataError
        If the folder holds no valid manifest, or one with a damaged entry (one line
        naming ``manifest.json`` and the entry; :func:`scenegen.datasets.build.manifest_entries`).
    """
    p = Path(root)
    manifest = read_manifest(p)
    entries = sorted(manifest["sequences"], key=lambda e: e["index"])
    return Dataset(p, manifest, entries)
