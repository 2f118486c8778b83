"""check_tracker on hand-made trackers: each check fails for the reason it names."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from scenegen.testing import CHECKS, check_tracker, checks_table, parametrize_with_checks


class Still:
    """Only init and step: never moves its boxes."""

    def init(self, frame, boxes):
        self.boxes = np.asarray(boxes, dtype=float)

    def step(self, frame):
        return SimpleNamespace(boxes=self.boxes.copy())


class Follower(Still):
    """Follows the centroid of the saturated pixels (the suite's targets are saturated
    discs on grey backgrounds): a good tracker of one unoccluded target."""

    def step(self, frame):
        f = frame.astype(int)
        rows, cols = np.nonzero(f.max(axis=-1) - f.min(axis=-1) > 100)
        if rows.size:
            w, h = self.boxes[0, 2:]
            self.boxes[0, :2] = cols.mean() + 0.5 - w / 2, rows.mean() + 0.5 - h / 2
        return SimpleNamespace(boxes=self.boxes.copy())


def _status(report):
    return {r.name: r.status for r in report.results}


def test_a_still_tracker_passes_the_protocol_checks_and_fails_to_keep_a_moving_target():
    report = check_tracker(Still, report=True)
    assert _status(report) == {
        "protocol": "passed",
        "edge_fixtures": "passed",
        "boxes": "passed",
        "deterministic": "passed",
        "translation_equivariance": "passed",
        "keeps_lone_target": "failed",
        "recovers_after_occlusion": "skipped",
    }
    assert report.failed == ["keeps_lone_target"]
    msg = dict((r.name, r.message) for r in report.results)["keeps_lone_target"]
    assert "IoU fell to" in msg and "below 0.5 at frame" in msg
    with pytest.raises(AssertionError, match="Still failed 1 conformance check.*keeps_lone_target"):
        check_tracker(Still)
    assert "| Still | pass | pass | pass | pass | pass | FAIL | – |" in checks_table([report])


def test_not_a_tracker_fails_protocol_and_skips_the_rest():
    report = check_tracker(lambda: SimpleNamespace(init=lambda f, b: None), report=True)
    assert report.results[0].status == "failed" and "no step method" in report.results[0].message
    # every other check once, in order, skipped for that reason (mutation testing: the
    # second check dropped, or protocol listed again as skipped, passed)
    assert report.names() == list(CHECKS)
    assert [(r.status, r.message) for r in report.results[1:]] == [
        ("skipped", "not a tracker (see protocol)")
    ] * (len(CHECKS) - 1)


def test_a_factory_returning_a_class_fails_protocol():
    # A class has init and step (unbound): it passed protocol, then every run raised
    # "Still.init() missing 1 required positional argument: 'boxes'".
    report = check_tracker(lambda: Still, report=True)
    assert report.status("protocol") == "failed"
    assert "the factory returned the class Still, not a tracker" in str(report), str(report)


def test_exceptions_name_the_fixture_and_frame():
    class Fragile(Still):
        def init(self, frame, boxes):
            super().init(frame, boxes)
            self.t = 0
            if frame.shape[0] == 48 and len(boxes) == 1 and boxes[0][2] < 2:
                self.tiny = True

        def step(self, frame):
            self.t += 1
            if getattr(self, "tiny", False) and self.t == 3:
                raise ZeroDivisionError("box too small")
            return super().step(frame)

    report = check_tracker(Fragile, report=True, checks=["edge_fixtures"])
    assert report.results[0].message == (
        "raised on 1 of 5 edge fixtures: one-pixel: step at frame 3 raised "
        "ZeroDivisionError: box too small"
    )


@pytest.mark.parametrize("where", ["init", "step", "factory"])
def test_a_tracker_that_exits_fails_instead_of_ending_the_run(where):
    # A SystemExit from init or step ended check_tracker (and a pytest run) with status 0.
    class Exits(Still):
        def __init__(self):
            if where == "factory":
                raise SystemExit(0)

        def init(self, frame, boxes):
            if where == "init":
                raise SystemExit(0)
            super().init(frame, boxes)

        def step(self, frame):
            raise SystemExit(0)

    report = check_tracker(Exits, report=True, checks=["protocol", "edge_fixtures"])
    expected = {"init": "init raised SystemExit: 0", "factory": "the factory raised SystemExit: 0",
                "step": "step at frame 1 raised SystemExit: 0"}[where]  # fmt: skip
    assert not report.passed and expected in str(report), str(report)


def test_writing_into_the_frames_fails():
    class Scribbler(Still):
        def step(self, frame):
            frame[0, 0] = 0
            return super().step(frame)

    report = check_tracker(Scribbler, report=True, checks="edge_fixtures")
    assert "read-only" in report.results[0].message


def test_drawing_on_the_frames_with_opencv_is_named():
    # OpenCV's own error for a read-only array says only "Bad argument in function
    # 'rectangle'": the message now says the tracker writes into its input frame.
    import cv2

    class Overlay(Still):
        def step(self, frame):
            cv2.rectangle(frame, (0, 0), (3, 3), (255, 0, 0), 1)
            return super().step(frame)

    message = check_tracker(Overlay, report=True, checks="edge_fixtures").results[0].message
    assert "in function 'rectangle' (it writes into its input frame" in message, message
    message = check_tracker(Overlay, report=True, checks="keeps_lone_target").results[0].message
    assert "(it writes into its input frame" in message, message

    class Crashes(Still):  # raises without writing: no such hint
        def step(self, frame):
            raise IndexError("boom")

    message = check_tracker(Crashes, report=True, checks="edge_fixtures").results[0].message
    assert "boom" in message and "writes into" not in message


@pytest.mark.parametrize(
    ("boxes", "needle"),
    [
        (lambda b: np.zeros((len(b), 5)), "has shape (1, 5), expected (1, 4)"),
        (lambda b: np.where(np.arange(4) == 0, np.nan, b), "(a row must be finite with w, h"),
        (lambda b: b * [1, 1, -1, 1], "(a row must be finite with w, h >= 0, or all NaN)"),
        (lambda b: [["a"] * 4] * len(b), ".boxes is not numeric"),
        (None, "the estimate (ndarray) has no .boxes"),
    ],
)
def test_malformed_boxes_are_named(boxes, needle):
    class Malformed(Still):
        def step(self, frame):
            if boxes is None:  # the boxes themselves, not an estimate holding them
                return self.boxes.copy()
            return SimpleNamespace(boxes=boxes(self.boxes))

    report = check_tracker(Malformed, report=True, checks=["boxes"])
    assert report.results[0].status == "failed" and needle in report.results[0].message


def test_determinism_only_where_claimed():
    class Noisy(Still):
        def __init__(self, rng=None):
            self.rng = np.random.default_rng()  # ignores the seed on purpose

        def step(self, frame):
            return SimpleNamespace(boxes=self.boxes + self.rng.normal(0, 1, self.boxes.shape))

    report = check_tracker(Noisy, report=True, checks=["deterministic"])
    assert "two runs with seed 0 differ from frame 1" in report.results[0].message
    skipped = check_tracker(Noisy, report=True, checks=["deterministic"], deterministic=False)
    assert skipped.results[0].status == "skipped"

    class Honest(Noisy):
        deterministic = False

    assert check_tracker(Honest, report=True, checks=["deterministic"]).results[0].status == (
        "skipped"
    )


class DriftsOnOddSeeds(Follower):
    """Follows its target with an even seed, 20 px to its right with an odd one."""

    def __init__(self, rng=0):
        self.drift = rng % 2

    def step(self, frame):
        est = super().step(frame)
        est.boxes[:, 0] += 20 * self.drift
        return est


def test_a_rate_over_repeats_judges_a_stochastic_tracker():
    opts = {"checks": ["keeps_lone_target"], "repeats": 4}
    half = check_tracker(DriftsOnOddSeeds, report=True, min_pass_rate=0.5, **opts)
    assert half.passed and half.results[0].message.endswith("in 2 of 4 runs")
    strict = check_tracker(DriftsOnOddSeeds, report=True, min_pass_rate=0.75, **opts)
    assert strict.results[0].message.startswith(
        "passed 2 of 4 runs, below the required rate 0.75: seed 1: IoU fell to"
    )
    # Three failing runs are given, and how many more there were (were silently left out).
    many = check_tracker(DriftsOnOddSeeds, report=True, **{**opts, "repeats": 10})
    message = many.results[0].message
    assert message.startswith("passed 5 of 10 runs") and message.count("seed ") == 3
    assert message.endswith("; and 2 more failing runs"), message


@pytest.mark.parametrize(
    ("convert", "needle"),
    [
        (lambda b: np.hstack([b[:, :2] + b[:, 2:] / 2, b[:, 2:]]), "[cx, cy, w, h] (centre)"),
        (lambda b: np.hstack([b[:, :2], b[:, :2] + b[:, 2:]]), "[x0, y0, x1, y1] (corners)"),
        (lambda b: b[:, [1, 0, 3, 2]], "[y, x, h, w] (row first)"),
    ],
)
def test_boxes_in_another_convention_are_named(convert, needle):
    # Were only "IoU fell to 0.14": nothing said the boxes were right in another convention.
    class OtherConvention(Follower):
        def step(self, frame):
            return SimpleNamespace(boxes=convert(super().step(frame).boxes))

    assert check_tracker(Follower, report=True, checks="keeps_lone_target").passed
    message = check_tracker(OtherConvention, report=True, checks="keeps_lone_target").results[
        0
    ].message
    assert message.startswith("IoU fell to") and (
        f"read as {needle} the boxes would match: a box is [x, y, w, h]" in message
    ), message


def test_a_tracker_that_loses_its_target_gets_no_convention_hint():
    message = check_tracker(Still, report=True, checks="keeps_lone_target").results[0].message
    assert message.startswith("IoU fell to") and "read as" not in message, message


def test_equivariance_failure_names_the_shift():
    class Anchored(Still):
        def step(self, frame):  # drifts towards the frame's top-left corner: not equivariant
            self.boxes[:, :2] *= 0.9
            return super().step(frame)

    report = check_tracker(Anchored, report=True, checks=["translation_equivariance"])
    assert "shifting the scene by (7, 5) px moved the estimated centre by" in (
        report.results[0].message
    )


def test_occlusion_check_runs_where_claimed():
    opts = {"report": True, "checks": ["recovers_after_occlusion"], "handles_occlusion": True}
    assert check_tracker(Follower, **opts).passed
    lost = check_tracker(Still, **opts).results[0]
    assert lost.status == "failed" and "first below 0.5 at frame 16 of 20" in lost.message
    assert (
        check_tracker(Still, report=True, checks=["recovers_after_occlusion"]).results[0].status
        == "skipped"
    )


@pytest.mark.parametrize(
    ("kw", "needle"),
    [
        ({"repeat": 2}, "unknown option 'repeat'; valid: seed, deterministic"),
        ({"repeats": 0}, "repeats must be an integer >= 1"),
        ({"min_pass_rate": 0}, "min_pass_rate must be in (0, 1]"),
        ({"checks": ["nope"]}, "unknown check 'nope'; valid: protocol"),
        # Were TypeErrors ("'<' not supported ...") or silently taken as True.
        ({"min_pass_rate": "0.5"}, "min_pass_rate must be a number, got '0.5'"),
        ({"iou_threshold": None}, "iou_threshold must be a number, got None"),
        ({"equivariance_tol": "1"}, "equivariance_tol must be a number"),
        ({"deterministic": "false"}, "deterministic must be True, False or None, got 'false'"),
        # Was every check failing as "the factory raised ValueError" (a numpy seed < 0).
        ({"seed": -1}, "seed must be an integer >= 0, got -1"),
    ],
)
def test_bad_options_are_named(kw, needle):
    with pytest.raises(ValueError) as info:
        check_tracker(Still, **kw)
    assert needle in str(info.value)


def test_repeats_may_be_a_numpy_integer_but_not_a_bool():
    # np.int64(2) was refused as "not an integer".
    report = check_tracker(Still, report=True, checks=["deterministic"], repeats=np.int64(2))
    assert report.passed
    for bad in (True, np.True_, 2.0, np.int64(0)):
        with pytest.raises(ValueError, match="repeats must be an integer >= 1"):
            check_tracker(Still, checks=["deterministic"], repeats=bad)


@parametrize_with_checks([Still, (Follower, {"handles_occlusion": False})])
def test_parametrize_with_checks_makes_one_test_per_check(factory, check, request):
    assert request.node.callspec.id.split("-", 1)[1] in CHECKS
    if factory is Still and check.name == "keeps_lone_target":
        with pytest.raises(AssertionError, match="Still: keeps_lone_target: IoU fell"):
            check(factory)
    else:
        check(factory)


def test_a_parametrized_check_passes_skips_or_fails_as_its_check_did():
    # Found by mutation testing: a passed check made a skipped test (a skip is not a
    # failure, so every test of the plugin still "passed"), and a factory without tests.
    mark = parametrize_with_checks([Still, (Follower, {"handles_occlusion": False})])
    names, params = mark.args
    assert names == ("factory", "check")
    assert [p.id for p in params] == [f"{who}-{n}" for who in ("Still", "Follower")
                                      for n in CHECKS]  # fmt: skip
    by_id = {p.id: p.values for p in params}
    factory, check = by_id["Follower-protocol"]
    try:
        assert check(factory) is None  # passed: neither skipped nor failed
    except pytest.skip.Exception as why:  # would only skip this test, not fail it
        pytest.fail(f"a passed check skipped its test: {why}")
    factory, check = by_id["Still-recovers_after_occlusion"]
    with pytest.raises(pytest.skip.Exception, match="recovers_after_occlusion: the tracker"):
        check(factory)
    factory, check = by_id["Still-keeps_lone_target"]
    with pytest.raises(AssertionError, match="Still: keeps_lone_target: IoU fell"):
        check(factory)


def test_options_are_keywords_only():
    # check_tracker(Still, True) must not be read as report=True
    with pytest.raises(TypeError):
        check_tracker(Still, True)


def test_docstring_example_runs():
    import doctest

    from scenegen.testing import conformance

    result = doctest.testmod(conformance)
    assert result.attempted > 0 and result.failed == 0


class OnlyFirst(Follower):
    """Follows the first box and drops the others: (1, 4) whatever K is."""

    def step(self, frame):
        return SimpleNamespace(boxes=super().step(frame).boxes[:1])


def test_boxes_runs_a_scene_of_two_targets():
    # Every scene had K = 1, so a tracker of the first box only passed every check.
    report = check_tracker(OnlyFirst, report=True, checks=["boxes"])
    assert report.results[0].status == "failed"
    assert "pair: frame 1: .boxes has shape (1, 4), expected (2, 4)" in report.results[0].message
    ok = check_tracker(Still, report=True, checks=["boxes"]).results[0]
    assert ok.status == "passed" and "K up to 2" in ok.message


def test_boxes_is_skipped_when_no_estimate_was_examined():
    # It passed on the one-frame fixture, where step is never called.
    class Raiser(Still):
        def step(self, frame):
            raise RuntimeError("boom")

    result = check_tracker(Raiser, report=True, checks=["boxes"]).results[0]
    assert result.status == "skipped" and "no estimate to check" in result.message


def test_determinism_is_checked_with_two_targets_too():
    # Differs between instances only when there are several targets (here: which one it
    # moves depends on a count shared by every instance, like an unseeded choice would).
    class OrdersByChance(Still):
        made = 0

        def __init__(self, rng=None):
            OrdersByChance.made += 1
            self.pick = OrdersByChance.made % 2

        def step(self, frame):
            out = self.boxes.copy()
            if len(out) > 1:
                out[self.pick] += 1.0
            return SimpleNamespace(boxes=out)

    result = check_tracker(OrdersByChance, report=True, checks=["deterministic"]).results[0]
    assert result.status == "failed"
    assert "differ from frame 1 (largest difference 1 px) on the 2-target scene 'pair'" in (
        result.message
    )
    assert check_tracker(Still, report=True, checks=["deterministic"]).results[0].message == (
        "same boxes twice with seed 0 on lone, pair"
    )


def test_determinism_failure_names_the_first_frame_that_differs():
    # NaN in both runs is no difference (it was reported as inf from the first lost frame).
    class LostThenNoisy(Still):
        def __init__(self, rng=None):
            self.t, self.jitter = 0, np.random.default_rng()  # ignores the seed on purpose

        def step(self, frame):
            self.t += 1
            if self.t == 1:
                return SimpleNamespace(boxes=np.full_like(self.boxes, np.nan))
            extra = self.jitter.uniform(0.1, 0.5) if self.t >= 5 else 0.0
            return SimpleNamespace(boxes=self.boxes + extra)

    msg = check_tracker(LostThenNoisy, report=True, checks=["deterministic"]).results[0].message
    assert "differ from frame 5 (largest difference 0." in msg, msg


def _window(window=3, rng=None):
    return Still()


def test_labels_are_stable_across_processes():
    import functools

    from scenegen.testing.checks import label

    # A partial's repr holds a memory address: test ids changed every run.
    assert label(functools.partial(_window, window=3)) == "_window(window=3)"
    assert label(functools.partial(_window, object())) == "_window(object)"
    assert label(Still) == "Still"


@parametrize_with_checks([(Follower, {"checks": ["protocol", "boxes"]})])
def test_parametrize_with_checks_honours_checks(factory, check):
    # `checks` was ignored: every check made a test.
    assert check.name in ("protocol", "boxes")
    check(factory)


def test_parametrize_with_checks_refuses_bad_options_when_collected():
    with pytest.raises(ValueError, match="options of Follower: unknown option 'bogus'"):
        parametrize_with_checks([(Follower, {"bogus": 1})])


def test_a_scene_that_cannot_be_built_is_raised_not_blamed_on_the_tracker(monkeypatch):
    from scenegen.testing import checks

    def broken(name):
        raise NotADirectoryError("cache: not a directory")

    checks._scene.cache_clear()
    monkeypatch.setattr(checks, "_make_scene", broken)
    try:
        from scenegen.testing import SceneError  # the documented name

        assert SceneError is checks.SceneError
        with pytest.raises(SceneError, match="cannot build the conformance scene"):
            check_tracker(Still, report=True, checks=["boxes"])
    finally:
        monkeypatch.undo()
        checks._scene.cache_clear()


# --- what each verdict says, frame by frame (found by mutation testing) ----------------


def _message(factory, check, **opts):
    result = check_tracker(factory, report=True, checks=[check], **opts).results[0]
    return result.status, result.message


@pytest.mark.parametrize(
    ("estimate", "needle"),
    [
        (lambda b: b.copy(), "the estimate (ndarray) has no .boxes"),
        (lambda b: SimpleNamespace(boxes="abc"), ".boxes is not numeric"),
    ],
    ids=["no-boxes", "not-numeric"],
)
def test_every_malformed_frame_is_counted(estimate, needle):
    # A malformed estimate does not end the run: each later frame is examined too.
    from scenegen.testing.checks import _scene

    class Malformed(Still):
        def step(self, frame):
            return estimate(self.boxes)

    status, message = _message(Malformed, "boxes")
    n_steps = len(_scene("pair")[0]) - 1
    assert status == "failed"
    assert f"pair: frame 1: {needle} (and {n_steps - 1} more)" in message, message


def test_the_first_malformed_box_of_a_frame_is_named():
    class TwoBad(Still):
        def step(self, frame):
            boxes = self.boxes.copy()
            boxes[0, 2] = -3.0  # a negative width
            if len(boxes) > 1:
                boxes[1, 3] = np.nan  # a row with some NaN
            return SimpleNamespace(boxes=boxes)

    status, message = _message(TwoBad, "boxes")
    assert status == "failed" and "pair: frame 1: box 0 is [" in message, message
    assert "box 1 is" not in message


@pytest.mark.parametrize(("repeats", "tail"), [(6, ""), (8, "; and 1 more failing runs")])
def test_three_failing_runs_are_given_and_how_many_more(repeats, tail):
    status, message = _message(DriftsOnOddSeeds, "keeps_lone_target", repeats=repeats)
    assert status == "failed" and message.startswith(
        f"passed {repeats // 2} of {repeats} runs"), message
    assert message.count("seed ") == 3, message
    assert message.endswith(tail) and message.count("more failing runs") == (tail != ""), message


def test_a_rate_is_judged_with_a_tolerance_and_a_pass_names_its_runs():
    # 2 of 4 runs pass: a required rate 1e-12 above 1/2 (float rounding) still passes.
    status, message = _message(DriftsOnOddSeeds, "keeps_lone_target", repeats=4,
                               min_pass_rate=0.5 + 1e-12)
    assert (status, message) == ("passed", "IoU >= 0.5 in all 16 frames in 2 of 4 runs")
    assert _message(Follower, "keeps_lone_target", repeats=2) == (
        "passed", "IoU >= 0.5 in all 16 frames in 2 of 2 runs")


def _views(on_b, base=Follower, parity=0):
    """A ``base`` tracker whose every other instance calls ``on_b(t, boxes)`` at step t:
    ``boxes`` is a copy of its estimate, changed in place or replaced by what ``on_b``
    returns (or ``on_b`` raises). Instances count from 1 in the order they are built;
    those with ``built % 2 == parity`` are changed. Trackers are built in a fixed order:
    view A then view B in the equivariance check (parity 0 changes view B), and in the
    determinism check one for the claim, then the two runs of each scene (parity 1
    changes each second run)."""

    class Views(base):
        built = 0

        def __init__(self):
            type(self).built += 1
            self.changed = type(self).built % 2 == parity

        def step(self, frame):
            boxes = np.array(super().step(frame).boxes)
            self.t = getattr(self, "t", 0) + 1
            if self.changed:
                out = on_b(self.t, boxes)
                boxes = boxes if out is None else out
            return SimpleNamespace(boxes=boxes)

    return Views


def test_a_good_tracker_is_equivariant_and_both_views_are_the_same_crop():
    from scenegen.testing.checks import SHIFT, _scene

    shapes, starts = [], []

    class Recording(Follower):
        def init(self, frame, boxes):
            shapes.append(frame.shape)
            starts.append(np.array(boxes))
            super().init(frame, boxes)

    status, _ = _message(Recording, "translation_equivariance")
    assert status == "passed"
    # Two views of 96 x 72 of a scene 7 and 5 px larger, one per corner, each started
    # from the target's box at frame 0 in its own coordinates.
    assert shapes == [(72, 96, 3), (72, 96, 3)]
    first = _scene("shifted")[2][0]
    assert np.array_equal(starts[0], first)
    assert np.array_equal(starts[1], first - [*SHIFT, 0, 0])


def test_the_frame_where_the_shifted_view_drifts_is_named():
    def offset(t, boxes):
        if t >= 3:
            boxes[:, 1] += 3.0

    status, message = _message(_views(offset), "translation_equivariance")
    assert status == "failed"
    assert "moved the estimated centre by 3.00 px more at frame 3 (tolerance 1 px)" in message


@pytest.mark.parametrize("lost", [slice(None), slice(2, 3)], ids=["all-nan", "nan-width"])
def test_a_target_lost_in_one_view_only_is_named_with_its_frame(lost):
    def lose(t, boxes):
        if t >= 4:
            boxes[:, lost] = np.nan

    status, message = _message(_views(lose), "translation_equivariance")
    assert status == "failed"
    assert message == "the target is lost (NaN) in only one of the two views from frame 4"


def test_a_run_that_raises_in_one_view_only_is_named():
    def boom(t, boxes):
        if t == 2:
            raise RuntimeError("boom")

    status, message = _message(_views(boom), "translation_equivariance")
    assert status == "failed"
    assert message == "the run raised: step at frame 2 raised RuntimeError: boom"


def test_determinism_names_a_second_run_that_raises():
    status, message = _message(_views(lambda t, boxes: 1 / 0 if t == 1 else None),
                               "deterministic")
    assert status == "failed"
    assert message == ("the run on 'lone' raised: step at frame 1 raised ZeroDivisionError: "
                       "division by zero")


def _oracle(scene, change):
    """A tracker that returns the scene's ground truth, passed through ``change(t, box)``."""
    from scenegen.testing.checks import _scene

    gt = _scene(scene)[2]

    class Oracle(Still):
        def step(self, frame):
            self.t = getattr(self, "t", 0) + 1
            return SimpleNamespace(boxes=change(self.t, gt[self.t].copy()))

    return Oracle


def test_an_iou_of_exactly_the_threshold_passes_and_the_first_frame_below_is_named():
    def doubled(t, boxes):  # twice as wide from the same corner: IoU exactly 1/2
        boxes[:, 2] *= 2
        return boxes

    assert _message(_oracle("lone", doubled), "keeps_lone_target") == (
        "passed", "IoU >= 0.5 in all 16 frames")

    def away(t, boxes):  # doubled, then away from frame 5: frames 1-4 at exactly 1/2
        boxes = doubled(t, boxes)
        if t >= 5:
            boxes[:, 0] += 40.0
        return boxes

    status, message = _message(_oracle("lone", away), "keeps_lone_target")
    assert status == "failed" and message.startswith(
        "IoU fell to 0.00 (first below 0.5 at frame 5 of 16)"), message


def test_a_lost_target_is_a_miss_not_a_match():
    def lost(t, boxes):
        return np.full_like(boxes, np.nan) if t >= 3 else boxes

    status, message = _message(_oracle("lone", lost), "keeps_lone_target")
    assert status == "failed" and message.startswith(
        "IoU fell to 0.00 (first below 0.5 at frame 3 of 16)"), message


def test_a_target_lost_in_both_views_alike_is_equivariant():
    # Lost (a NaN width) from frame 4 in both views: the same in both, so no failure.
    def lose(t, boxes):
        if t >= 4:
            boxes[:, 2] = np.nan

    class BothLost(Follower):
        def step(self, frame):
            est = super().step(frame)
            self.t = getattr(self, "t", 0) + 1
            lose(self.t, est.boxes)
            return est

    assert _message(BothLost, "translation_equivariance")[0] == "passed"


@pytest.mark.parametrize(("bad", "tail"), [((2,), ""), ((2, 4), " (and 1 more)")])
def test_malformed_estimates_after_the_first_are_counted(bad, tail):
    class SometimesBad(Still):
        def step(self, frame):
            self.t = getattr(self, "t", 0) + 1
            return SimpleNamespace(boxes=self.boxes[:1] if self.t in bad else self.boxes)

    status, message = _message(SometimesBad, "boxes")
    assert status == "failed" and message.endswith(
        "pair: frame 2: .boxes has shape (1, 4), expected (2, 4)" + tail), message


def test_the_boxes_check_counts_the_lost_boxes_from_frame_1():
    from scenegen.testing.checks import BOX_SCENES, EDGE_FIXTURES, _scene

    class LostAtFrame1(Still):
        def step(self, frame):
            self.t = getattr(self, "t", 0) + 1
            return SimpleNamespace(boxes=self.boxes * (np.nan if self.t == 1 else 1.0))

    status, message = _message(LostAtFrame1, "boxes")
    scenes = [_scene(n) for n in (*EDGE_FIXTURES, *BOX_SCENES)]
    lost = sum(len(init) for frames, init, _ in scenes if len(frames) > 1)
    assert status == "passed" and message.endswith(f"({lost} NaN boxes)"), message


def test_a_hint_is_given_when_the_converted_boxes_reach_the_threshold_exactly():
    # Centre boxes of a box twice as wide: read as [cx, cy, w, h] they overlap the
    # truth by exactly 1/2 (integer boxes, exact arithmetic), as [x, y, w, h] not at all.
    def centre_doubled(t, boxes):
        return np.hstack([boxes[:, :2] + boxes[:, 2:] * [1.0, 0.5], boxes[:, 2:] * [2, 1]])

    status, message = _message(_oracle("lone", centre_doubled), "keeps_lone_target")
    assert status == "failed" and "read as [cx, cy, w, h] (centre) the boxes would match" in (
        message), message


def test_an_exactly_equivariant_tracker_passes_a_tolerance_of_zero():
    # The init boxes are integers: the still boxes of the two views differ by the shift
    # exactly.
    assert _message(Still, "translation_equivariance", equivariance_tol=0.0) == (
        "passed", "equivariant within 0 px")


def test_determinism_names_the_first_frame_that_differs_in_one_coordinate():
    def jitter(t, boxes):
        if t >= 3:
            boxes[0, 0] += 0.25

    status, message = _message(_views(jitter, Still, parity=1), "deterministic")
    assert status == "failed" and message.startswith(
        "two runs with seed 0 differ from frame 3 (largest difference 0.25 px)"), message


def test_a_drift_of_exactly_the_tolerance_is_not_named_as_the_first_failure():
    # Integer boxes (Still): view B off by exactly 1 px (the tolerance) at frame 2, then
    # by 3 px from frame 3: frame 3 is the first beyond the tolerance.
    def drift(t, boxes):
        if t >= 2:
            boxes[:, 1] += 1.0 if t == 2 else 3.0

    status, message = _message(_views(drift, Still), "translation_equivariance")
    assert status == "failed" and message.endswith(
        "moved the estimated centre by 3.00 px more at frame 3 (tolerance 1 px)"), message


def test_a_target_lost_in_both_views_alike_passes_a_tolerance_of_zero():
    class StillLost(Still):
        def step(self, frame):
            self.t = getattr(self, "t", 0) + 1
            return SimpleNamespace(boxes=self.boxes * (np.nan if self.t >= 4 else 1.0))

    assert _message(StillLost, "translation_equivariance", equivariance_tol=0.0)[0] == "passed"


def test_determinism_names_a_second_run_that_loses_the_target():
    def lose(t, boxes):
        if t >= 3:
            boxes[:] = np.nan

    status, message = _message(_views(lose, Still, parity=1), "deterministic")
    assert status == "failed" and message.startswith(
        "two runs with seed 0 differ from frame 3 (largest difference inf px)"), message


def test_boxes_of_zero_width_or_height_are_well_formed():
    class Flat(Still):
        def step(self, frame):
            return SimpleNamespace(boxes=self.boxes * [1, 1, 0, 1])

    assert _message(Flat, "boxes")[0] == "passed"


def test_a_deterministic_tracker_that_loses_its_target_is_deterministic():
    # NaN in both runs at the same frames is no difference.
    class LosesAlike(Still):
        def step(self, frame):
            self.t = getattr(self, "t", 0) + 1
            return SimpleNamespace(boxes=self.boxes * (np.nan if self.t >= 3 else 1.0))

    assert _message(LosesAlike, "deterministic")[0] == "passed"


@pytest.mark.parametrize(
    ("change", "status"),
    [((-50.0, -50.0, None), "passed"), ((0.0, 0.0, -0.5), "failed")],
    ids=["outside-the-frame", "width-minus-half"],
)
def test_only_negative_sizes_make_a_box_malformed(change, status):
    # A box may lie partly or wholly outside the frame (negative x, y); a width of -0.5
    # is as malformed as -3.
    class Shifted(Still):
        def step(self, frame):
            boxes = self.boxes + [*change[:2], 0.0, 0.0]
            if change[2] is not None:
                boxes[:, 2] = change[2]
            return SimpleNamespace(boxes=boxes)

    assert _message(Shifted, "boxes")[0] == status


def test_a_malformed_last_estimate_is_no_box_in_the_equivariance_check():
    # A malformed estimate leaves no box (NaN), in the last frame too: in view B only,
    # the target is lost in one view.
    from scenegen.testing.checks import _scene

    last = len(_scene("shifted")[0]) - 1
    bad_last = _views(lambda t, boxes: boxes[:, :3] if t == last else None, Still)
    assert _message(bad_last, "translation_equivariance") == (
        "failed", f"the target is lost (NaN) in only one of the two views from frame {last}")
