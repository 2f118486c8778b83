"""Mutation testing of the formula modules with cosmic-ray (``make mutate``).

Usage::

    python tools/mutation/mutate.py [MODULE ...] [--count] [--report] [--retest]
        [--sample N] [--only ITEM ...] [--timeout SECONDS]

MODULE is a key of ``MODULES`` (default: all, one after another). For each module:

1. the sources (``scenegen``, ``trackers``, ``tests``, ``fixtures``, ``pyproject.toml``) are
   copied to ``build/mutate/tree`` (once; file times kept, so the numba caches stay
   valid), and cosmic-ray mutates that copy, never the working tree;
2. ``cosmic-ray init`` lists every mutation of the module; this script then marks as
   skipped the mutations outside the module's *formula scope* (the functions listed in
   ``MODULES``: the algorithm, not argument checking and error messages) and every
   mutation but one canonical replacement per operator site (``CANONICAL``: a + b -> a - b,
   a * b -> a / b, a < b -> a <= b, ...; as mutmut does, instead of cosmic-ray's every
   operator for every operator);
3. at most ``--sample`` of them (default 25, a seeded choice that depends only on the
   source) are run, to keep a module's run within minutes; ``--sample 0`` runs all.
   ``--only`` (one module) narrows the choice to some functions of the scope and line
   ranges of the file, e.g. the functions added since the module's last full run;
4. the module's test command (the fast tests that guard it, selected by path) must pass
   on the unmutated copy; then ``cosmic-ray exec`` runs it once per mutant, stopping at
   the first failure (``-x``); a mutant is killed if a test fails or times out (the limit
   is the larger of the module's ``min_timeout`` and 4 x the baseline run, or
   ``--timeout``; the report lists each timed-out mutant as TIMEOUT, to be checked: a
   loop that cannot end, or a survivor that ran out of time);
5. the score and the surviving mutants (with their diffs) are written to
   ``build/mutate/<module>.txt`` and printed. A surviving mutant listed in
   ``equivalent.py`` is reported as equivalent: an entry names its line by text, and
   when that line occurs more than once in the scope, by its function too (and the line
   above it, if the function holds it twice); the module is refused otherwise
   (``ambiguities``), so that an entry never excuses a copy it was not meant for.

cosmic-ray rather than mutmut: mutmut 3 does not mutate decorated functions (its
trampolines cannot wrap them), so every ``@njit`` kernel of the mean shift would be left
out; cosmic-ray edits the source file, and the numba functions recompile from the
mutated source (the module's tests run with the JIT on and NUMBA_BOUNDSCHECK=1;
NUMBA_DISABLE_JIT is not needed: recompiling the mean-shift kernels costs about 3 s a
mutant, less than running its tests in the interpreter).

A session database per module (``build/mutate/<module>.sqlite``) keeps the results:
running again resumes with the mutants not yet run (a wider ``--sample`` or ``--only``
adds the mutants it newly selects). ``--count`` only initialises and prints how many
mutants would run; ``--report`` only prints the stored results; ``--retest`` runs the
survivors again (with ``--only``, only those on its lines: the other survivors keep their
results instead of being skipped as outside the choice).
"""

from __future__ import annotations

import argparse
import ast
import hashlib
import os
import re
import shlex
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BUILD = ROOT / "build" / "mutate"
TREE = BUILD / "tree"
COPIED = ("scenegen", "trackers", "tests", "fixtures", "pyproject.toml")


@dataclass(frozen=True)
class Module:
    path: str
    scope: tuple[str, ...]          # qualified function names (Class.method or function)
    tests: tuple[str, ...]          # pytest arguments (paths, -k expressions)
    env: dict[str, str] = field(default_factory=dict)
    # The least timeout (s); the timeout is the larger of this and 4 x the baseline run.
    min_timeout: float = 30.0


_MEAN_SHIFT_TESTS = (
    "tests/trackers/test_meanshift_trackers.py", "tests/trackers/test_kams.py",
    "tests/trackers/test_oracle_meanshift.py", "tests/trackers/test_meanshift_scenes.py",
    "tests/trackers/test_equivalences.py",
)

# The generator's tests (the README is not copied to the mutation tree: its example's
# test is left out).
_RENDER_TESTS = (
    "tests/scenegen/render/test_generator.py", "tests/scenegen/render/test_realistic.py",
    "--deselect",
    "tests/scenegen/render/test_realistic.py::test_readme_realistic_example_generates",
)
# Hypothesis without shrinking (tests/conftest.py): a failing example kills the mutant,
# and shrinking it took 20-40 s a mutant in the generator's drawn scenes.
_NO_SHRINK = {"HYPOTHESIS_PROFILE": "mutate"}
# The histogram kernels' tests: per-box numpy transcriptions of every kernel, the paths
# (direct, support, integral) against them and against each other, the box kernel, and
# which path each box takes (the cost model transcribed, the dispatch following it).
_HISTOGRAM_TESTS = (
    "tests/trackers/models/test_observation.py", "tests/trackers/models/test_box_kernel.py",
    "tests/trackers/models/test_histogram_paths.py",
)

# A mutant of a file of trackers/kernels drops every kernel's numba cache (numba_cache.py),
# so its tests recompile every kernel they use (about 40 s, more on the shared cores),
# while the baseline run that sets the timeout finds the cache warm: 4 x the baseline
# (47-80 s) timed out mutants that would have survived (found with ``stages`` and
# ``sampling``, where half the mutants of the first runs counted as killed by a timeout
# were annotations and shape[-1] of one-dimensional arrays).
_KERNEL_TIMEOUT = 400.0

MODULES: dict[str, Module] = {
    "resampling": Module(
        "trackers/filters/resampling.py",
        ("group_starts", "_finite_non_negative", "_normalise_groups", "_draw",
         "resample_groups", "_resample_normalised", "resample", "weighted_resample_groups",
         "weighted_resample"),
        ("tests/trackers/filters/test_resampling.py",
         "tests/trackers/filters/test_resampling_oracle.py",
         "tests/trackers/test_equivalences.py"),
    ),
    "particle": Module(
        "trackers/particle.py",
        ("circular_shift", "_ParticleTracker._init", "_ParticleTracker._boxes",
         "_ParticleTracker._estimate",
         "Condensation._init", "Condensation._step", "JointPF._step",
         "_Partitioned._layout", "_Partitioned._partitioned_step", "_Partitioned._reassemble",
         "PartitionedSampling._groups", "DistributedPartitionedSampling._init",
         "DistributedPartitionedSampling._groups", "DistributedPartitionedSampling._step"),
        ("tests/trackers/test_oracle_particle.py", "tests/trackers/test_equivalences.py",
         "tests/trackers/test_particle.py", "tests/trackers/test_ps_weighting.py",
         "tests/trackers/test_stage_kernels.py"),
    ),
    # The compiled stages of the particle filters' step: numpy's pairwise sum replicated,
    # the AR2 propagation of each particle's stage object, the stage's boxes and
    # log-weights, the group normalisation, the weighted resampling with its gathers (joint
    # and placed scope), the DPS reassembly, the posterior log-weights (row sums), the
    # estimate, the diagnostics and the clipping of returned boxes. Left out:
    # the test-only wrappers numpy_sum and numpy_reduceat_sum, and the checks (_valid,
    # normalise_groups_checked) that only send bad weights to numpy's path, which raises.
    "stages": Module(
        "trackers/kernels/stages.py",
        ("_pairwise_block", "_pairwise", "_numpy_sum", "_numpy_reduceat_sum",
         "_propagate_objects", "_state_boxes", "_stage_log_weights", "_normalise_groups",
         "_gather_pair", "_gather_placed", "_weighted_resample_gather", "_scope",
         "weighted_resample_gather", "_resample_propagate", "resample_propagate",
         "_group_max_shift", "group_weights", "_reassemble_shift", "_reassemble_sums",
         "_max_shift", "_divide_by_sum", "_final_log_weights", "reassemble",
         "_weighted_mean_states", "_row_max_shift", "_normalise_rows", "_effective_uv",
         "effective_uv", "_add_row_sums", "add_row_sums", "_clip_corner", "_clip_centres",
         "clip_centres"),
        ("tests/trackers/test_stage_kernels.py", "tests/trackers/test_ps_weighting.py",
         "tests/trackers/test_equivalences.py", "tests/trackers/filters/test_resampling.py",
         "tests/trackers/filters/test_resampling_oracle.py", "tests/trackers/test_particle.py",
         "tests/trackers/test_oracle_particle.py"),
        # Out-of-bounds writes in compiled code are undefined behaviour, not errors.
        {"NUMBA_BOUNDSCHECK": "1"},
        _KERNEL_TIMEOUT,
    ),
    # The compiled inverse-CDF draws of every resampler (per group, the three schemes) and
    # the distinct sub-states behind the DPS uniqueness diagnostic.
    "sampling": Module(
        "trackers/kernels/sampling.py",
        ("_inverse_cdf_groups", "inverse_cdf_groups", "_count_distinct", "count_distinct"),
        ("tests/trackers/filters/test_resampling.py",
         "tests/trackers/filters/test_resampling_oracle.py",
         "tests/trackers/test_stage_kernels.py", "tests/trackers/test_equivalences.py",
         "tests/trackers/test_particle.py", "tests/trackers/test_oracle_particle.py"),
        {"NUMBA_BOUNDSCHECK": "1"},
        _KERNEL_TIMEOUT,
    ),
    "meanshift": Module(
        "trackers/kernels/meanshift.py",
        ("_pixel_range", "_chord", "_row_weights", "_window", "_distance", "_clear", "_shift",
         "_mean_shift"),
        ("tests/trackers/test_oracle_meanshift.py", "tests/trackers/test_meanshift_kernel.py"),
        # Out-of-bounds writes in compiled code are undefined behaviour, not errors:
        # bounds checks make a mutant that shrinks a buffer fail instead of corrupting.
        # (Its round-16 run predates numba_cache.py: a mutant then recompiled only this
        # file's kernels, about 3 s; now every kernel, hence the kernel timeout.)
        {"NUMBA_BOUNDSCHECK": "1"}, min_timeout=_KERNEL_TIMEOUT,
    ),
    # The KAMS paper's trackers around the kernels: per-object sets of windows, the mean
    # shift tracker, SOK's eight extra starts and the hybrid filter. (KAMS is the annealed
    # filter with a mean-shift move, one call without an operator: nothing to mutate.)
    **{key: Module(path, scope, _MEAN_SHIFT_TESTS) for key, path, scope in (
        ("ms-trackers", "trackers/meanshift.py",
         ("window_boxes", "set_log_likelihoods", "set_distances", "set_mean_shift",
          "keep_inside", "MeanShiftTracker._init", "MeanShiftTracker._step")),
        ("sok", "trackers/sok.py", ("SOK._init", "SOK._step")),
        ("hybrid", "trackers/hybrid.py", ("HybridPF._init", "HybridPF._step")),
    )},
    "annealed": Module(
        "trackers/annealed.py",
        ("survival_rate", "survival_beta", "_bracket",
         "weighted_estimate", "resample_targets", "AnnealedPF._init", "AnnealedPF._step",
         "AnnealedPF._beta", "_layer_sigmas"),
        ("tests/trackers/test_oracle_annealing.py", "tests/trackers/test_annealed.py"),
    ),
    "shm": Module(
        "trackers/shm.py",
        ("transition_matrix", "_OrderingEvidence.__init__",
         "_OrderingEvidence.log_evidence", "_SHMBase._init_common", "SHMTracker._init",
         "SHMTracker._step", "FastSHMTracker._init", "FastSHMTracker._step"),
        ("tests/trackers/test_oracle_shm.py", "tests/trackers/test_shm.py",
         "tests/trackers/test_shm_scripted.py"),
    ),
    "kalman": Module(
        "trackers/filters/kalman.py",
        ("MotionModel.constant_velocity", "MotionModel.ar2", "MotionModel.joint",
         "KalmanFilter.predict", "KalmanFilter.update", "KalmanFilter._missed"),
        ("tests/trackers/filters/test_kalman.py", "tests/trackers/test_oracle_shm.py"),
    ),
    "metrics": Module(
        "scenegen/evaluation/metrics.py",
        ("box_area", "intersection_area", "iou", "centres", "centre_error", "track_state",
         "precision_recall", "success_rate", "recovery_rate", "mean_over_tracked",
         "uniqueness_percent", "effective_dynamics_percent", "_nanmean0", "otb_curves",
         "failure_frame", "tracked_fraction", "mcnemar_counts", "mcnemar", "clear_mot",
         "idf1", "ordering_index", "overlap_fraction", "overlapping_pairs",
         "depth_order_accuracy"),
        ("tests/scenegen/evaluation",),
    ),
    # CLEAR MOT, identity and HOTA as TrackEval computes them, the frames they score and
    # MOTChallenge's distractor preprocessing (check_threshold is argument checking).
    # Every test file of tests/scenegen/evaluation reaches the module (metrics.clear_mot
    # and idf1 call it, evaluate builds its reports from it); the fast ones run first.
    "mot": Module(
        "scenegen/evaluation/mot.py",
        ("box_iou", "MotFrames.n_gt_dets", "MotFrames.n_tracker_dets", "_relabel",
         "mot_frames", "_in_order", "remove_distractor_matches", "_clear_final", "clear",
         "_identity_final", "identity", "_hota_final", "hota", "score_all", "mot_counts",
         "add_counts", "from_counts", "combine"),
        ("tests/scenegen/evaluation/test_mot.py",
         "tests/scenegen/evaluation/test_mot_mutants.py",
         "tests/scenegen/evaluation/test_metrics.py",
         "tests/scenegen/evaluation/test_metrics_oracle.py",
         "tests/scenegen/evaluation/test_trackeval_oracle.py",
         "tests/scenegen/evaluation/test_evaluate.py"),
        _NO_SHRINK,
    ),
    # The MOTChallenge files (scenegen/io/mot.py; ``mot`` above is the scoring): the
    # ground-truth rows and the boxes that count in each gt_mode, the tracker file
    # written and read back (the 1-based pixels, the row order TrackEval breaks ties by,
    # the rows a reader refuses). check_gt_mode is argument checking; read_result_text,
    # writable and _write_errno turn operating-system errors into one line.
    "mot-io": Module(
        "scenegen/io/mot.py",
        ("_num", "visible_enough", "gt_keep", "gt_rows", "write_mot_tracker",
         "read_mot_tracker", "check_number_text", "_integer", "read_mot_tracker_rows"),
        ("tests/scenegen/cli/test_export_evaluate.py",
         "tests/scenegen/evaluation/test_trackeval_oracle.py",
         "tests/scenegen/evaluation/test_otb_oracle.py",
         "tests/scenegen/evaluation/test_evaluate.py"),
    ),
    "stats": Module(
        "scenegen/lab/experiments/stats.py",
        ("norm_sf", "norm_ppf", "wilson", "newcombe_diff", "newcombe_paired_diff",
         "two_proportion_z", "mcnemar_exact", "binomial_greater", "chi2_sf",
         "chi2_homogeneity", "cochran_q", "bootstrap_clustered_diff", "_rng",
         "bootstrap_mean", "bootstrap_paired_diff", "verdict"),
        ("tests/scenegen/lab/test_stats.py",),
    ),
    "runner": Module(
        "scenegen/lab/experiments/runner.py",
        ("derive_seed", "scene_seed", "Task.__post_init__", "Task.sweep_label", "Task.case",
         "Task.scene_seed", "Task.tracker_seed", "Task.filename", "Task.key", "plan_tasks",
         "_frozen", "_round", "tracker_params", "run_task"),
        ("tests/scenegen/lab/test_run_records.py",
         "tests/scenegen/lab/test_experiments.py::test_seed_derivation_is_stable",
         "tests/scenegen/lab/test_param_overrides.py"),
    ),
    "summary": Module(
        "scenegen/lab/experiments/summary.py",
        ("drop_first_frame", "_arr", "_state", "succeeded", "_recovered", "_run_mean", "_rate",
         "_mean", "_val", "_group", "_case", "_target_index", "_compare", "_claim",
         "_paired_table", "_paired_rates", "_mcnemar_claim", "_scene_claim",
         "_orderings_claim", "_boot_claim", "_object_stats", "_pool_rate", "_dps_synthetic",
         "_other_mean", "_dps_real", "_pooled_ps_claims", "_error", "_kams_fails",
         "_kams_accuracy", "_kams_robustness", "_shm_run", "_shm_depth", "summarize"),
        ("tests/scenegen/lab/test_summary_oracle.py",
         "tests/scenegen/lab/test_experiments.py::test_dps_limitation_pools_the_orderings_"
         "the_paper_puts_above_dps",
         "tests/scenegen/lab/test_experiments.py::test_mcnemar_claims_carry_the_paired_interval",
         "tests/scenegen/lab/test_experiments.py::test_clustered_claims_count_scenes_not_runs"),
    ),
    # The generator's ground truth: the AR2 paths and their boundary rules, and the
    # compiled compositor that paints the labels and scans every entity's visible box and
    # pixel count (the visibility's numerator). gtcheck.py in tests/scenegen/render
    # recomputes every frame's labels and ground truth with plain numpy.
    "motion": Module(
        "scenegen/render/motion.py",
        ("ar2_path", "ar2_stationary_moments"),
        ("tests/scenegen/render/test_motion_oracle.py", *_RENDER_TESTS),
        _NO_SHRINK,
    ),
    "compose": Module(
        "scenegen/render/compose.py",
        ("paint", "_scan_visible", "scan_static", "render_chunk", "_draw_frame",
         "_frame_stats"),
        ("tests/scenegen/render/test_compose_oracle.py", *_RENDER_TESTS),
        # Out-of-bounds writes in compiled code are undefined behaviour, not errors.
        {"NUMBA_BOUNDSCHECK": "1", **_NO_SHRINK},
    ),
    # What the generator writes from the compositor's output: amodal boxes and centres,
    # the visibility (visible pixels / the silhouette's pixels), visible boxes, presence.
    "ground-truth": Module(
        "scenegen/render/plan.py",
        ("_top_left", "_drop_shapes_outside", "_pack", "_ground_truth"),
        ("tests/scenegen/render/test_compose_oracle.py", *_RENDER_TESTS),
        _NO_SHRINK,
    ),
    # The colour-histogram kernels every particle filter and mean-shift tracker weighs its
    # boxes with: the bin-index image (quantize), which pixels a box holds and their
    # fixed-point weights (profiles), the per-pixel path (direct) and the integral-histogram
    # path (integral), checked against plain-numpy transcriptions and each other.
    # _check_frame, _check_bin_count, _is_number and _is_integer are argument checking.
    # A kernel file changed drops every kernel's numba cache (numba_cache.drop_stale), so
    # each mutant recompiles the kernels its tests use (30-60 s on the shared cores, above
    # 4 x the warm baseline): hence the timeout. quantize's tests compile only its kernels.
    "quantize": Module(
        "trackers/kernels/quantize.py",
        ("_planes", "_quantize_rgb", "quantize_rgb", "_quantize_hsv", "hsv_n_bins",
         "quantize_hsv"),
        ("tests/trackers/models/test_observation.py",
         "tests/trackers/test_docstring_examples.py", "-k",
         "quantize or saturation or bad_number"),
        {"NUMBA_BOUNDSCHECK": "1", **_NO_SHRINK}, min_timeout=_KERNEL_TIMEOUT,
    ),
    "profiles": Module(
        "trackers/kernels/profiles.py",
        ("box_kernel_levels", "_level_args", "_first_inside", "_pixel_range",
         "_cone_weights", "_epanechnikov_weights", "_level_rects", "_box_row_weights",
         "_next_change"),
        _HISTOGRAM_TESTS, {"NUMBA_BOUNDSCHECK": "1", **_NO_SHRINK}, min_timeout=_KERNEL_TIMEOUT,
    ),
    "direct": Module(
        "trackers/kernels/direct.py",
        ("_lanes", "_scatter", "_scatter_unit", "_pair_sums", "_epanechnikov_pair_sums",
         "_accumulate", "_accumulate_support", "_region_histograms", "_band_rho",
         "_sums_rho", "_direct_distance"),
        _HISTOGRAM_TESTS, {"NUMBA_BOUNDSCHECK": "1", **_NO_SHRINK}, min_timeout=_KERNEL_TIMEOUT,
    ),
    "integral": Module(
        "trackers/kernels/integral.py",
        ("_band_rows", "_corner_rho", "_gather_rho", "_box_band_rho", "_integral_distances",
         "_integral_score"),
        _HISTOGRAM_TESTS, {"NUMBA_BOUNDSCHECK": "1", **_NO_SHRINK}, min_timeout=_KERNEL_TIMEOUT,
    ),
    # What histogram.py computes around them: the references' supports and empty-band
    # rho, the boxes grouped by reference, each group's choice of path (its cost model
    # and ROI), the parallel dispatch, and the Bhattacharyya coefficient and distance.
    "histogram": Module(
        "trackers/kernels/histogram.py",
        ("_reference_groups", "_integral_cheaper", "_plan_paths", "_support_colours",
         "_region_distances", "_support", "region_paths", "bhattacharyya_coefficient",
         "bhattacharyya_distance"),
        _HISTOGRAM_TESTS, {"NUMBA_BOUNDSCHECK": "1", **_NO_SHRINK}, min_timeout=_KERNEL_TIMEOUT,
    ),
    # What users judge their own trackers by: the conformance checks (a run and the
    # malformed estimates it records, IoU and centres, the claims, determinism, the
    # equivariance, the rate over repeats, the convention hint, the IoU checks), the one
    # NaN-aware comparison behind fixtures and scenegen_expect, and the two-sample
    # comparison of a stochastic tracker's runs. check_protocol and the error texts'
    # helpers (first_line, _writes_hint) only word a failure the run already has.
    "checks": Module(
        "scenegen/testing/checks.py",
        ("_run", "_iou", "_claim", "check_edge_fixtures", "check_boxes",
         "check_deterministic", "_judge", "check_translation_equivariance",
         "_convention_hint", "_iou_check", "check_recovers_after_occlusion"),
        ("tests/scenegen/testing/test_conformance.py",
         "tests/trackers/test_tracker_conformance.py",
         "tests/scenegen/testing/test_plugin.py", "tests/scenegen/testing/test_builtin.py"),
        _NO_SHRINK,
    ),
    "compare": Module(
        "scenegen/testing/compare.py",
        ("_nan_mask", "_wide", "difference"),
        ("tests/scenegen/testing/test_compare.py", "tests/scenegen/testing/test_fixtures.py",
         "tests/scenegen/testing/test_plugin.py"),
        _NO_SHRINK,
    ),
    # How the checks are run and reported: a check's outcome from what it raised, the
    # skip of every check after a failed protocol, the options, the report's verdicts
    # and texts, the pytest parametrisation and the Markdown table.
    "conformance": Module(
        "scenegen/testing/conformance.py",
        ("ConformanceReport.passed", "ConformanceReport.failed", "ConformanceReport.status",
         "ConformanceReport.names", "ConformanceReport.as_dict", "ConformanceReport.__str__",
         "_run_check", "check_tracker", "make_options", "_names", "_entries",
         "parametrize_with_checks", "_Check.__call__", "checks_table"),
        ("tests/scenegen/testing/test_conformance.py",
         "tests/trackers/test_tracker_conformance.py",
         "tests/scenegen/testing/test_plugin.py"),
        _NO_SHRINK,
    ),
    # The scenes users' property tests draw: every drawn value within the strategy's
    # arguments (sizes, margins, speeds, noise, frames, roles), entities that fit the
    # canvas, the realistic switches, boxes. The _check_* argument checks only word
    # errors, but _check_fits decides which canvases can be drawn at all.
    "strategies": Module(
        "scenegen/testing/strategies.py",
        ("_check_fits", "_hundredths", "_draw_appearance", "ar2_params", "_draw_ar2",
         "entity_specs", "_draw_entity", "scene_configs", "_draw_occluder",
         "_draw_distractor", "_draw_background", "_draw_clutter", "_draw_scene",
         "_textured", "_realistic_entities", "_realistic_clutter", "_draw_real_background",
         "_draw_camera", "_draw_photometric", "sequences", "_sequences", "boxes", "_draw_box"),
        # with shrinking: the strategies' promise to shrink to simple scenes is tested
        ("tests/scenegen/testing/test_strategy_ranges.py",
         "tests/scenegen/testing/test_strategies.py",
         "tests/scenegen/testing/test_readable_failures.py"),
    ),
    "distribution": Module(
        "scenegen/testing/distribution.py",
        ("_runs", "distribution_difference", "assert_distribution_matches"),
        ("tests/scenegen/testing/test_distribution.py",),
        _NO_SHRINK,
    ),
}

# One replacement per operator site (cosmic-ray's operator names).
CANONICAL = {
    "ReplaceBinaryOperator": {"Add": "Sub", "Sub": "Add", "Mul": "Div", "Div": "Mul",
                              "FloorDiv": "Div", "Mod": "FloorDiv", "Pow": "Mul",
                              "BitAnd": "BitOr", "BitOr": "BitAnd", "BitXor": "BitOr",
                              "LShift": "RShift", "RShift": "LShift"},
    "ReplaceComparisonOperator": {"Lt": "LtE", "LtE": "Lt", "Gt": "GtE", "GtE": "Gt",
                                  "Eq": "NotEq", "NotEq": "Eq", "Is": "IsNot",
                                  "IsNot": "Is", "In": "NotIn", "NotIn": "In"},
    "ReplaceUnaryOperator": {"USub": "Delete", "UAdd": "USub", "Not": "Delete",
                             "Invert": "Delete"},
}
KEPT = {"NumberReplacer", "AddNot", "ReplaceTrueWithFalse", "ReplaceFalseWithTrue",
        "ReplaceAndWithOr", "ReplaceOrWithAnd", "ZeroIterationForLoop",
        "ReplaceBreakWithContinue", "ReplaceContinueWithBreak"}


def canonical(operator: str) -> bool:
    """Whether a cosmic-ray operator name is one this run keeps."""
    name = operator.split("/")[-1]
    if name in KEPT:
        return True
    m = re.fullmatch(r"(Replace\w+Operator)_(\w+?)_(\w+)", name)
    if not m:
        return False
    family, source, target = m.groups()
    return CANONICAL.get(family, {}).get(source) == target


def scope_spans(path: Path, names: tuple[str, ...]) -> dict[str, tuple[int, int]]:
    """Line span (first, last) of each named function and method in ``path``."""
    tree = ast.parse(path.read_text())
    spans = {}

    def visit(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.ClassDef)):
                qual = f"{prefix}{child.name}"
                if isinstance(child, ast.FunctionDef) and qual in names:
                    spans[qual] = (child.lineno, child.end_lineno)
                visit(child, f"{qual}.")

    visit(tree, "")
    missing = set(names) - set(spans)
    if missing:
        raise SystemExit(f"{path}: scope names not found: {sorted(missing)}")
    return spans


def scope_lines(path: Path, names: tuple[str, ...]) -> list[tuple[int, int]]:
    """Line spans (first, last) of the named functions and methods in ``path``."""
    return list(scope_spans(path, names).values())


@dataclass(frozen=True)
class Site:
    """A line of a module's formula scope, as an equivalent mutant's entry names it."""
    function: str                   # the innermost function of the scope holding it
    text: str                       # the line, stripped
    before: str                     # the nearest non-blank line above it, stripped


def scope_sites(path: Path, names: tuple[str, ...]) -> dict[int, Site]:
    """Every line (by number) of the named functions and methods in ``path``."""
    owner: dict[int, str] = {}
    # Outer functions first, so that a nested function of the scope owns its lines.
    for qual, (a, b) in sorted(scope_spans(path, names).items(),
                               key=lambda item: item[1][0] - item[1][1]):
        owner.update(dict.fromkeys(range(a, b + 1), qual))
    sites, before = {}, ""
    for row, line in enumerate(path.read_text().splitlines(), start=1):
        if row in owner:
            sites[row] = Site(owner[row], line.strip(), before)
        if line.strip():
            before = line.strip()
    return sites


def make_tree() -> None:
    """A fresh copy of the sources (a run interrupted mid-mutant leaves its copy mutated)."""
    if TREE.exists():
        shutil.rmtree(TREE)
    TREE.mkdir(parents=True)
    for name in COPIED:
        src = ROOT / name
        if src.is_dir():
            shutil.copytree(src, TREE / name, copy_function=shutil.copy2,
                            ignore=shutil.ignore_patterns(".hypothesis"))
        else:
            shutil.copy2(src, TREE / name)


def test_command(mod: Module) -> str:
    args = " ".join(shlex.quote(arg) for arg in mod.tests)  # a -k expression has spaces
    return f"{sys.executable} -m pytest -x -q -p no:cacheprovider --no-header {args}"


def write_config(name: str, mod: Module, timeout: float) -> Path:
    cfg = BUILD / f"{name}.toml"
    # cosmic-ray splits the command itself (no shell): set variables through env(1).
    env = ("env " + "".join(f"{k}={v} " for k, v in mod.env.items())) if mod.env else ""
    cmd = (env + test_command(mod)).replace("\\", "\\\\").replace('"', '\\"')
    cfg.write_text(
        "[cosmic-ray]\n"
        f'module-path = "{mod.path}"\n'
        f"timeout = {timeout:.0f}\n"
        "excluded-modules = []\n"
        f'test-command = "{cmd}"\n'
        "[cosmic-ray.distributor]\n"
        'name = "local"\n'
    )
    return cfg


def cosmic(*args: str) -> None:
    exe = Path(sys.executable).with_name("cosmic-ray")
    subprocess.run([str(exe), *args], cwd=TREE, check=True,
                   env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})


def only_spans(path: Path, mod: Module, only: tuple[str, ...]) -> list[tuple[int, int]]:
    """The line spans ``--only`` selects: functions of the module's scope (qualified names)
    and line ranges of its file (``FIRST-LAST`` or ``LINE``)."""
    spans = []
    for item in only:
        m = re.fullmatch(r"(\d+)(?:-(\d+))?", item)
        if m:
            spans.append((int(m[1]), int(m[2] or m[1])))
        elif item in mod.scope:
            spans += scope_lines(path, (item,))
        else:
            raise SystemExit(f"--only {item!r}: neither a line range nor a function of the "
                             f"scope ({', '.join(mod.scope)})")
    return spans


def _in_spans(row: int, spans: list[tuple[int, int]]) -> bool:
    return any(a <= row <= b for a, b in spans)


def filter_session(session: Path, mod: Module, sample: int, only: tuple[str, ...] = (),
                   chosen: list[tuple[int, int]] | None = None) -> int:
    """Skip the mutations outside the scope and the non-canonical ones, and all but a
    seeded sample of ``sample`` of the rest (0: keep all); with ``only``, also those
    outside its functions and line ranges (``chosen``: their spans, when the caller has
    them from :func:`only_spans`). Return how many are kept. The skips of a previous
    call are undone first, so a wider choice runs the mutants it adds."""
    import sqlite3

    import numpy as np
    from cosmic_ray.work_db import use_db
    from cosmic_ray.work_item import WorkerOutcome, WorkResult

    con = sqlite3.connect(session)
    with con:
        con.execute("DELETE FROM work_results WHERE worker_outcome = 'SKIPPED'")
    con.close()
    spans = scope_lines(TREE / mod.path, mod.scope)
    if only:
        if chosen is None:
            chosen = only_spans(TREE / mod.path, mod, only)
        spans = [(a, b) for a, b in chosen if any(c <= a and b <= d for c, d in spans)]
        if len(spans) < len(chosen):
            raise SystemExit(f"--only {' '.join(only)}: a line range outside the scope")
    with use_db(str(session)) as db:
        done = {job for job, _ in db.results}
        items = list(db.work_items)
        candidates = []
        for item in items:
            spec = item.mutations[0]
            row = spec.start_pos[0]
            if _in_spans(row, spans) and canonical(spec.operator_name):
                candidates.append(item)
        # Job ids are random; sort by the mutation itself so the sample depends only on
        # the source and the seed.
        candidates.sort(key=lambda it: (it.mutations[0].start_pos, it.mutations[0].end_pos,
                                        it.mutations[0].operator_name,
                                        it.mutations[0].occurrence))
        if sample and len(candidates) > sample:
            pick = np.random.default_rng(13).choice(len(candidates), sample, replace=False)
            candidates = [candidates[i] for i in sorted(pick)]
        kept = {it.job_id for it in candidates}
        keep = len(kept)
        skip = [it.job_id for it in items if it.job_id not in kept and it.job_id not in done]
        if skip:
            db.set_multiple_results(skip, WorkResult(worker_outcome=WorkerOutcome.SKIPPED,
                                                     output="outside the formula scope"))
    return keep


# Surviving mutants that cannot change any result, by module: (original line, mutated
# line, reason[, where[, after]]), lines stripped (equivalent.py). They are listed in the
# report and left out of the score.
EQUIVALENT: dict[str, list[tuple]] = {}
EQUIVALENT_FILE = Path(__file__).with_name("equivalent.py")
if EQUIVALENT_FILE.exists():
    exec(compile(EQUIVALENT_FILE.read_text(), str(EQUIVALENT_FILE), "exec"),  # noqa: S102
         {"EQUIVALENT": EQUIVALENT})


@dataclass(frozen=True)
class Equivalent:
    """An entry of equivalent.py. A line can occur several times in a module's scope, and
    a mutation equivalent at one copy need not be at another: an entry whose line is not
    unique in the scope must name the functions it is meant for (``where``), and the line
    above it (``after``) if the line is not unique in one of them (``ambiguities``)."""
    original: str
    mutated: str
    reason: str
    where: tuple[str, ...] = ()     # the functions (qualified names) it covers; () all
    after: str | None = None        # the nearest non-blank line above the original

    @classmethod
    def of(cls, entry: tuple) -> Equivalent:
        where = entry[3] if len(entry) > 3 else ()
        return cls(*entry[:3], (where,) if isinstance(where, str) else tuple(where),
                   entry[4] if len(entry) > 4 else None)

    def covers(self, site: Site | None) -> bool:
        """Whether the entry is meant for a mutation of the line at ``site``."""
        if not self.where:
            return True
        return (site is not None and site.function in self.where
                and (self.after is None or site.before == self.after))


def ambiguities(entries: list[Equivalent], sites: dict[int, Site]) -> list[str]:
    """What is wrong with the entries: a line that occurs more than once in the scope,
    without the functions it is meant for; a named function that does not hold the line
    once (after ``after``, if given). An entry whose line occurs nowhere matches nothing
    (a line since changed) and is not an error."""
    errors = []
    for e in entries:
        at = [s for s in sites.values() if s.text == e.original]
        name = f"{e.original!r} -> {e.mutated!r}"
        if not e.where:
            if len(at) > 1:
                errors.append(f"{name}: the line occurs {len(at)} times in the scope (in "
                              f"{', '.join(sorted({s.function for s in at}))}): name the "
                              f"functions the entry is meant for")
            continue
        for f in e.where:
            here = [s for s in at if s.function == f and e.covers(s)]
            if len(here) != 1:
                hint = ("; give the line above it (after)" if here and e.after is None
                        else "")
                errors.append(f"{name}: the line occurs {len(here)} times in {f}"
                              + (f" after {e.after!r}" if e.after is not None else "")
                              + hint)
    return errors


def equivalents(name: str, mod: Module) -> tuple[list[Equivalent], dict[int, Site]]:
    """The module's entries and its scope's lines; refuses ambiguous entries."""
    entries = [Equivalent.of(e) for e in EQUIVALENT.get(name, [])]
    sites = scope_sites(ROOT / mod.path, mod.scope)
    errors = ambiguities(entries, sites)
    if errors:
        raise SystemExit(f"{EQUIVALENT_FILE.name}[{name!r}]: ambiguous entries:\n  "
                         + "\n  ".join(errors))
    return entries, sites


def equivalent_reason(entries: list[Equivalent], sites: dict[int, Site], row: int,
                      original: str, mutated: str) -> str | None:
    """The reason of the entry covering a surviving mutant of line ``row``, if any."""
    for e in entries:
        if (e.original, e.mutated) == (original, mutated) and e.covers(sites.get(row)):
            return e.reason
    return None


def _changed_lines(diff: str) -> tuple[str, str]:
    minus = [ln[1:].strip() for ln in diff.splitlines()
             if ln.startswith("-") and not ln.startswith("---")]
    plus = [ln[1:].strip() for ln in diff.splitlines()
            if ln.startswith("+") and not ln.startswith("+++")]
    return " ".join(minus), " ".join(plus)


def report(name: str, mod: Module, session: Path,
           rows: list[tuple[int, int]] | None = None) -> tuple[int, int, int]:
    """Print and write the score of the mutants run (with ``rows``, of those in its
    line spans only)."""
    from cosmic_ray.work_db import use_db
    from cosmic_ray.work_item import TestOutcome, WorkerOutcome

    killed = survived = incompetent = equivalent = timed_out = 0
    lines, eq_lines, timeout_lines = [], [], []
    entries, sites = equivalents(name, mod)
    with use_db(str(session)) as db:
        specs = {item.job_id: item.mutations[0] for item in db.work_items}
        for job, result in db.results:
            spec = specs[job]
            if result.worker_outcome == WorkerOutcome.SKIPPED or (
                    rows is not None and not _in_spans(spec.start_pos[0], rows)):
                continue
            if result.test_outcome == TestOutcome.SURVIVED:
                why = equivalent_reason(entries, sites, spec.start_pos[0],
                                        *_changed_lines(result.diff or ""))
                if why:
                    equivalent += 1
                    eq_lines.append(f"EQUIVALENT line {spec.start_pos[0]}: "
                                    f"{' -> '.join(_changed_lines(result.diff))}: {why}")
                    continue
                survived += 1
                lines.append(f"SURVIVED {job} {spec.operator_name} line {spec.start_pos[0]}\n"
                             f"{result.diff}")
            elif result.test_outcome == TestOutcome.INCOMPETENT:
                incompetent += 1
            else:
                killed += 1
                if result.output == "timeout":  # cosmic-ray's output for a timed-out run
                    timed_out += 1
                    timeout_lines.append(f"TIMEOUT {job} line {spec.start_pos[0]}: "
                                         f"{' -> '.join(_changed_lines(result.diff or ''))}")
    total = killed + survived
    score = 100.0 * killed / total if total else float("nan")
    head = (f"{name}: {mod.path}: {killed} killed / {total} non-equivalent mutants = "
            f"{score:.1f} % ({timed_out} of the killed by the timeout, {equivalent} "
            f"equivalent, {incompetent} incompetent; tests: {' '.join(mod.tests)})")
    (BUILD / f"{name}.txt").write_text(head + "\n\n" + "\n".join(eq_lines) + "\n\n"
                                       + "\n".join(timeout_lines) + "\n\n"
                                       + "\n".join(lines))
    print(head, flush=True)
    return killed, survived, incompetent


def reset_survivors(session: Path, spans: list[tuple[int, int]] | None = None) -> int:
    """Forget the results of the surviving (and incompetent) mutants, so that exec runs
    them again; with ``spans`` (``--only``), only of those on the spans' lines: a
    survivor outside them would otherwise lose its result and be skipped as outside
    the choice. Return how many were reset."""
    import sqlite3

    from cosmic_ray.work_db import use_db

    with use_db(str(session)) as db:
        rows = {item.job_id: item.mutations[0].start_pos[0] for item in db.work_items}
    con = sqlite3.connect(session)
    with con:
        jobs = [job for (job,) in con.execute(
            "SELECT job_id FROM work_results WHERE test_outcome IN "
            "('SURVIVED', 'INCOMPETENT')")
            if spans is None or _in_spans(rows[job], spans)]
        con.executemany("DELETE FROM work_results WHERE job_id = ?", [(j,) for j in jobs])
    con.close()
    return len(jobs)


def run(name: str, mod: Module, *, count_only: bool, report_only: bool, sample: int,
        retest: bool, only: tuple[str, ...] = (), timeout: float | None = None) -> None:
    session = BUILD / f"{name}.sqlite"
    # The spans of --only, computed once: the tree made below is a copy of these sources.
    rows = only_spans(ROOT / mod.path, mod, only) if only else None
    equivalents(name, mod)  # refuse ambiguous entries before any run
    if report_only:
        report(name, mod, session, rows)
        return
    make_tree()
    start = time.monotonic()
    base = subprocess.run(test_command(mod), shell=True, cwd=TREE,
                          env={**os.environ, **mod.env, "PYTHONDONTWRITEBYTECODE": "1"},
                          capture_output=True, text=True)
    if base.returncode != 0:
        raise SystemExit(f"{name}: the tests fail on the unmutated sources:\n"
                         f"{base.stdout[-3000:]}")
    baseline = time.monotonic() - start
    limit = timeout if timeout is not None else max(mod.min_timeout, 4 * baseline)
    cfg = write_config(name, mod, timeout=limit)
    stamp = BUILD / f"{name}.sha256"
    digest = hashlib.sha256((ROOT / mod.path).read_bytes()).hexdigest()
    if session.exists() and (not stamp.exists() or stamp.read_text() != digest):
        session.unlink()  # the module changed: the stored mutations are stale
    if not session.exists():
        cosmic("init", str(cfg), str(session))
        stamp.write_text(digest)
    if retest:
        reset_survivors(session, rows)
    n = filter_session(session, mod, sample, only, rows)
    print(f"{name}: {n} mutants in scope (baseline test run {baseline:.1f} s, timeout "
          f"{limit:.0f} s)", flush=True)
    if count_only:
        return
    cosmic("exec", str(cfg), str(session))
    report(name, mod, session, rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("modules", nargs="*", metavar="MODULE",
                        help=f"one of {', '.join(MODULES)} (default: all)")
    parser.add_argument("--count", action="store_true", help="only count the mutants")
    parser.add_argument("--report", action="store_true", help="only print stored results")
    parser.add_argument("--retest", action="store_true",
                        help="run the surviving mutants again (after adding tests); with --only, "
                             "those on its lines")
    parser.add_argument("--sample", type=int, default=25,
                        help="run a seeded sample of at most this many mutants per module "
                             "(default 25; 0: all)")
    parser.add_argument("--only", nargs="+", default=[], metavar="ITEM",
                        help="(one module) run and report only the mutants of these "
                             "functions of its scope (qualified names) and line ranges of "
                             "its file (FIRST-LAST or LINE); the sample is drawn from them")
    parser.add_argument("--timeout", type=float, default=None, metavar="SECONDS",
                        help="the limit of one mutant's test run (default: the larger of "
                             "the module's least timeout and 4 x the baseline run); a "
                             "timed-out mutant counts as killed and is listed as TIMEOUT "
                             "in the report, to be checked")
    args = parser.parse_args(argv)
    if args.timeout is not None and not 0 < args.timeout < float("inf"):
        parser.error(f"--timeout {args.timeout}: must be a positive, finite number of "
                     f"seconds")
    unknown = [m for m in args.modules if m not in MODULES]
    if unknown:
        parser.error(f"unknown module {unknown[0]!r}; valid: {', '.join(MODULES)}")
    if args.only and len(args.modules) != 1:
        parser.error("--only needs exactly one MODULE")
    BUILD.mkdir(parents=True, exist_ok=True)
    for name in args.modules or list(MODULES):
        run(name, MODULES[name], count_only=args.count, report_only=args.report,
            sample=args.sample, retest=args.retest, only=tuple(args.only),
            timeout=args.timeout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
