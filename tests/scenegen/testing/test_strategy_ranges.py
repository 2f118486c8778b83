"""Every value the strategies draw lies in its stated range, and each end of the range is
drawn.

Users' property tests trust both halves: a range drawn too wide makes their tests fail on
scenes the strategy promised not to draw (an occluder past the margin, a target starting
outside the frame); a range drawn too narrow silently leaves out the scenes they meant to
test (a target touching the border, the largest size, the slowest camera). Mutation
testing (``tools/mutation/mutate.py strategies``) found both kinds untested. Below, the
docstrings' bounds are checked on drawn configs (no rendering: hundreds of examples cost
about a second), and each end of each range is pinned exactly by running the draws with
``Ends``, a stand-in for ``hypothesis.strategies`` that draws ends.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import Phase, find, given, settings
from hypothesis.errors import InvalidArgument, NoSuchExample

from scenegen.config import AR2, Appearance, EntitySpec, SceneConfig
from scenegen.testing import strategies as S
from scenegen.testing.strategies import boxes, entity_specs, scene_configs, sequences

EPS = 1e-9
EVERYTHING = {"occlusion": True, "clutter": True, "distractors": True, "noise": True,
              "exits": True, "realistic": True}  # fmt: skip


def _within(value: float, lo: float, hi: float) -> bool:
    return lo - EPS <= value <= hi + EPS


def _check_ar2(ar2: AR2, boundaries: tuple[str, ...], max_sigma: float, margin: float) -> None:
    assert ar2.boundary in boundaries, ar2
    assert _within(ar2.a1, 1, 2) and math.isclose(ar2.a1 + ar2.a2, 1.0), ar2
    assert _within(ar2.sigma, 0, max_sigma) and ar2.margin == margin, ar2


def _check_pattern(app: Any, realistic: bool) -> None:
    if app.pattern in ("stripes", "checker"):
        assert 1 <= app.stripe_width <= 6, app
    if app.pattern == "texture":
        assert _within(app.texture_sigma, 0, 40), app
    if app.pattern == "perlin":
        assert realistic and _within(app.noise_scale, 1, 16), app
    if app.pattern == "image":
        assert realistic and app.source in S._IMAGE_SOURCES and app.fit in S._FITS, app


def check_config(config: SceneConfig, **kw: Any) -> None:
    """``config`` is one ``scene_configs(**kw)`` may draw (its defaults otherwise)."""
    a = {"min_width": 32, "max_width": 120, "min_height": 24, "max_height": 90,
         "min_frames": 1, "max_frames": 8, "min_entities": 1, "max_entities": 3,
         "min_size": 3, "max_size": 24, "max_speed": 3.0, "max_sigma": 2.0, "margin": 0.0,
         **{k: False for k in EVERYTHING}, **kw}  # fmt: skip
    W, H, T, m = config.width, config.height, config.n_frames, a["margin"]
    assert a["min_width"] <= W <= a["max_width"] and a["min_height"] <= H <= a["max_height"]
    assert a["min_frames"] <= T <= a["max_frames"]
    ents = config.entities
    assert a["min_entities"] <= len(ents) <= a["max_entities"]
    exits, realistic = a["exits"], a["realistic"]
    boundaries = S.BOUNDARIES if exits else S.BOUNDARIES[:2]
    # names count each role from 1, targets first, then the others as drawn
    seen: dict[str, int] = {}
    for e in ents:
        seen[e.role] = seen.get(e.role, 0) + 1
        assert e.name == f"{e.role}{seen[e.role]}", [x.name for x in ents]
    roles = [e.role for e in ents]
    n_targets = roles.count("target")
    assert roles[:n_targets] == ["target"] * n_targets
    assert a["distractors"] or "distractor" not in roles
    assert a["occlusion"] or "occluder" not in roles
    first = ents[0]
    assert first.role == "target" and first.appear == 0 and first.disappear is None
    assert first.position_noise == 0
    span_w = max(1, min(a["max_size"], int(W - 2 * m)))
    span_h = max(1, min(a["max_size"], int(H - 2 * m)))
    by_name = {e.name: e for e in ents}
    for i, e in enumerate(ents):
        app = e.appearance
        if e.role == "target":
            ew, eh = app.size
            assert min(a["min_size"], span_w) <= ew <= span_w, (e.name, app.size, span_w)
            assert min(a["min_size"], span_h) <= eh <= span_h, (e.name, app.size, span_h)
            assert app.shape in S._SHAPES
            if app.pattern not in ("image", "perlin"):
                assert 1 <= len(app.colors) <= 4 and set(app.colors) <= set(S._COLORS), app
            _check_pattern(app, realistic)
            slack_x, slack_y = (ew / 2, eh / 2) if exits and i > 0 else (0.0, 0.0)
            x, y = e.position
            assert _within(x, m + ew / 2 - slack_x, W - m - ew / 2 + slack_x), (e.name, x)
            assert _within(y, m + eh / 2 - slack_y, H - m - eh / 2 + slack_y), (e.name, y)
            if e.motion is not None:
                for ar2 in (e.motion.x, e.motion.y):
                    _check_ar2(ar2, boundaries, a["max_sigma"], m)
                assert all(abs(v) <= a["max_speed"] + EPS for v in e.motion.velocity)
            assert _within(e.position_noise, 0, 3 if a["noise"] else 0), e
            if exits:
                assert 0 <= e.appear <= T - 1, e
                assert e.disappear is None or e.appear < e.disappear <= T, e
            else:
                assert (e.appear, e.disappear) == (0, None), e
        elif e.role == "distractor":
            model = by_name[e.mimic]
            assert model.role == "target" and ents.index(model) < i, (e.name, e.mimic)
            mw, mh = model.appearance.size
            assert abs(e.mimic_offset[0]) <= mw and abs(e.mimic_offset[1]) <= mh, e
            assert _within(e.color_jitter, 0, 10), e
            if model.appearance.pattern == "image":
                assert e.color_jitter == 0, e
            for ar2 in (e.motion.x, e.motion.y):
                _check_ar2(ar2, boundaries, a["max_sigma"], m)
            assert all(abs(v) <= a["max_speed"] + EPS for v in e.motion.velocity)
            assert 0 <= e.appear <= T - 1 and e.disappear is None, e
        else:
            _check_occluder(e, [t for t in ents[:n_targets]], W, H, m, realistic)
            assert 0 <= e.appear <= T - 1 and e.disappear is None, e
    # distinct depths: occluders in front (0, 1, ...), in the order drawn
    depths = [e.depth[0][1] for e in ents]
    assert sorted(depths) == list(range(len(ents))), depths
    front = [e.depth[0][1] for e in ents if e.role == "occluder"]
    assert front == list(range(len(front))), depths
    _check_clutter(config, a)
    assert _within(config.sensor_noise, 0, 10 if a["noise"] else 0)
    _check_background(config, a)
    if config.camera is not None or config.photometric is not None:
        assert realistic
    if config.camera is not None:
        _check_camera(config.camera, T)
    if config.photometric is not None:
        _check_photometric(config.photometric)


def _check_occluder(e, targets, W: int, H: int, m: float, realistic: bool) -> None:
    """Over one of the targets, padded by 0 to 8 pixels a side, inside the margin."""
    ow, oh = e.appearance.size
    app = e.appearance
    assert app.shape in ("rect", "ellipse") and app.pattern in ("solid", "image", "perlin")
    _check_pattern(app, realistic)
    if app.pattern != "image":
        assert len(app.colors) == 1 and app.colors[0] in S._OCCLUDER_COLORS, app
    x, y = e.position
    assert _within(x, m + ow / 2, W - m - ow / 2) and _within(y, m + oh / 2, H - m - oh / 2), e
    fits = []
    for t in targets:
        tw, th = t.appearance.size
        tx, ty = t.position
        pads = [p for p in range(9) if ow == max(1, min(tw + 2 * p, int(W - 2 * m)))
                and oh == max(1, min(th + 2 * p, int(H - 2 * m)))]  # fmt: skip
        if pads and abs(x - tx) <= ow / 2 + EPS and abs(y - ty) <= oh / 2 + EPS:
            fits.append(t.name)
    assert fits, (e, [(t.name, t.appearance.size, t.position) for t in targets])


def _check_clutter(config: SceneConfig, a: dict[str, Any]) -> None:
    if not a["clutter"]:
        assert config.clutter == ()
        return
    W, H, m, s0 = config.width, config.height, a["margin"], a["min_size"]
    assert len(config.clutter) <= 1
    for c in config.clutter:
        assert 1 <= c.count <= S._MAX_CLUTTER and c.min_size == s0, c
        side = c.appearance.size[0]
        assert c.appearance.size == (side, side) and s0 <= side <= max(s0, min(W, H) // 4), c
        assert c.appearance.shape in S._SHAPES and c.placement in ("uniform", "grid"), c
        assert c.region == ((m, m, W - 2 * m, H - 2 * m) if m > 0 else None), c
        _check_pattern(c.appearance, a["realistic"])
        if c.appearance.pattern == "image":
            plain = type(c)(count=0)
            assert (c.palette, c.n_colors) == (plain.palette, plain.n_colors), c
        else:
            assert c.palette == S._COLORS and 1 <= c.n_colors <= 3, c


def _check_background(config: SceneConfig, a: dict[str, Any]) -> None:
    b = config.background
    if b.kind in ("image", "perlin"):
        assert a["realistic"], b
        if b.kind == "perlin":
            assert _within(b.scale, 1, 32) and (b.low, b.high) == (40, 220), b
        else:
            assert b.source in S._IMAGE_SOURCES and b.fit in S._FITS, b
        return
    assert b.kind == "uniform" or a["noise"], b
    if b.kind != "noise":
        assert b.color in S._BACKGROUND_COLORS, b
    if b.kind != "uniform":
        assert 0 <= b.low <= b.high <= 255, b
    if b.kind == "texture":
        assert _within(b.scale, 0.5, 8), b


def _check_camera(cam, T: int) -> None:
    assert all(0 <= v <= 24 for v in cam.extent), cam
    dx, dy = cam.extent
    if cam.keyframes:
        assert cam.keyframes == ((0, -dx, -dy), (max(T - 1, 1), dx, dy)), cam
        assert cam.x is None and cam.y is None, cam
        return
    for ar2 in (cam.x, cam.y):
        assert ar2.boundary in S.BOUNDARIES[:2] and _within(ar2.sigma, 0, 3), cam
    assert all(_within(v, -3, 3) for v in cam.velocity), cam


def _check_photometric(photo) -> None:
    assert _within(photo.gain.sigma, 0, 0.1) and _within(photo.offset.sigma, 0, 5), photo
    assert _within(photo.motion_blur, 0, 2), photo
    assert photo.jpeg_quality is None or 20 <= photo.jpeg_quality <= 95, photo


# --- and each end of each range drawn ------------------------------------------------------
#
# Searching for an end with ``find`` takes seconds per end (a value on a grid of
# hundredths is rarely drawn at its end). Instead the draws run with a stand-in for
# ``hypothesis.strategies`` whose every draw is the low or the high end of its range: the
# strategies' code then gives the ends of each drawn value exactly.


class Ends:
    """``hypothesis.strategies`` as the strategies module uses it, every draw an end.

    ``pick`` overrides the choice among options (keyed by the options' tuple): a value,
    or a list cycled through draw by draw.
    """

    def __init__(self, end: str, pick: dict | None = None):
        # "low", "high", or "alternate": integers low, high, low, ... (the rest low)
        self.high = end == "high"
        self.alternate = end == "alternate"
        self.n_ints = 0
        self.pick = {k: list(v) if isinstance(v, list) else [v] for k, v in (pick or {}).items()}
        self.turn: dict = {}

    def integers(self, a, b):
        assert a <= b, (a, b)
        return ("int", a, b)

    def sampled_from(self, xs):
        return ("one", tuple(xs))

    def booleans(self):
        return ("one", (False, True))

    def none(self):
        return ("one", (None,))

    def lists(self, elements, *, min_size, max_size):
        return ("list", elements, min_size, max_size)

    def one_of(self, *options):
        return ("any", options)

    def permutations(self, xs):
        return ("perm", list(xs))

    def draw(self, s):
        kind = s[0]
        if kind == "int":
            self.n_ints += 1
            high = self.high or (self.alternate and self.n_ints % 2 == 0)
            return s[2] if high else s[1]
        if kind == "one":
            if s[1] in self.pick:
                values = self.pick[s[1]]
                n = self.turn.get(s[1], 0)
                self.turn[s[1]] = n + 1
                return values[n % len(values)]
            return s[1][-1] if self.high else s[1][0]
        if kind == "list":
            return [self.draw(s[1]) for _ in range(s[3] if self.high else s[2])]
        if kind == "any":
            return self.draw(s[1][-1] if self.high else s[1][0])
        return s[1][::-1] if self.high else s[1]


@pytest.fixture
def ends(monkeypatch):
    """``ends(end, **pick)``: an :class:`Ends` put in place of the module's ``st``."""

    def make(end: str, pick: dict | None = None) -> Ends:
        e = Ends(end, pick)
        monkeypatch.setattr(S, "st", e)
        return e

    return make


def test_ar2_ends(ends):
    lo = S._draw_ar2(ends("low").draw, ("reflect", "clamp"), 1.5, 2.0)
    assert (lo.boundary, lo.a1, lo.a2, lo.sigma, lo.margin) == ("reflect", 1.0, 0.0, 0.0, 2.0)
    hi = S._draw_ar2(ends("high").draw, ("reflect", "clamp"), 1.5, 2.0)
    assert (hi.boundary, hi.a1, hi.a2, hi.sigma, hi.margin) == ("clamp", 2.0, -1.0, 1.5, 2.0)


@pytest.mark.parametrize("pattern", ["stripes", "checker", "texture"])
def test_appearance_ends(ends, pattern):
    pick = {S._PATTERNS: pattern}
    lo = S._draw_appearance(ends("low", pick).draw, (3, 20), (4, 21))
    hi = S._draw_appearance(ends("high", pick).draw, (3, 20), (4, 21))
    assert (lo.shape, lo.size, lo.colors) == ("rect", (3, 4), S._COLORS[:1])
    assert (hi.shape, hi.size, hi.colors) == ("triangle", (20, 21), S._COLORS[-1:] * 4)
    if pattern == "texture":
        assert (lo.texture_sigma, hi.texture_sigma) == (0, 40)
    else:
        assert (lo.stripe_width, hi.stripe_width) == (1, 6)


@pytest.mark.parametrize("exits", [False, True])
@pytest.mark.parametrize("later", [False, True])
def test_entity_ends(ends, exits, later):
    W, H, T, m = 100, 80, 6, 0.0 if exits else 5.0
    args = (W, H, T, "e", ("target", "distractor"), 3, 200, 2.5, 1.5, m, True, exits, later)
    lo = S._draw_entity(ends("low", {(False, True): True}).draw, *args)
    hi = S._draw_entity(ends("high").draw, *args)
    span_w, span_h = int(W - 2 * m), int(H - 2 * m)  # the canvas less the margin
    assert (lo.role, lo.appearance.size) == ("target", (3, 3))
    assert (hi.role, hi.appearance.size) == ("distractor", (span_w, span_h))
    slack = exits and later
    assert lo.position == (m + 1.5 - 1.5 * slack, m + 1.5 - 1.5 * slack)
    assert hi.position == (W - m - span_w / 2 * (1 - slack), H - m - span_h / 2 * (1 - slack))
    assert lo.motion.velocity == (-2.5, -2.5) and hi.motion.velocity == (2.5, 2.5)
    assert lo.motion.x.sigma == 0 and hi.motion.y.sigma == 1.5
    assert hi.motion.x.boundary == ("free" if exits else "clamp") and hi.motion.x.margin == m
    assert (lo.position_noise, hi.position_noise) == (0, 3)
    if exits:
        assert (lo.appear, lo.disappear, hi.appear, hi.disappear) == (0, 1, T - 1, T)
    else:
        assert (lo.appear, lo.disappear, hi.appear, hi.disappear) == (0, None, 0, None)
    assert S._draw_entity(ends("low").draw, *args).motion is None  # shrinks to static


def _target(x, y, w, h):
    return EntitySpec(name="target1", role="target", appearance=Appearance(size=(w, h)),
                      position=(x, y))  # fmt: skip


@pytest.mark.parametrize("margin", [0.0, 4.0])
def test_occluder_ends(ends, margin):
    # in the open: padded 0 or 8 px a side, centred half its size off the target's centre
    t = _target(50, 40, 10, 6)
    lo = S._draw_occluder(ends("low").draw, "o", t, (100, 80, 6), margin)
    hi = S._draw_occluder(ends("high").draw, "o", t, (100, 80, 6), margin)
    assert (lo.appearance.size, lo.position, lo.appear) == ((10, 6), (45, 37), 0)
    assert (hi.appearance.size, hi.position, hi.appear) == ((26, 22), (63, 51), 5)
    assert (lo.appearance.shape, hi.appearance.shape) == ("rect", "ellipse")
    assert lo.appearance.colors == S._OCCLUDER_COLORS[:1]
    assert hi.appearance.colors == S._OCCLUDER_COLORS[-1:]
    # over a one-pixel target, unpadded: one pixel
    t = _target(50, 40, 1, 1)
    assert S._draw_occluder(ends("low").draw, "o", t, (100, 80, 6), margin).appearance.size == (
        1, 1)
    # against the border: kept inside the margin, and no wider than the canvas less it
    t = _target(margin + 5, margin + 3, 10, 6)
    lo = S._draw_occluder(ends("low").draw, "o", t, (30, 20, 6), margin)
    assert lo.position == (margin + 5, margin + 3)
    t = _target(30 - margin - 5, 20 - margin - 3, 10, 6)
    hi = S._draw_occluder(ends("high").draw, "o", t, (30, 20, 6), margin)
    ow, oh = min(26, int(30 - 2 * margin)), min(22, int(20 - 2 * margin))
    assert hi.appearance.size == (ow, oh)
    assert hi.position == (30 - margin - ow / 2, 20 - margin - oh / 2)


def test_distractor_ends(ends):
    model = _target(50, 40, 10, 6)
    args = ("d", [model], 6, 2.5, 1.5, 0.0)
    lo = S._draw_distractor(ends("low").draw, *args, True)
    hi = S._draw_distractor(ends("high").draw, *args, True)
    assert (lo.mimic, lo.mimic_offset, lo.color_jitter, lo.appear) == ("target1", (-10, -6), 0, 0)
    assert (hi.mimic, hi.mimic_offset, hi.color_jitter, hi.appear) == ("target1", (10, 6), 10, 5)
    assert lo.motion.velocity == (-2.5, -2.5) and hi.motion.velocity == (2.5, 2.5)
    assert (lo.motion.x.boundary, hi.motion.y.boundary) == ("reflect", "free")
    assert (lo.motion.y.sigma, hi.motion.x.sigma) == (0, 1.5)
    assert S._draw_distractor(ends("high").draw, *args, False).motion.x.boundary == "clamp"


def test_background_ends(ends):
    assert S._draw_background(ends("high").draw, False).kind == "uniform"
    lo = S._draw_background(ends("low", {("uniform", "noise", "texture"): "texture"}).draw, True)
    hi = S._draw_background(ends("high").draw, True)
    assert (lo.kind, lo.color, lo.low, lo.high, lo.scale) == (
        "texture", S._BACKGROUND_COLORS[0], 0, 0, 0.5)
    assert (hi.kind, hi.color, hi.low, hi.high, hi.scale) == (
        "texture", S._BACKGROUND_COLORS[-1], 255, 255, 8)
    noise = S._draw_background(ends("high", {("uniform", "noise", "texture"): "noise"}).draw, True)
    assert (noise.kind, noise.low, noise.high) == ("noise", 255, 255)
    real = S._draw_real_background(ends("high").draw)
    assert (real.kind, real.scale, real.low, real.high) == ("perlin", 32, 40, 220)
    real = S._draw_real_background(ends("low", {("image", "perlin"): "perlin"}).draw)
    assert (real.kind, real.scale) == ("perlin", 1)
    real = S._draw_real_background(ends("low").draw)
    assert (real.kind, real.source, real.fit) == ("image", S._IMAGE_SOURCES[0], S._FITS[0])


@pytest.mark.parametrize("margin", [0.0, 0.5, 3.0])
def test_clutter_ends(ends, margin):
    lo = S._draw_clutter(ends("low").draw, 100, 80, 2, margin)
    hi = S._draw_clutter(ends("high").draw, 100, 80, 2, margin)
    region = (margin, margin, 100 - 2 * margin, 80 - 2 * margin) if margin else None
    assert (lo.count, lo.appearance.size, lo.n_colors, lo.min_size, lo.region) == (
        1, (2, 2), 1, 2, region)
    assert (hi.count, hi.appearance.size, hi.n_colors, hi.min_size, hi.region) == (
        S._MAX_CLUTTER, (20, 20), 3, 2, region)
    assert (lo.placement, hi.placement) == ("uniform", "grid")
    assert S._draw_clutter(ends("high").draw, 10, 8, 5, 0.0).appearance.size == (5, 5)


def test_textured_ends(ends):
    app = Appearance(pattern="stripes", stripe_width=2, colors=((1, 2, 3),))
    assert S._textured(ends("low").draw, app) == app
    lo = S._textured(ends("low", {("keep", "image", "perlin"): "perlin"}).draw, app)
    hi = S._textured(ends("high").draw, app)
    assert (lo.pattern, lo.noise_scale, hi.pattern, hi.noise_scale) == ("perlin", 1, "perlin", 16)
    assert lo.stripe_width == hi.stripe_width == Appearance().stripe_width
    img = S._textured(ends("high", {("keep", "image", "perlin"): "image"}).draw, app)
    assert (img.source, img.fit, img.tint) == (S._IMAGE_SOURCES[-1], S._FITS[-1], S._COLORS[-1])
    img = S._textured(ends("low", {("keep", "image", "perlin"): "image"}).draw, app)
    assert (img.source, img.fit, img.tint, img.colors) == (
        S._IMAGE_SOURCES[0], S._FITS[0], None, Appearance().colors)


def test_camera_ends(ends):
    assert S._draw_camera(ends("low").draw, 6) is None
    cam = S._draw_camera(ends("high").draw, 6)
    assert (cam.extent, cam.keyframes) == ((24, 24), ((0, -24, -24), (5, 24, 24)))
    assert S._draw_camera(ends("high").draw, 1).keyframes == ((0, -24, -24), (1, 24, 24))
    cam = S._draw_camera(ends("alternate", {("none", "ar2", "scripted"): "scripted"}).draw, 6)
    assert (cam.extent, cam.keyframes) == ((0, 24), ((0, 0, -24), (5, 0, 24)))
    kinds = ("none", "ar2", "scripted")
    lo = S._draw_camera(ends("low", {kinds: "ar2"}).draw, 6)
    hi = S._draw_camera(ends("high", {kinds: "ar2"}).draw, 6)
    assert (lo.extent, lo.x.sigma, lo.y.sigma, lo.velocity, lo.zoom) == (
        (0, 0), 0, 0, (-3, -3), None)
    assert (hi.extent, hi.x.sigma, hi.y.sigma, hi.velocity) == ((24, 24), 3, 3, (3, 3))
    assert (lo.x.boundary, hi.x.boundary, hi.y.boundary) == ("reflect", "clamp", "clamp")
    assert hi.zoom == AR2(boundary="reflect", a1=1.0, a2=0.0, sigma=0.05, margin=0.4)


def test_photometric_ends(ends):
    assert S._draw_photometric(ends("low").draw) is None
    lo = S._draw_photometric(ends("low", {(False, True): True}).draw)
    hi = S._draw_photometric(ends("high").draw)
    assert (lo.gain.sigma, lo.offset.sigma, lo.motion_blur, lo.jpeg_quality) == (0, 0, 0, None)
    assert (hi.gain.sigma, hi.offset.sigma, hi.motion_blur, hi.jpeg_quality) == (0.1, 5, 2, 95)
    assert hi.gain == AR2(boundary="reflect", a1=1.0, a2=0.0, sigma=0.1, margin=0.5)
    assert hi.offset == AR2(boundary="reflect", a1=1.0, a2=0.0, sigma=5, margin=40)
    assert hi.keyframes == ()
    low_q = S._draw_photometric(_LowQuality().draw)
    assert low_q.jpeg_quality == 20


class _LowQuality(Ends):
    """Low ends, but the JPEG quality drawn (not None)."""

    def __init__(self):
        super().__init__("low", {(False, True): True})

    def draw(self, s):
        if s[0] == "any":
            return self.draw(s[1][-1])
        return super().draw(s)


@pytest.mark.parametrize("end", ["low", "high"])
def test_scene_ends(ends, end):
    # the whole scene at each end, every switch on: every check of check_config holds,
    # and what only the whole scene decides (names, depths, the first target's rules)
    roles = ["target", "distractor", "occluder"]
    kw = {"min_width": 64, "max_width": 100, "min_height": 48, "max_height": 80,
          "min_frames": 2, "max_frames": 6, "min_entities": 5, "max_entities": 6,
          "min_size": 3, "max_size": 20, "max_speed": 2.5, "max_sigma": 1.5, **EVERYTHING}
    e = ends(end, {("target", "distractor", "occluder"): roles, (False, True): True})
    switches = {k: True for k in EVERYTHING}
    config = S._draw_scene(
        e.draw, (64, 100), (48, 80), (2, 6), (5, 6), (3, 20), 2.5, 1.5, 0.0, switches)
    check_config(config, **kw)
    names = [x.name for x in config.entities]
    if end == "low":
        assert (config.width, config.height, config.n_frames) == (64, 48, 2)
        # roles drawn: target (always), then target, distractor, occluder, target
        assert names == ["target1", "target2", "target3", "distractor1", "occluder1"]
    else:
        assert (config.width, config.height, config.n_frames) == (100, 80, 6)
        assert names == ["target1", "target2", "target3", "distractor1", "occluder1",
                         "distractor2"]  # fmt: skip
        assert config.sensor_noise == 10 and config.clutter[0].count == S._MAX_CLUTTER
        assert config.camera.extent == (24, 24) and config.photometric.motion_blur == 2
        assert {x.appearance.size for x in config.entities if x.role == "target"} == {(20, 20)}
        assert config.clutter[0].appearance.pattern == "perlin"  # textured too
        # with exits every target but the first may start half outside
        assert [x.position for x in config.entities if x.role == "target"] == [
            (90, 70), (100, 80), (100, 80)]
    first = config.entities[0]
    assert (first.appear, first.disappear, first.position_noise) == (0, None, 0)
    if end == "low":  # every switch on, each drawn at its low end
        assert config.sensor_noise == 0 and config.clutter[0].count == 1
        assert config.photometric.motion_blur == 0 and config.camera is None
    # realistic: every entity but the mimics textured (high: Perlin; low: kept as drawn)
    for x in config.entities:
        if x.mimic is None:
            assert x.appearance.pattern == ("perlin" if end == "high" else "solid"), x
        else:
            assert x.appearance == EntitySpec(name="d", role="distractor", mimic="t").appearance
    depth = {x.name: x.depth[0][1] for x in config.entities}
    n_occ = sum(x.role == "occluder" for x in config.entities)
    rest = [n for n in names if not n.startswith("occluder")]
    order = rest if end == "low" else rest[::-1]
    assert [depth[n] for n in order] == list(range(n_occ, len(names)))


def test_boxes_ends(ends):
    ends("low")  # the module's st made an Ends (its draws are given explicitly below)
    hi = S._draw_box(Ends("high").draw, 320, 160, 8, 96, True, 16)
    lo = S._draw_box(Ends("low").draw, 320, 160, 8, 96, True, 16)
    np.testing.assert_array_equal(lo, [0, 0, 0.5, 0.5])
    np.testing.assert_array_equal(hi, [14, 4, 6, 6])
    # outside: all but one step inside the canvas, on either side
    lo = S._draw_box(Ends("low").draw, 20, 10, 1, 20, False, 1)
    hi = S._draw_box(Ends("high").draw, 20, 10, 1, 20, False, 1)
    np.testing.assert_array_equal(lo, [0, 0, 1, 1])
    np.testing.assert_array_equal(hi, [19, 9, 20, 10])
    box = S._draw_box(_WideLeft().draw, 20, 10, 1, 20, False, 1)
    np.testing.assert_array_equal(box, [-19, -9, 20, 10])


class _WideLeft(Ends):
    """The largest sizes, then the lowest positions: a box outside but for one pixel."""

    def __init__(self):
        super().__init__("high")
        self.n = 0

    def draw(self, s):
        self.n += 1
        return s[1] if self.n > 2 else s[2]


def test_a_mimic_of_an_image_keeps_no_colour_jitter(ends):
    # an image has no colours to jitter: the mimic's jitter would be refused
    e = ends("high", {("keep", "image", "perlin"): "image"})
    config = S._draw_scene(e.draw, (64, 64), (48, 48), (2, 2), (2, 2), (3, 20), 1.0, 1.0, 0.0,
                           {**{k: False for k in EVERYTHING}, "distractors": True,
                            "realistic": True})  # fmt: skip
    target, mimic = config.entities
    assert target.appearance.pattern == "image" and mimic.mimic == "target1"
    assert mimic.color_jitter == 0
    e = ends("high", {("keep", "image", "perlin"): "perlin"})
    config = S._draw_scene(e.draw, (64, 64), (48, 48), (2, 2), (2, 2), (3, 20), 1.0, 1.0, 0.0,
                           {**{k: False for k in EVERYTHING}, "distractors": True,
                            "realistic": True})  # fmt: skip
    assert config.entities[1].color_jitter == 10


def test_hundredths_on_the_grid_or_the_midpoint(ends):
    draw = ends("low").draw
    assert S._hundredths(draw, 0.004, 0.012) == 0.01  # the one grid point inside
    assert S._hundredths(draw, 0.001, 0.004) == 0.0025  # none inside: the midpoint
    assert S._hundredths(ends("high").draw, -0.5, 0.25) == 0.25


def test_boxes_and_entities_fill_the_smallest_canvas_and_refuse_an_empty_one():
    for kw in ({"width": 1, "height": 1}, {"width": 10, "height": 10, "min_size": 10},
               {"width": 10, "height": 10, "min_size": 10, "max_size": 10, "integer": True}):
        box = find(boxes(**kw), lambda b: True, settings=settings(database=None))
        np.testing.assert_array_equal(box, [0, 0, kw["width"], kw["height"]])
    spec = find(entity_specs(width=1, height=1, min_size=1), lambda e: True,
                settings=settings(database=None))  # fmt: skip
    assert (spec.appearance.size, spec.position) == ((1, 1), (0.5, 0.5))
    for strategy in (boxes, entity_specs):
        for key in ("width", "height"):
            with pytest.raises(InvalidArgument, match=f"{key}=0 must be >= 1"):
                strategy(**{"width": 5, "height": 5, key: 0})
    with pytest.raises(InvalidArgument, match="min_size=0 must be >= 1"):
        entity_specs(width=5, height=5, min_size=0)
    # two entities are enough for an occluder or a distractor
    first = settings(database=None, phases=[Phase.generate])
    for flag in ("occlusion", "distractors"):
        config = find(scene_configs(max_entities=2, **{flag: True}),
                      lambda c: len(c.entities) == 2, settings=first)  # fmt: skip
        assert len(config.entities) == 2


def test_the_default_seeds_are_every_non_negative_32_bit_integer(monkeypatch):
    drawn = []
    monkeypatch.setattr(S, "_sequences", lambda configs, seeds: drawn.append(seeds))
    sequences()
    (seeds,) = drawn
    assert find(seeds, lambda s: True, settings=settings(database=None)) == 0
    assert find(seeds, lambda s: s >= 2**32 - 1, settings=settings(database=None)) == 2**32 - 1
    with pytest.raises(NoSuchExample):  # (-1 is found in 2000 draws of integers(-1, ...))
        find(seeds, lambda s: s < 0 or s >= 2**32,
             settings=settings(database=None, max_examples=2000, derandomize=True))


def test_the_defaults_are_the_documented_ones(monkeypatch):
    # what each public strategy passes to its draw when called with its defaults (a
    # mutant of a default drew narrower or wider scenes than the docstrings say)
    calls = []
    for name in ("_scene_configs", "_entity_specs", "_ar2_params", "_boxes"):
        monkeypatch.setattr(S, name, lambda *args, _n=name: calls.append((_n, args)))
    scene_configs()
    entity_specs(width=50, height=40)
    S.ar2_params()
    S.boxes(width=20, height=10)
    off = dict.fromkeys(("occlusion", "clutter", "distractors", "noise", "exits", "realistic"),
                        False)  # fmt: skip
    assert calls == [
        ("_scene_configs", ((32, 120), (24, 90), (1, 8), (1, 3), (3, 24), 3.0, 2.0, 0.0, off)),
        ("_entity_specs", (50, 40, 1, "entity", ("target",), 3, 24, 3.0, 2.0, 0.0, False, False,
                           True)),
        ("_ar2_params", (S.BOUNDARIES, 2.0, 0.0)),
        ("_boxes", (320, 160, 16, 320, True, 16)),
    ]  # fmt: skip


def test_canvas_and_count_bounds_are_checked_by_name():
    # a max below its own minimum of 1 is named as such, not as the min > max it also is
    with pytest.raises(InvalidArgument, match="max_height=0 must be >= 1"):
        scene_configs(min_height=1, max_height=0)
    with pytest.raises(InvalidArgument, match="max_width=0 must be >= 1"):
        scene_configs(min_width=1, max_width=0)
    with pytest.raises(InvalidArgument, match="max_frames=0 must be >= 1"):
        scene_configs(min_frames=1, max_frames=0)
    for key in ("min_width", "min_height", "min_frames", "min_entities", "min_size"):
        with pytest.raises(InvalidArgument, match=f"{key}=0 must be >= 1"):
            scene_configs(**{key: 0})
    with pytest.raises(InvalidArgument, match="max_entities=0 must be >= 1"):
        scene_configs(min_entities=1, max_entities=0)


# --- every drawn config within its ranges (last: the slowest) -------------------------

CASES = {
    "defaults": {},
    "everything": {**EVERYTHING, "max_entities": 5, "min_size": 1},
    "margin": {"min_width": 64, "min_height": 48, "margin": 12, "occlusion": True,
               "clutter": True, "distractors": True, "noise": True, "realistic": True,
               "max_entities": 5},
    "tight": {"min_width": 40, "max_width": 40, "min_height": 30, "max_height": 30,
              "margin": 10, "max_size": 30, "occlusion": True, "max_entities": 4,
              "max_speed": 0.5, "max_sigma": 0.25},
    "few-frames": {"min_frames": 2, "max_frames": 3, "min_entities": 3, "max_entities": 6,
                   "exits": True, "distractors": True, "occlusion": True, "noise": True},
}  # fmt: skip


@pytest.mark.parametrize("case", list(CASES))
def test_every_drawn_value_is_in_its_range(case):
    kw = CASES[case]

    @settings(max_examples=150, database=None)
    @given(scene_configs(**kw))
    def each(config):
        check_config(config, **kw)

    each()


@settings(max_examples=100, database=None)
@given(spec=entity_specs(width=50, height=40, n_frames=6, roles=("target",), exits=True,
                         noise=True, max_speed=1.5, max_sigma=0.5))  # fmt: skip
def test_entity_specs_start_at_most_half_outside(spec):
    ew, eh = spec.appearance.size
    x, y = spec.position
    assert _within(x, 0, 50) and _within(y, 0, 40), spec  # the centre in the frame
    assert 3 <= ew <= 24 and 3 <= eh <= 24
    assert _within(spec.position_noise, 0, 3)
    if spec.motion is not None:
        for ar2 in (spec.motion.x, spec.motion.y):
            _check_ar2(ar2, S.BOUNDARIES, 0.5, 0.0)
        assert all(abs(v) <= 1.5 for v in spec.motion.velocity)
