"""Scoring a tracker result against ground truth: metrics, MOT scores and the report."""

from scenegen.evaluation import metrics, mot
from scenegen.evaluation.evaluate import evaluate, evaluate_tracks, format_table, to_json
from scenegen.evaluation.report import OverallScores, SequenceReport, TargetScores

__all__ = [
    "OverallScores",
    "SequenceReport",
    "TargetScores",
    "evaluate",
    "evaluate_tracks",
    "format_table",
    "metrics",
    "mot",
    "to_json",
]
