"""Typed evaluation reports: per-target and overall scores of one tracker on one sequence.

:class:`SequenceReport` holds one :class:`TargetScores` per target and an
:class:`OverallScores`; each has ``to_dict()`` (plain JSON types, undefined numbers None)
and the report has ``to_json()``. :func:`format_table` renders a report for a terminal.
The JSON keys are part of the public interface (``scenegen evaluate --json``): per target
and overall they include ``mota``, ``motp``, ``idf1``, ``idp``, ``idr``, ``fp``, ``fn``,
``idsw``, ``hota``, ``deta``, ``assa``, ``auc`` and ``precision_20``.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, fields
from typing import Any

from scenegen.evaluation.mot import MotScores

__all__ = ["MotSummary", "OverallScores", "SequenceReport", "TargetScores", "format_table"]


def _finite(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


@dataclass(frozen=True)
class MotSummary:
    """CLEAR MOT, identity and HOTA numbers of one row (a target, or all targets).

    Fractions in [0, 1] (MOTA can be negative); counts are ints. Computed as TrackEval
    does (:mod:`scenegen.evaluation.mot`).

    Attributes
    ----------
    mota, motp, moda : float
        CLEAR MOT accuracy, precision (mean IoU of the matches) and detection accuracy.
    tp, fp, fn, idsw, frag : int
        Matches, false positives, misses, identity switches, fragmentations.
    mt, pt, ml : int
        Objects mostly tracked, partly tracked, mostly lost.
    idf1, idp, idr : float
        Identity F1, precision and recall.
    hota, deta, assa, loca : float
        HOTA and its detection, association and localisation accuracy (means over the
        thresholds).
    scores : MotScores or None
        The full scores the numbers come from (:meth:`from_scores`), with the counts
        :func:`scenegen.evaluation.mot.combine` adds up to score several sequences as one,
        as TrackEval's ``COMBINED_SEQ``; not compared, not in :meth:`to_dict`.

    See Also
    --------
    scenegen.evaluation.mot.ClearScores, scenegen.evaluation.mot.IdentityScores,
    scenegen.evaluation.mot.HotaScores
    """

    mota: float
    motp: float
    moda: float
    tp: int
    fp: int
    fn: int
    idsw: int
    frag: int
    mt: int
    pt: int
    ml: int
    idf1: float
    idp: float
    idr: float
    hota: float
    deta: float
    assa: float
    loca: float
    scores: MotScores | None = field(default=None, compare=False, repr=False)

    @classmethod
    def from_scores(cls, s: MotScores) -> MotSummary:
        """The summary of the scores of :func:`scenegen.evaluation.mot.score_all`.

        Parameters
        ----------
        s : MotScores
            CLEAR MOT, identity and HOTA scores of one sequence (or one target).

        Returns
        -------
        MotSummary
            The same numbers, unchanged (undefined ones stay NaN until :meth:`to_dict`),
            and ``s`` itself as :attr:`scores`.

        Examples
        --------
        Two sequences scored as one, as TrackEval's summary row:

        >>> import numpy as np
        >>> from scenegen.evaluation.mot import combine, mot_frames, score_all
        >>> gt = np.array([[[0, 0, 10, 10.]], [[1, 0, 10, 10.]]])      # (T=2, K=1, 4)
        >>> a = MotSummary.from_scores(score_all(mot_frames(gt, gt)))
        >>> b = MotSummary.from_scores(score_all(mot_frames(gt, np.full_like(gt, np.nan))))
        >>> MotSummary.from_scores(combine([a.scores, b.scores])).mota
        0.5
        """
        c, i, h = s.clear, s.identity, s.hota
        return cls(
            mota=c.mota, motp=c.motp, moda=c.moda, tp=c.tp, fp=c.fp, fn=c.fn, idsw=c.idsw,
            frag=c.frag, mt=c.mt, pt=c.pt, ml=c.ml, idf1=i.idf1, idp=i.idp, idr=i.idr,
            hota=h.hota, deta=h.deta, assa=h.assa, loca=h.loca, scores=s,
        )  # fmt: skip

    def to_dict(self) -> dict[str, Any]:
        """The numbers as plain JSON types.

        Returns
        -------
        dict of str to float, int or None
            One key per attribute (``mota`` ... ``loca``; not :attr:`scores`), in field
            order; floats that are NaN or infinite become None, counts stay ints.
        """
        values = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "scores"}
        return {k: (_finite(v) if isinstance(v, float) else v) for k, v in values.items()}


@dataclass(frozen=True)
class TargetScores:
    """Scores of one target.

    Attributes
    ----------
    id, name : int, str
        The target entity.
    track_id : int or None
        The tracker's track scored against it (None: no track paired).
    frames : int
        Frames evaluated (ground truth counts there, see ``gt_mode``).
    tracked : float or None
        % of those frames with DPS track state 1.
    success, recovered : bool or None
        Tracked in every frame; tracked in the final frames.
    precision, recall : float or None
        DPS precision and recall, % over tracked frames.
    mean_iou, mean_centre_error : float or None
        Mean IoU; mean centre error in pixels over frames with an estimate.
    auc, precision_20 : float or None
        OTB success AUC and precision at 20 px.
    failure_frame : int
        KAMS failure frame (a frame of the sequence, counted from 0; the persistence is
        counted over the frames where the target is scored), -1 if none.
    mot : MotSummary
        CLEAR MOT / identity / HOTA of this target against its track alone.
    """

    id: int
    name: str
    track_id: int | None
    frames: int
    tracked: float | None
    success: bool | None
    recovered: bool | None
    precision: float | None
    recall: float | None
    mean_iou: float | None
    mean_centre_error: float | None
    auc: float | None
    precision_20: float | None
    failure_frame: int
    mot: MotSummary

    def to_dict(self) -> dict[str, Any]:
        """The target's scores as one flat dict of plain JSON types.

        Returns
        -------
        dict of str to int, str, float, bool or None
            Every attribute but ``mot`` (``id``, ``name``, ``track_id``, ``frames``,
            ``tracked``, ... ``failure_frame``), then the keys of
            :meth:`MotSummary.to_dict` (``mota``, ``idf1``, ``hota``, ...) at the same
            level; floats that are NaN or infinite become None.
        """
        out = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "mot"}
        for k, v in out.items():
            if isinstance(v, float):
                out[k] = _finite(v)
        out.update(self.mot.to_dict())
        return out


@dataclass(frozen=True)
class OverallScores:
    """Scores over all targets of the sequence.

    Attributes
    ----------
    mean_iou : float or None
        Mean IoU over every evaluated frame of the targets present at frame 0 (pooled):
        the targets a tracker is started on, whatever the tracks came from.
    auc, precision_20 : float or None
        OTB success AUC and precision at 20 px, over the targets present at frame 0: the
        mean of their per-target values
        (``otb_average == "sequence"``: each target is one OTB sequence, averaged as the
        OTB toolkit averages sequences) or from all frames pooled (``"frames"``).
    otb_average : str
        ``"sequence"`` or ``"frames"``.
    mot : MotSummary
        CLEAR MOT / identity / HOTA of all targets against all tracks.
    depth_order_accuracy : float or None
        SHM trackers: % of overlapping target pairs in the right depth order.
    """

    mean_iou: float | None
    auc: float | None
    precision_20: float | None
    otb_average: str
    mot: MotSummary
    depth_order_accuracy: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """The overall scores as one flat dict of plain JSON types.

        Returns
        -------
        dict of str to float, int, str or None
            ``mean_iou``, ``auc``, ``precision_20``, ``otb_average``, then the keys of
            :meth:`MotSummary.to_dict` at the same level, then ``depth_order_accuracy``
            only when it is not None; floats that are NaN or infinite become None.
        """
        out: dict[str, Any] = {
            "mean_iou": _finite(self.mean_iou),
            "auc": _finite(self.auc),
            "precision_20": _finite(self.precision_20),
            "otb_average": self.otb_average,
        }
        out.update(self.mot.to_dict())
        if self.depth_order_accuracy is not None:
            out["depth_order_accuracy"] = _finite(self.depth_order_accuracy)
        return out


@dataclass(frozen=True)
class SequenceReport:
    """One tracker's scores on one sequence.

    Attributes
    ----------
    sequence, tracker : str
    n_frames : int
    gt_mode : str
        ``"amodal"`` or ``"visible"`` (see :mod:`scenegen.io.mot`).
    visibility_threshold : float
        ``visible`` mode: a target counts where its visible fraction exceeds this.
    targets : tuple of TargetScores
    overall : OverallScores
    """

    sequence: str
    tracker: str
    n_frames: int
    gt_mode: str
    visibility_threshold: float
    targets: tuple[TargetScores, ...]
    overall: OverallScores

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types; undefined numbers are None.

        Returns
        -------
        dict of str to object
            ``sequence``, ``tracker``, ``n_frames``, ``gt_mode``, ``visibility_threshold``
            (as stored), ``targets`` (a list of :meth:`TargetScores.to_dict`, in order)
            and ``overall`` (:meth:`OverallScores.to_dict`).
        """
        return {
            "sequence": self.sequence,
            "tracker": self.tracker,
            "n_frames": self.n_frames,
            "gt_mode": self.gt_mode,
            "visibility_threshold": self.visibility_threshold,
            "targets": [t.to_dict() for t in self.targets],
            "overall": self.overall.to_dict(),
        }

    def to_json(self) -> str:
        """One JSON document (sorted keys, no NaN).

        Returns
        -------
        str
            :meth:`to_dict` serialised on one line by ``json.dumps``, keys sorted.

        Raises
        ------
        ValueError
            If ``visibility_threshold`` is NaN or infinite (the one float written as
            stored; :func:`scenegen.evaluation.evaluate` only makes it in [0, 1)).
        """
        return json.dumps(self.to_dict(), sort_keys=True, allow_nan=False)


def _fmt(v: Any, digits: int = 1) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    return f"{v:.{digits}f}"


def _table(head: list[str], rows: list[list[str]]) -> list[str]:
    widths = [max(len(r[i]) for r in [head, *rows]) for i in range(len(head))]
    lines = [
        "  ".join(h.rjust(w) for h, w in zip(head, widths, strict=True)),
        "  ".join("-" * w for w in widths),
    ]
    return lines + ["  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)) for r in rows]


def _mot_cells(m: MotSummary) -> list[str]:
    return [
        _fmt(m.mota, 3), _fmt(m.motp, 3), _fmt(m.idf1, 3), _fmt(m.idp, 3), _fmt(m.idr, 3),
        str(m.fp), str(m.fn), str(m.idsw), str(m.frag), str(m.mt), str(m.ml),
        _fmt(m.hota, 3), _fmt(m.deta, 3), _fmt(m.assa, 3), _fmt(m.loca, 3),
    ]  # fmt: skip


def format_table(report: SequenceReport) -> str:
    """Render a report as two plain-text tables (single-target and multi-object scores).

    Parameters
    ----------
    report : SequenceReport
        The report to render.

    Returns
    -------
    str
        A header line, the two tables (each with an ``all`` row for the overall scores) and
        a one-line overall summary, joined by newlines; undefined numbers show as ``-``.
    """
    thr = f" > {report.visibility_threshold:g}" if report.gt_mode == "visible" else ""
    lines = [
        f"sequence {report.sequence!r}, tracker {report.tracker!r}, {report.n_frames} frames, "
        f"ground truth {report.gt_mode}{thr}",
        "",
        "single-target scores (DPS, OTB, KAMS):",
    ]
    head = ["id", "name", "frames", "tracked%", "success", "recovered", "prec%", "rec%", "IoU",
            "err px", "AUC", "P@20", "fail@"]  # fmt: skip
    rows = [
        [
            _fmt(t.id), t.name, str(t.frames), _fmt(t.tracked), _fmt(t.success),
            _fmt(t.recovered), _fmt(t.precision), _fmt(t.recall), _fmt(t.mean_iou, 3),
            _fmt(t.mean_centre_error), _fmt(t.auc, 3), _fmt(t.precision_20, 3),
            "-" if t.failure_frame < 0 else str(t.failure_frame),
        ]
        for t in report.targets
    ]  # fmt: skip
    o = report.overall
    avg = "mean over targets" if o.otb_average == "sequence" else "pooled frames"
    rows.append(["all", "", "", "", "", "", "", "", _fmt(o.mean_iou, 3), "", _fmt(o.auc, 3),
                 _fmt(o.precision_20, 3), ""])  # fmt: skip
    lines += _table(head, rows)
    lines.append(f"(overall AUC and P@20: {avg})")
    lines += ["", "multi-object scores (CLEAR MOT, identity, HOTA; as TrackEval):"]
    head = ["id", "track", "MOTA", "MOTP", "IDF1", "IDP", "IDR", "FP", "FN", "IDSW", "Frag",
            "MT", "ML", "HOTA", "DetA", "AssA", "LocA"]  # fmt: skip
    rows = [[_fmt(t.id), _fmt(t.track_id), *_mot_cells(t.mot)] for t in report.targets]
    rows.append(["all", "", *_mot_cells(o.mot)])
    lines += _table(head, rows)
    summary = (
        f"overall: MOTA {_fmt(o.mot.mota, 3)}  MOTP {_fmt(o.mot.motp, 3)}  "
        f"IDF1 {_fmt(o.mot.idf1, 3)}  HOTA {_fmt(o.mot.hota, 3)}  AUC {_fmt(o.auc, 3)}  "
        f"P@20 {_fmt(o.precision_20, 3)}"
    )
    if o.depth_order_accuracy is not None:
        summary += f"  depth order {_fmt(o.depth_order_accuracy)}%"
    lines += ["", summary]
    return "\n".join(lines)
