"""Scoring a tracker result against ground truth: metrics and the evaluation report."""

from scenegen.evaluation import metrics
from scenegen.evaluation.evaluate import evaluate, format_table, to_json

__all__ = ["evaluate", "format_table", "metrics", "to_json"]
