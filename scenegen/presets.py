"""The presets: scenarios that reproduce the three papers' test sequences.

``names()`` lists them; ``get(name)`` returns a fresh :class:`~scenegen.config.SceneConfig`.
Each preset function's docstring names the paper section it reproduces and what differs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from scenegen.config import (
    AR2,
    Appearance,
    Background,
    Camera,
    ClutterSpec,
    EntitySpec,
    Motion,
    Photometric,
    SceneConfig,
    Variation,
)
from scenegen.config.messages import _short
from scenegen.errors import ConfigError

__all__ = ["all_names", "describe", "get", "names", "realistic_names"]

_PRESETS: dict[str, Callable[[], SceneConfig]] = {}
_REALISTIC: dict[str, Callable[[], SceneConfig]] = {}


def _preset(name: str) -> Callable[[Callable[[], SceneConfig]], Callable[[], SceneConfig]]:
    def register(fn: Callable[[], SceneConfig]) -> Callable[[], SceneConfig]:
        _PRESETS[name] = fn
        return fn

    return register


_ORIGINAL_ORDER = ("dps-synthetic", "dps-occlusion", "kams-a", "kams-b", "kams-c", "kams-d",
                   "shm-crossing")


def names() -> list[str]:
    """The preset names: the original seven in the contract's order, then the newer ones
    (``dps-occlusion-2``, ``dps-dancers``, ``shm-clutter``) in definition order.

    Returns
    -------
    list of str
        The names of the papers' scenarios.

    Examples
    --------
    >>> from scenegen import presets
    >>> presets.names()[:3]
    ['dps-synthetic', 'dps-occlusion', 'kams-a']
    """
    first = [n for n in _ORIGINAL_ORDER if n in _PRESETS]
    return first + [n for n in _PRESETS if n not in _ORIGINAL_ORDER]


def realistic_names() -> list[str]:
    """The realistic presets (real images, textures, camera motion, blur, light): kept
    apart from :func:`names` (the papers' scenarios, each with a committed fixture).

    Returns
    -------
    list of str
        Their names, in definition order.
    """
    return list(_REALISTIC)


def all_names() -> list[str]:
    """:func:`names` then :func:`realistic_names`: every name :func:`get` accepts.

    Returns
    -------
    list of str
        Every preset name.
    """
    return names() + realistic_names()


def get(name: str) -> SceneConfig:
    """The config of preset ``name`` (any of :func:`all_names`).

    Parameters
    ----------
    name : str
        The preset's name.

    Returns
    -------
    SceneConfig
        A new config, built on each call.

    Raises
    ------
    ConfigError
        For an unknown name, listing the valid ones.

    Examples
    --------
    >>> from scenegen import presets
    >>> config = presets.get("kams-a")
    >>> config.width, config.height, config.n_frames
    (320, 240, 140)
    """
    if not isinstance(name, str):  # a list was a TypeError (unhashable)
        raise ConfigError(f"unknown preset {_short(name)}; valid presets: {', '.join(all_names())}")
    if name in _REALISTIC:
        return _REALISTIC[name]()
    if name not in _PRESETS:
        raise ConfigError(f"unknown preset {name!r}; valid presets: {', '.join(all_names())}")
    return _PRESETS[name]()


def describe(name: str) -> str:
    """The first paragraph of the preset's docstring (what it reproduces).

    Parameters
    ----------
    name : str
        The preset's name (any of :func:`all_names`).

    Returns
    -------
    str
        The paragraph on one line (whitespace runs collapsed to one space).

    Raises
    ------
    ConfigError
        For an unknown name, listing the valid ones.
    """
    get(name)
    doc = ((_PRESETS.get(name) or _REALISTIC[name]).__doc__ or "").strip()
    return " ".join(doc.split("\n\n")[0].split())


def _walk(sigma: float, margin: float = 2.0, damping: float = 0.5) -> AR2:
    # Damped-velocity AR2 (docs/algorithms.md §1: A1 = 1 + d, A2 = -d), reflected at the border.
    return AR2(boundary="reflect", a1=1.0 + damping, a2=-damping, sigma=sigma, margin=margin)


_DPS_LOOKS = [
    ("ellipse", "sectors", ((220, 40, 40), (250, 220, 60), (40, 60, 200), (250, 250, 250))),
    ("rect", "stripes", ((30, 160, 60), (240, 240, 240))),
    ("rect", "bands", ((60, 60, 220), (230, 120, 30), (60, 60, 220))),
    ("ellipse", "rings", ((200, 40, 200), (90, 230, 230), (200, 40, 200))),
    ("rect", "checker", ((250, 140, 0), (30, 30, 30))),
    ("diamond", "solid", ((0, 190, 190),)),
    ("ellipse", "bands", ((255, 230, 0), (150, 0, 40))),
]
_DPS_START = [(70, 70), (180, 60), (290, 80), (60, 200), (170, 160), (280, 210), (170, 240)]


@_preset("dps-synthetic")
def dps_synthetic() -> SceneConfig:
    """DPS paper §3.2–3.3 (Fig. 2–3): seven coloured objects on random noise, with a
    distractor that copies object 1, pulls away from it and vanishes.

    360x288 RGB, 25 frames, i.i.d. noise background. Seven ~30x30 templates with distinct
    hue/saturation patterns move by AR2 with σ_u = σ_v = 3 px and no scale change. A
    distractor that mimics object 1 (colour jitter 6) appears over it at frame 3, drifts
    to the right at 8 px/frame and disappears at frame 9; object 1 must then be
    re-acquired.

    Differs from the paper: the paper's AR2 coefficients are not given; we damp the
    velocity (A1 = 1.5, A2 = −0.5) so that objects wander ~30 px in 25 frames and stay
    mostly apart, and reflect them at the border (2 px margin). The paper learned object
    1's model from the distractor; here trackers learn it from object 1 at frame 0, and the
    distractor is a slightly recoloured copy drawn in front of every object.

    Tuned (issue 6, item 6): the paper gives neither the distractor's speed nor its
    direction. The distractor's drift was first (5, 3.5) px/frame, ~30 px over its six
    frames: a track that followed it still overlapped object 1's 30x30 box, so object 1
    was never lost and then recovered, and the paper's recovery effect did not appear. We
    set the drift to (8, 0) px/frame, ~40 px to the right by frame 8, so that a track pulled
    along by the distractor loses object 1. The drift was chosen on tracker seeds other
    than the experiment's: with 16 runs per method at λ = 20, object 1's recovery was 75%
    for DPS, 51% for the mean of the seven PS orderings and 25% for Non-PS ((9, 0):
    81/68/31%; (10, 0) is too fast to pull the trackers away). That was one scene; over
    many scenes the lead vanished (issue 14, below). The appear and disappear frames (3
    and 9) are the paper's.

    Issue 14 (measured on base seeds 1, 2, 3 only, 30 scenes, λ = 20, 1–5 runs per scene
    and method; base seed 0 was not looked at): the scene is kept as it is, because the PS
    ordering cannot decide object 1's fate on any scene with our PS. The distractor
    overlaps object 1's box for 2–6 frames (median 4); when it captures object 1's
    particles (object 1 lost in 15–33 % of PS runs, mostly first at frames 6–12) the
    track is gone for good (1 of 24 lost PS runs recovered), and whether that happens is
    decided by the scene far more than by the sampling (per scene, the PS runs recover
    0 % or 100 % in 19 of 30 scenes). Five variants of the distractor were run with all
    nine methods or five of them: an exact copy (colour jitter 0) at (8, 0) and (10, 0)
    px/frame, and an exact copy that lingers over object 1 and then accelerates away
    (AR2 a1 = 2.5 or 2.6, a2 = −1.5 or −1.6, from 2 or 3 px/frame: 3–9 px apart at frame
    4, 37–71 px at frame 8). They moved object 1's PS recovery between
    ~55 % and ~80 %, but in none did the orderings differ (χ² p 0.2–0.95 over the seven
    orderings with 60 runs each; 59 / 66 / 63 % with 150 runs each for object 1 sampled
    first / last / fourth on the lingering copy), nor did DPS lead PS. The reason is
    structural: in our PS (the paper's Fig. 1 scheme) each object's sub-state goes, every
    frame, through the same cycle — its own dynamics, a resampling by its own likelihood,
    then six resamplings by the other objects' likelihoods, which do not depend on it —
    whatever its place in the ordering; the place only changes at which point of that
    cycle the estimate and the uniqueness are read. The first-stage object's low
    uniqueness (8–9 % against 100 %) is real but is read after its own resampling and five
    foreign ones, the last-stage object's right after its dynamics, and the next frame's
    dynamics re-spread every object alike. A diagnostic variant of PS
    that applies every object's dynamics before the first stage (not committed, not the
    paper's scheme: objects 2–7 then fail half the time) does make the ordering matter
    (28 % sampled last against 57–62 % sampled first or second, χ² p = 0.001), which
    locates the effect in the sampling scheme, not in the scene. Details and the judged
    numbers: docs/experiments.md, "DPS Table 2".

    Round 4: that PS was our reading of weighted resampling ("placed": each stage draws
    by its own object's likelihood). The papers' own statement, g = p(Z | X_{o_j}) with
    ancestors ∝ π g (``weighting="stage"``, now the trackers' default), does make the
    ordering matter on this unchanged scene: on base seeds 0 and 7 (neither used for
    tuning) object 1 sampled in the last three stages is recovered in 57–83 % of runs,
    in the first four in 34–65 %, and the orderings differ at every λ (Cochran's Q p <=
    0.034); docs/experiments.md, "Other readings of PS".
    """
    ents = []
    for i, ((shape, pattern, colors), pos) in enumerate(zip(_DPS_LOOKS, _DPS_START, strict=True)):
        ents.append(
            EntitySpec(
                name=f"object{i + 1}",
                role="target",
                appearance=Appearance(shape=shape, size=(30, 30), pattern=pattern, colors=colors),
                position=pos,
                motion=Motion(x=_walk(3.0), y=_walk(3.0)),
                depth=((0, i + 1),),
            )
        )
    ents.append(
        EntitySpec(
            name="distractor1",
            role="distractor",
            mimic="object1",
            color_jitter=6.0,
            motion=Motion(
                x=AR2(boundary="reflect", sigma=0.5, margin=2),
                y=AR2(boundary="reflect", sigma=0.5, margin=2),
                velocity=(8.0, 0.0),
            ),
            appear=3,
            disappear=9,
            depth=((0, 0),),
        )
    )
    return SceneConfig(
        name="dps-synthetic",
        width=360,
        height=288,
        n_frames=25,
        background=Background(kind="noise"),
        entities=tuple(ents),
    )


_SKIN = (225, 180, 150)
_HAIR = (60, 40, 30)


def _person(colors: tuple[tuple[int, int, int], ...], size: tuple[int, int]) -> Appearance:
    return Appearance(shape="ellipse", size=size, pattern="bands", colors=colors)


# The DPS real-sequence analogues share one builder so that the tuned quantities are named.
_WALKER = (_HAIR, _SKIN, (200, 30, 30), (40, 40, 120))


def _standing(name: str, shirt: tuple[tuple[int, int, int], ...], x: float, y: float,
              depth: int, size: tuple[int, int] = (44, 50)) -> EntitySpec:
    """A stationary person; ``shirt`` is one or more colour bands between face and legs."""
    return EntitySpec(
        name=name,
        role="target",
        appearance=_person((_HAIR, _SKIN, *shirt, (40, 40, 120)), size),
        position=(x, y),
        depth=((0, depth),),
    )


def _walker(speed: float, x0: float, y0: float, depth: tuple[tuple[int, int], ...],
            sigma_x: float = 0.02) -> EntitySpec:
    return EntitySpec(
        name="walker",
        role="target",
        appearance=_person(_WALKER, (32, 42)),
        position=(x0, y0),
        motion=Motion(
            x=AR2(boundary="reflect", sigma=sigma_x, margin=2),
            y=_walk(0.1, margin=2),
            velocity=(speed, 0.0),
        ),
        depth=depth,
    )


_OCCLUSION_BG = Background(kind="texture", color=(200, 200, 180), low=60, high=200, scale=6)

OCCLUSION_TUNING: dict[str, object] = {
    "speed": 1.6,
    # Half the walker's red (same HSV bins), half blue: it attracts the hidden walker's
    # particles, yet scores below the walker once the walker is visible again. Worn by
    # the first person since round 12 (until then by the second, and the first wore green).
    "shirt1": ((200, 60, 40), (40, 90, 200)),
    "shirt2": ((40, 140, 40),),
}
"""The quantities of ``dps-occlusion`` that were tuned (see its docstring)."""


@_preset("dps-occlusion")
def dps_occlusion() -> SceneConfig:
    """DPS paper §5.2, RealSeq1 (Fig. 7, Table 3): a person walks behind two stationary
    people and is totally occluded for several frames each time.

    360x288, 191 frames, smooth textured background. Three targets: object 1 (the walker,
    32x42, 1.6 px/frame with small acceleration noise) passes behind objects 2 and 3
    (stationary, 44x50, standing in front); each total occlusion lasts about 10 frames.
    The stationary people share the walker's hair, face and trouser colours; the first
    one's shirt is half the walker's red, so it distracts the walker's particles while the
    walker is hidden behind it (the second wears green). Until round 12 the attractor was
    on the second person and the first wore green; the paragraphs below that speak of
    "the half-red person" at x ≈ 235 or of rounds before 12 are about that scene.

    Why DPS got 36 % on the previous version (analysis in docs/experiments.md): the second
    person's shirt, RGB (200, 60, 40), fell in the same 10-bin HSV histogram cells as the
    walker's (200, 30, 30), so to the trackers it *was* the walker. Every method carried
    the walker through the first occlusion; at the second, the walker's particles settled
    on the twin and stayed there when the walker walked on (failures at frames 146–161,
    the estimate at the twin's x ≈ 230). Impoverishment was present — uniqueness of the
    walker 40 % in PS(1,2,3), 100 % when it is sampled last, 66–68 % for every object in
    DPS — but a perfect twin defeats spread and impoverished particle sets alike, so the
    success rates did not follow the sampling scheme (seed-1 scenes: Non-PS 17 %, PS 8–33 %,
    DPS 25 %). With a blue shirt instead every method succeeded in 12 of 12 runs.

    Tuned (issue 14, round 2): the second person's shirt (one band in the walker's red,
    one blue: an attractor that is not a twin), on base seed 1 (6 scenes x 2 runs, not
    the judged scenes): Non-PS 67 %, each PS ordering 67 %, DPS 92 % success. Also tried:
    walker speed 1.0 with the twin (Non-PS 83 %, PS 92–100 %, DPS 92 %: too easy), 2.0 with
    the half-twin (Non-PS 75 %, PS 83–92 %, DPS 75 %). Judged on base seed 0: DPS 64 %,
    PS 46–70 % (57 % pooled, p = 0.18), Non-PS 46 %.

    Round 3 (issue 14), on base seeds 1, 2 and 3 only (6 scenes x 2 runs each, 36 runs per
    method): Non-PS 36 %, PS(1,2,3) 67 %, PS(2,3,1) 67 %, PS(3,1,2) 72 %, DPS 58 %. The
    failures start after the second total occlusion (frames ~140–180): the walker's
    estimate stays on the half-red person (x ≈ 225–250) while the walker walks on
    (x ≈ 250–290); about one in ten starts earlier (frames ~108–125), the particles
    jumping ahead onto that person as the walker goes behind it. The walker's end-of-step
    uniqueness follows its stage (PS(1,2,3) 40 %, PS(3,1,2) 57 %, PS(2,3,1) 100 %, DPS
    66 %), but measured where it matters, at the walker's own propagation
    (``tools/occlusion/cycle.py``), every PS ordering and DPS propagate it from the same
    share of distinct ancestors (29–32 %) with the same spread (6.6–7.9 px): between two
    propagations of an object, every ordering applies the same three selections (its own
    likelihood, then the other two objects', which do not depend on its state), only at
    another point of the step. So no scene can make the PS ordering or DPS decide the
    walker's fate on our trackers (docs/experiments.md, "DPS Table 3: why the orderings
    cannot differ with the `placed` weighting"). Variants tried, all methods with the same
    parameters: tracker dynamics σ = (3, 3, 0.001) (seeds 1–2: DPS 83 %, PS 62–79 %, Non-PS
    54 %; seed 3: DPS 25 %, PS 50–75 %, Non-PS 25 %: the lead was noise); λ = 40 (seeds 1–2:
    DPS 71 %, PS 75–83 %, Non-PS 46 %). Nothing was kept: the scene and the paper's tracker
    parameters are those of round 2. Replication on base seed 5 (never used for tuning): DPS
    72 %, PS 62–68 % (64 % pooled, p = 0.15), Non-PS 64 %.

    Round 4: the cycle argument above holds for the ``placed`` weighting, our reading of
    weighted resampling until then. With the papers' ``stage`` weighting (now the
    default), the ordering reaches an object's propagation, and on ``dps-synthetic`` (seven
    objects) it decides object 1's recovery; here, with three objects, the walker is
    thinned once per step and not while hidden, and on 30 judged scenes (base seed 0)
    DPS keeps it in 59 % of runs against 53–61 % for the PS orderings (+3 points pooled,
    95 % interval −4 to +11) and 46 % for Non-PS. The scene is unchanged
    (docs/experiments.md, "Other readings of PS").

    Round 5, where the walker moves from (``stage``; tuning seeds 1–3, 18 runs per
    method): sampled first it ends the step with 39 % distinct states, sampled last with
    100 % (DPS 62 %), the paper's Fig. 8; but at its own propagation it moves from 28 %
    distinct ancestors when first and 20 % when last (DPS 28 %), with the same spread,
    6.8–7.1 px, for every ordering and DPS. The last object's unique states are fresh
    candidates, selected by the next step's stages before it moves again. So no sampling
    scheme gives the hidden walker a wider cloud to cross the half-red person (at λ = 150:
    3.6–4.8 px, no ordering pattern; DPS 38–58 % against PS 33–52 %). Docs:
    "DPS Table 3 with the `stage` weighting".

    Round 6, seven tracked objects (``tools/dps/variants.py --crowd``: four stationary
    objects of ``dps-synthetic`` added near the corners, N = 300; tuning seeds 1–3, 18
    runs per method): the walker sampled first ends the step with 11.5 % distinct states,
    but every method loses it in most runs (DPS 2 / 18, PS pooled 21 / 126, Non-PS 2 / 18),
    the final weights keeping six likelihoods. Not adopted.

    Round 10, whether the walker's spread decides it (tracker σ_u = σ_v = 1, 2, 3, 4 for
    every method; base seeds 1–3, the default 10 x 5 each, runs paired): PS and DPS keep
    the walker in 54 / 59 / 59 / 54 % of runs, σ = 4 against σ = 1 +0.2 points (scene
    bootstrap 95 % interval −6 to +6), though the PS and DPS clouds at the walker's
    propagation widen from 4.6–6.5 to 8.9–9.7 px (``tools/occlusion/cycle.py``, 3 runs
    per method and σ). This scene's failures are not
    spread-limited: the paper's condition ("its dynamics must be sufficiently spread",
    §5.2) does not hold here. ``dps-occlusion-2`` meets it, and DPS still does not lead
    there. Not re-tuned, for that reason (docs/experiments.md, "Does the walker's spread
    decide it?").

    Round 11 (tuning seeds 1–3): the wider cloud changes *when* the walker is lost, not
    where: at σ = 4 as at σ = 1 all but 6–10 of ~100 failures begin at the half-red
    person, with the walker 70–100 % visible, but about ten frames later (median 26
    against 16.5 frames since it was last hidden). Dressing both stationary people in the
    half-red attractor (``--tune 'shirt1=[[200, 60, 40], [40, 90, 200]]'``) does not make
    the scene spread-limited either (σ = 4 against σ = 1: +5.0 points, −6.7 to +15.9), so
    the scene is unchanged (docs/experiments.md, "A second candidate for a
    spread-limited `dps-occlusion`"). Swapping the two shirts (the attractor on the first
    person, green on the second) does: σ = 4 against σ = 1 +17.5 points (+9.2 to +25.8),
    every failure but one behind the attractor. Judged once, as pre-registered, on base
    seed 23 (30 x 5): DPS 61 %, PS 72 / 64 / 58 %, Non-PS 55 %; DPS − PS pooled −3.3
    points (−10.2 to +3.3). Not adopted in round 11 ("A third candidate: the attractor
    on the first person").

    Round 12: adopted (the shirts swapped, nothing else), because it is the one version
    of the scene on which all three of the paper's RealSeq1 conditions hold: slow total
    occlusions, an attractor beside the hidden walker, and failures that a wider cloud
    prevents. It was chosen by that criterion on tuning seeds 1–3 and judged on seed 23
    before adoption; the report's verdicts are re-judged on base seed 0, whose scenes no
    tuning used (docs/experiments.md, "The attractor on the first person, adopted").

    Differs from the paper: RealSeq1 is real video of people; ours are banded ellipses
    (hair/face/shirt/trousers), the occluders are a little larger than the walker so that
    occlusion is total for several frames each time, and the walk is nearly straight.
    """
    t = OCCLUSION_TUNING
    return SceneConfig(
        name="dps-occlusion",
        width=360,
        height=288,
        n_frames=191,
        background=_OCCLUSION_BG,
        entities=(
            _walker(float(t["speed"]), 30.0, 150.0, ((0, 2),)),  # type: ignore[arg-type]
            _standing("standing1", t["shirt1"], 130.0, 150.0, 0),  # type: ignore[arg-type]
            _standing("standing2", t["shirt2"], 235.0, 151.0, 1),  # type: ignore[arg-type]
        ),
    )


OCCLUSION2_TUNING: dict[str, object] = {
    "speed": 1.7,
    # The occluder wears the half-red attractor of ``dps-occlusion`` (round 8); until then
    # it was green and the second person wore the walker's twin shirt, (200, 60, 40).
    "shirt1": ((200, 60, 40), (40, 90, 200)),
    "shirt2": ((40, 140, 40),),
}
"""The quantities of ``dps-occlusion-2`` that were tuned (see its docstring)."""


@_preset("dps-occlusion-2")
def dps_occlusion_2() -> SceneConfig:
    """DPS paper §5.2, RealSeq2 (Fig. 9, Table 3): a person walks behind one stationary
    person, then passes in front of a second one.

    360x288, 139 frames (as RealSeq2), the background and people of ``dps-occlusion``.
    Object 1 (the walker) is hidden for 8–9 frames behind object 2 (the first stationary
    person) and then occludes object 3 while passing in front of it. Object 2 wears the
    half-red shirt of ``dps-occlusion``'s second person, which attracts the hidden
    walker's particles; object 3 a green one.

    Tuned in round 8 (docs/experiments.md, "`dps-occlusion-2` re-tuned so that an
    occlusion decides it"), on base seeds 1–3 (5 scenes x 2 runs each): until then object 2
    wore green and object 3 the walker's twin shirt, RGB (200, 60, 40), in the walker's
    HSV histogram cells. ``tools/occlusion/failures.py`` showed that the old scene never
    lost the walker at an occlusion: every failure began in plain view (visibility 1.00)
    while the walker passed in front of the twin, 63–78 frames after its one total
    occlusion, where no sampling scheme can tell the two apart. With the attractor on the
    occluder every failure of every method begins at the occlusion (11–21 frames after
    the walker was last hidden), as the paper's do ("PS(1,2,3) fails to recover from
    occlusion", its Fig. 9). The shirts were chosen by that condition, not by any
    method's rate; tuning runs: Non-PS 23, PS 20 / 23 / 24, DPS 25 of 30 (old: 19, 18 /
    22 / 19, 16). A blue third shirt gave the same runs; a slower walker (1.4 px/frame)
    moved failures back to the second person. Judged on base seed 13 (first), then 0:
    DPS 72 / 78 %, PS 76–88 / 76–94 % (82 / 84 % pooled), Non-PS 58 / 56 %; 59 of 62 and
    56 of 57 failures begin at the occlusion. Round 10 (tracker σ_u = σ_v = 1, 2, 3, 4;
    base seeds 1–3, 10 x 5 each): PS and DPS keep the walker in 62 / 76 / 78 / 84 % of
    runs (σ = 4 against 1: +22 points, 95 % interval +15 to +28) as their clouds at the
    walker's propagation widen from 5.6–5.9 to 9.2–11.3 px, so here the spread does decide
    it, as the paper's condition needs; yet at σ = 2 the PS orderings and DPS move it with
    the same spread (6.8–7.5 px, no ordering pattern), so the ordering cannot act through
    it. The rest of this docstring is
    about the version before round 8.

    Round 2, not tuned: on base seed 1 (6 scenes x 2 runs) this version gives Non-PS 33 %,
    PS 58–67 %, DPS 50 % success. Tried without a gain for DPS: the first person in the
    half-red shirt of ``dps-occlusion`` (Non-PS 33 %, PS 42–67 %, DPS 42 %), both people in
    it (67 / 67–92 / 58 %), the second only (92 / 100 / 100 %). At the walker's own
    propagation every PS ordering and DPS spread it from the same share of distinct
    ancestors, as on ``dps-occlusion`` (``tools/occlusion/cycle.py`` on seeds 1–3, 3
    scenes x 1 run each: 30–33 %, spread 6.9 px; Non-PS 35 %). Judged
    on base seed 0: DPS 66 %, PS 62–74 % (69 % pooled), Non-PS 62 %; on base seed 5
    (replication): DPS 84 %, PS 58–78 % (67 % pooled, p = 0.010), Non-PS 46 %.

    Differs from the paper: as ``dps-occlusion``; the paper's occlusions last 6 and 10
    frames, ours about as long (walker 32 px wide, occluders 44 px, speed below).
    """
    t = OCCLUSION2_TUNING
    return SceneConfig(
        name="dps-occlusion-2",
        width=360,
        height=288,
        n_frames=139,
        background=_OCCLUSION_BG,
        entities=(
            _walker(float(t["speed"]), 40.0, 150.0, ((0, 1),)),  # type: ignore[arg-type]
            _standing("standing1", t["shirt1"], 130.0, 150.0, 0),  # type: ignore[arg-type]
            _standing("standing2", t["shirt2"], 235.0, 151.0, 2),  # type: ignore[arg-type]
        ),
    )


_DANCER_SHIRTS = ((200, 40, 160), (40, 160, 200), (230, 200, 40), (230, 230, 230))
_DANCER_TROUSERS = ((60, 60, 140), (60, 60, 140), (60, 60, 140), (20, 20, 20))

DANCERS_TUNING: dict[str, object] = {
    # Sway of dancers 1–3 and of dancer 4: amplitude (px), period (frames), AR2 noise σ
    # (px/frame², the erratic part of the sway).
    "amplitude": 28.0, "period": 21.0, "sigma": 2.0,
    "amplitude4": 28.0, "period4": 21.0, "sigma4": 2.0,
    "shirts": _DANCER_SHIRTS,
    # Centres of the sways: dancer 4 at 250 px overlaps dancer 3 only partly.
    "xs": (50.0, 115.0, 185.0, 250.0),
}
"""The quantities of ``dps-dancers`` that were tuned (see its docstring)."""


def _sway(amp: float, period: float, sigma: float, mean: float, sign: float) -> tuple[AR2, float]:
    # x = mean + sign amp cos(ωt) as a (slightly damped) AR2 oscillation, plus noise σ;
    # returns the AR2 and the initial velocity.
    omega, r = 2 * np.pi / period, 0.999
    a1, a2 = 2 * r * float(np.cos(omega)), -(r**2)
    v0 = sign * amp * (1 - float(np.cos(omega)))
    return AR2(boundary="free", a1=a1, a2=a2, sigma=sigma, mean=mean), v0


@_preset("dps-dancers")
def dps_dancers() -> SceneConfig:
    """DPS paper §5.2, RealSeq3 (Fig. 10, Table 4): four dancers; dancer 4 (black
    trousers) is partly occluded by dancer 3 and must be followed with 200 particles.

    352x240, 32 frames (as RealSeq3). Four 32x40 dancers stand in a row and sway
    horizontally: an AR2 oscillation (amplitude 28 px, period 21 frames) with acceleration
    noise σ = 2 px/frame² (an erratic sway, at the size of the trackers' own dynamics
    noise; peak speeds 10–30 px/frame, median 20, over 40 scene seeds). Dancer 4 sways in
    antiphase with dancer 3 and passes behind it around frames 9–13: at the closest point
    it is less than half visible in 90 % of scenes, totally hidden in 2.5 %. The sway is
    unbounded, so in a few scenes (3 of 40) a dancer leaves the frame for some frames
    (those frames are not scored). The experiment (``DPS_DANCERS``) runs every method
    with N = 200 and λ = 150, so DPS's four mixture components have 50 particles each —
    the limitation Table 4 shows (DPS 36% success against 26–84% for the PS orderings).

    Why DPS was not limited on the previous version (issue 14; measured on base seeds 1–3,
    3 scenes x 2 runs): with λ = 20 the likelihood is broad, the effective sample size
    (ESS) of the stage that places dancer 4 is 35–39 % of the particles it weighs — ~70 of
    200 in PS, ~20 of 50 in each DPS component — so 50 particles per component already
    cover dancer 4's motion. The failures (frames 13–16) came from the full occlusion:
    dancer 4 reverses behind dancer 3 and its particles leave with the old velocity, which
    no particle count repairs (Non-PS 11 %, every PS ordering and DPS 44–56 %).

    Tuned (issue 14) on base seeds 1–4, never on the judged seeds 0 and 5: dancer 4's
    sway centre (235 → 250 px: partial occlusion), the sway noise σ (0.3 → 2) and λ
    (20 → 150, the same for every method). With the peaked likelihood the ESS of dancer
    4's stage falls to ~5 of 50 in a DPS component (~15 of 200 in PS): a component then
    rests on a handful of particles for each erratic dancer, and DPS loses dancer 4 more
    often at both crossings. Kept variant, seeds 1–4 (8 scenes x 2 runs): Non-PS 9 %, PS
    77–83 % (pooled 79 %), DPS 67 % success of dancer 4; failures in frames 10–15 (first
    crossing): DPS 11, PS 6–8 per ordering; in frames 20–31 (second): DPS 10, PS 3–8.
    Also tried (3–6 scenes x 2 runs, seeds 1–3 or 2–4): only a more erratic dancer 4
    (σ4 = 2–3) or all dancers erratic at λ = 20: every method 11–44 %; the partial
    occlusion alone: PS 83–100 %, DPS 94–100 %; with λ = 60–400 and smooth sway: PS and
    DPS 100 % (DPS ESS 3–9 per component is still enough for a smooth sway); dancer 3 in
    dancer 4's shirt (λ = 60): PS 61–94 %, DPS 78 %; σ = 2 with λ = 200: PS 64–78 %, DPS
    75 %; σ4 = 2.5: PS 55–59 %, DPS 55 %. The DPS deficit is thus small and depends on λ.
    Judged after freezing this (base seed 0, and seed 5 as a replication): not reproduced,
    DPS is at the PS orderings' level; docs/experiments.md, "DPS Table 4", has the numbers.

    Differs from the paper: real dancers are replaced by banded ellipses; the sway is
    periodic plus noise; λ is larger than the paper's 20 (tuned, above). In the paper the
    worst ordering is PS(1,2,3,4), which samples dancer 4 last; here the orderings are
    alike on the tuning seeds (dancer 4 is not impoverished when sampled last, as DPS
    §3.3 predicts, nor much when sampled first).
    """
    t = DANCERS_TUNING
    shirts = t["shirts"]
    ents = []
    for i, x in enumerate(t["xs"]):  # type: ignore[arg-type]
        # x = mean ± amp cos(ωt): dancers 1–3 start left, dancer 4 right (antiphase), so
        # dancer 4 passes behind dancer 3 around t = period / 2.
        four = i == 3
        sign = 1.0 if four else -1.0
        sway, v0 = _sway(float(t["amplitude4" if four else "amplitude"]),  # type: ignore[arg-type]
                         float(t["period4" if four else "period"]),  # type: ignore[arg-type]
                         float(t["sigma4" if four else "sigma"]),  # type: ignore[arg-type]
                         x, sign)
        ents.append(
            EntitySpec(
                name=f"dancer{i + 1}",
                role="target",
                appearance=_person((_HAIR, _SKIN, shirts[i], _DANCER_TROUSERS[i]),  # type: ignore[index]
                                   (32, 40)),
                position=(x + sign * float(t["amplitude4" if four else "amplitude"]), 120.0),  # type: ignore[arg-type]
                motion=Motion(x=sway, y=_walk(0.3, margin=2), velocity=(v0, 0.0)),
                depth=((0, 3 if four else i),),
            )
        )
    return SceneConfig(
        name="dps-dancers",
        width=352,
        height=240,
        n_frames=32,
        background=_OCCLUSION_BG,
        entities=tuple(ents),
    )


_KAMS_COLORS = ((230, 30, 30), (30, 170, 30), (30, 60, 230), (240, 210, 0))


def _kams(name: str, sigma: float, n_clutter: int) -> SceneConfig:
    disc = Appearance(shape="ellipse", size=(30, 30), pattern="sectors", colors=_KAMS_COLORS)
    target = EntitySpec(
        name="target",
        role="target",
        appearance=disc,
        position=(70.0, 120.0),
        motion=Motion(
            x=AR2(boundary="reflect", a1=1.9, a2=-0.9, sigma=0.6, margin=20),
            y=AR2(boundary="reflect", a1=1.9, a2=-0.9, sigma=0.6, margin=20),
            velocity=(2.0, 1.0),
        ),
        position_noise=sigma,
        depth=((0, 0),),
    )
    clutter = ClutterSpec(
        count=n_clutter,
        appearance=Appearance(shape="ellipse", size=(16, 16), pattern="sectors",
                              colors=_KAMS_COLORS),
        palette=_KAMS_COLORS,
        n_colors=4,
        min_size=8,
    )
    return SceneConfig(
        name=name,
        width=320,
        height=240,
        n_frames=140,
        background=Background(kind="uniform", color=(255, 255, 255)),
        entities=(target,),
        clutter=(clutter,),
    )


@_preset("kams-a")
def kams_a() -> SceneConfig:
    """KAMS paper §3.2, Fig. 7(a): a multicoloured disc on white with measurement noise
    σ = 4 and 100 static clutter discs.

    320x240, 140 frames. The target (a 30 px disc of four coloured sectors) follows a
    smooth damped-velocity AR2 path (A1 = 1.9, A2 = −0.9, σ = 0.6, reflected 20 px inside
    the border); each frame it is drawn at the path position plus N(0, σ²) noise. Clutter:
    discs of 8–16 px whose four sectors take random colours from the target's palette,
    always behind the target.

    The clutter is smaller than the target so that, as in the paper, it adds *local*
    maxima to the colour likelihood and leaves the background partly white (kams-d: about
    60% of the frame covered). With clutter discs as large as the target (16–30 px, an
    earlier version) about one disc in ten has the target's four colours in equal parts,
    i.e. its histogram: windows far from the target reached a Bhattacharyya distance of
    0.00–0.02, the target was not the likelihood's unique maximum, and no colour tracker
    could follow it through the σ = 14 jumps. At 8–16 px the best window more than 20 px
    from the target scores d ≥ 0.10 (kams-d, seeds 0–2) against 0 at the target.

    Differs from the paper: the paper's path and object sizes are not given; ours are as
    above.
    """
    return _kams("kams-a", 4.0, 100)


@_preset("kams-b")
def kams_b() -> SceneConfig:
    """KAMS paper §3.2, Fig. 7(b): as kams-a with σ = 8 and 300 clutter discs.

    Differs from the paper: path and sizes chosen by us (see kams-a).
    """
    return _kams("kams-b", 8.0, 300)


@_preset("kams-c")
def kams_c() -> SceneConfig:
    """KAMS paper §3.2, Fig. 7(c): as kams-a with σ = 12 and 500 clutter discs.

    Differs from the paper: path and sizes chosen by us (see kams-a).
    """
    return _kams("kams-c", 12.0, 500)


@_preset("kams-d")
def kams_d() -> SceneConfig:
    """KAMS paper §3.2, Fig. 7(d): as kams-a with σ = 14 and 600 clutter discs.

    Differs from the paper: path and sizes chosen by us (see kams-a).
    """
    return _kams("kams-d", 14.0, 600)


@_preset("shm-crossing")
def shm_crossing() -> SceneConfig:
    """SHM paper §5: two objects (like hands) cross each other six times; their depth
    order swaps between crossings.

    360x288, 120 frames, a smooth textured background with some static clutter around the
    crossing point. Two 40x40 objects oscillate horizontally in antiphase (AR2 with
    A1 = 2r cos ω, A2 = −r², ω = 2π/40, r = 0.999: x ≈ 180 ± 70 cos ωt), 14 px apart
    vertically, so they overlap by up to ~65% at t ≈ 10, 30, 50, 70, 90, 110. Hand A is in
    front for the first two crossings, hand B for the next two, A again for the last two;
    the order changes at t = 40 and 80 while the hands are apart. Appearance varies with
    pose: ±8° rotation and ±8% shading.

    Differs from the paper: the paper tracks real hands in video; ours are textured
    patches whose motion is nearly periodic so that the crossings are predictable.
    """
    omega, r, amp = 2 * np.pi / 40, 0.999, 70.0
    a1, a2 = 2 * r * float(np.cos(omega)), -(r**2)
    v0 = amp * (1 - float(np.cos(omega)))

    def hand(name, colors, shape, pattern, x0, v, y0, depth, phase):
        return EntitySpec(
            name=name,
            role="target",
            appearance=Appearance(shape=shape, size=(40, 40), pattern=pattern, colors=colors),
            position=(x0, y0),
            motion=Motion(
                x=AR2(boundary="free", a1=a1, a2=a2, sigma=0.2, mean=180.0),
                y=AR2(boundary="reflect", a1=1.5, a2=-0.6, sigma=0.4, mean=y0),
                velocity=(v, 0.0),
            ),
            variation=Variation(rotation=8.0, shading=0.08, period=37.0, phase=phase),
            depth=depth,
        )

    a = hand(
        "hand-a", ((230, 170, 130), (150, 90, 60)), "ellipse", "stripes",
        180.0 + amp, v0, 137.0, ((0, 0), (40, 1), (80, 0)), 0.0,
    )  # fmt: skip
    b = hand(
        "hand-b", ((90, 140, 220), (240, 240, 240)), "rect", "checker",
        180.0 - amp, -v0, 151.0, ((0, 1), (40, 0), (80, 1)), 1.3,
    )  # fmt: skip
    clutter = ClutterSpec(
        count=15,
        appearance=Appearance(shape="ellipse", size=(14, 14), pattern="solid"),
        palette=((230, 170, 130), (90, 140, 220), (120, 120, 120), (200, 200, 90)),
        min_size=8,
        region=(130.0, 90.0, 100.0, 110.0),
    )
    return _shm_scene("shm-crossing", a, b, (clutter,))


def _shm_hands() -> tuple[EntitySpec, EntitySpec]:
    cfg = shm_crossing()
    return cfg.entities[0], cfg.entities[1]


SHM_CLUTTER_TUNING: dict[str, object] = {"count": 6, "size": 36, "min_size": 30}
"""The quantities of ``shm-clutter`` that were tuned (see its docstring)."""


@_preset("shm-clutter")
def shm_clutter() -> SceneConfig:
    """SHM paper §5, Fig. 5(c): the crossing of ``shm-crossing`` in front of background
    clutter that resembles the hands (heavy occlusion and clutter).

    As ``shm-crossing``, plus hand-sized static patches drawn with the hands' own colours
    and patterns (striped skin-coloured ellipses like hand A, blue-and-white checked
    rectangles like hand B) around the crossing, behind both hands. A tracker that follows
    one measurement per target (Kalman) is pulled onto a look-alike patch when its hand is
    occluded; SHM's hypothesized measurements keep both hands.

    Tuned (issue 14) on base seed 1 (8 scenes; judged on base seed 0): the number and size
    of the look-alike patches per hand. Both hands tracked throughout, Kalman / SHM / fast
    SHM: 4 patches of 30–36 px: 62 / 75 / 75 %; 6 (kept): 25 / 75 / 75 %, mean centre error
    13.4 / 6.6 / 6.6 px; 8: 25 / 62 / 62 %; 6 of 36–40 px: 12 / 12 / 12 % (too hard for all).

    Differs from the paper: the paper's clutter is the real background of its hand video;
    ours are static copies of the hands' colours and patterns.
    """
    a, b = _shm_hands()
    t = SHM_CLUTTER_TUNING
    size, lo = int(t["size"]), int(t["min_size"])  # type: ignore[call-overload]
    n = int(t["count"])  # type: ignore[call-overload]
    like_a = ClutterSpec(
        count=n,
        appearance=Appearance(shape="ellipse", size=(size, size), pattern="stripes",
                              colors=((230, 170, 130), (150, 90, 60))),
        palette=((230, 170, 130), (150, 90, 60)),
        n_colors=2,
        min_size=lo,
        region=(70.0, 80.0, 220.0, 130.0),
        name="clutter-a",
    )
    like_b = ClutterSpec(
        count=n,
        appearance=Appearance(shape="rect", size=(size, size), pattern="checker",
                              colors=((90, 140, 220), (240, 240, 240))),
        palette=((90, 140, 220), (240, 240, 240)),
        n_colors=2,
        min_size=lo,
        region=(70.0, 80.0, 220.0, 130.0),
        name="clutter-b",
    )
    return _shm_scene("shm-clutter", a, b, (like_a, like_b))


def _shm_scene(name: str, a: EntitySpec, b: EntitySpec,
               clutter: tuple[ClutterSpec, ...]) -> SceneConfig:
    return SceneConfig(
        name=name,
        width=360,
        height=288,
        n_frames=120,
        background=Background(kind="texture", color=(180, 200, 190), low=40, high=160, scale=8),
        entities=(a, b),
        clutter=clutter,
    )


# --------------------------------------------------------------------------------------
# Realistic presets (issue 18): real images and textures from scikit-image (no download),
# camera motion, motion blur, illumination change and JPEG. Ground truth is exact: boxes,
# labels and visibility are those of the sharp silhouettes (docs/format.md).


def _realistic(name: str) -> Callable[[Callable[[], SceneConfig]], Callable[[], SceneConfig]]:
    def register(fn: Callable[[], SceneConfig]) -> Callable[[], SceneConfig]:
        _REALISTIC[name] = fn
        return fn

    return register


def _face(index: int, tint: tuple[int, int, int], size: tuple[int, int] = (40, 48)) -> Appearance:
    return Appearance(
        shape="ellipse", size=size, pattern="image", source=f"skimage:lfw_subset[{index}]",
        tint=tint,
    )  # fmt: skip


def _light(sigma_gain: float = 0.02, sigma_offset: float = 1.0) -> tuple[AR2, AR2]:
    """Slow illumination drift: log gain within ±0.25, offset within ±20 grey levels."""
    gain = AR2(boundary="reflect", a1=1.9, a2=-0.9, sigma=sigma_gain / 10, margin=0.25)
    offset = AR2(boundary="reflect", a1=1.9, a2=-0.9, sigma=sigma_offset / 10, margin=20.0)
    return gain, offset


@_realistic("faces-crossing")
def faces_crossing() -> SceneConfig:
    """Two faces cross in front of a café table three times (after the SHM paper's
    crossing hands and the DPS paper's real sequences): for SHM and DPS.

    320x240, 90 frames. The background is scikit-image's ``coffee`` photograph, cropped to
    cover a frame that a slow AR2 camera pans over (up to ±16 x ±8 px). The two faces are
    ``lfw_subset`` faces 12 and 41 (25x25 grey crops) drawn as 40x48 ellipses tinted
    warm and cool, oscillating horizontally in antiphase (x ≈ 160 ± 70 cos(2πt/60)) at
    slightly different heights, so they overlap at t ≈ 15, 45, 75; face A is in front at
    the first and last crossing, face B at the second. The light drifts (gain and offset
    AR2), moving faces blur over half a frame interval, sensor noise std 3, JPEG
    quality 85.

    Differs from the papers: real video of real people; here the faces are rigid
    photographs without pose change, and the camera shifts by whole pixels.
    """
    omega, r, amp = 2 * np.pi / 60, 0.999, 70.0
    a1, a2 = 2 * r * float(np.cos(omega)), -(r**2)
    v0 = amp * (1 - float(np.cos(omega)))

    def face(name, index, tint, x0, v, y0, depth):
        return EntitySpec(
            name=name, role="target", appearance=_face(index, tint), position=(x0, y0),
            motion=Motion(
                x=AR2(boundary="free", a1=a1, a2=a2, sigma=0.2, mean=160.0),
                y=AR2(boundary="reflect", a1=1.5, a2=-0.6, sigma=0.3, mean=y0, margin=4),
                velocity=(v, 0.0),
            ),
            depth=depth,
        )  # fmt: skip

    gain, offset = _light()
    return SceneConfig(
        name="faces-crossing",
        width=320,
        height=240,
        n_frames=90,
        background=Background(kind="image", source="skimage:coffee", fit="crop"),
        entities=(
            face("face-a", 12, (255, 215, 185), 160 + amp, v0, 112.0, ((0, 0), (30, 1), (60, 0))),
            face("face-b", 41, (200, 215, 255), 160 - amp, -v0, 128.0, ((0, 1), (30, 0), (60, 1))),
        ),  # fmt: skip
        sensor_noise=3.0,
        camera=Camera(
            extent=(16, 8),
            x=AR2(boundary="reflect", a1=1.8, a2=-0.8, sigma=0.15),
            y=AR2(boundary="reflect", a1=1.8, a2=-0.8, sigma=0.08),
        ),
        photometric=Photometric(gain=gain, offset=offset, motion_blur=0.5, jpeg_quality=85),
    )


_FOLIAGE = ((40, 70, 20), (90, 120, 40), (140, 110, 50), (60, 90, 60), (170, 120, 40))


@_realistic("tiger-like")
def tiger_like() -> SceneConfig:
    """A mottled, tiger-coloured target moves through textured foliage while the camera
    pans (after the KAMS paper's tiger sequence): for KAMS and mean shift.

    320x240, 120 frames. The background is scikit-image's ``grass`` texture tiled and
    tinted green, 64 px wider and 32 px taller than the frame on each side; the camera
    pans by AR2 (up to ±64 x ±32 px, velocity reversing at the limits). The target is a
    56x32 ellipse of Perlin-like value noise between black, orange and ochre (feature size
    5 px) moving by AR2 (σ = 2 px) inside the frame. 60 static clutter items (ellipses
    of value noise in foliage colours, some ochre like the target, 10-24 px) lie behind
    it, and two large grass-textured "leaves" in front occlude it when it passes. Motion
    blur over one frame interval (camera motion included: the target's image velocity),
    JPEG quality 80.

    Differs from the paper: the paper's tiger is real footage with non-rigid motion and
    self-occlusion; ours is a rigid textured blob and the camera shifts by whole pixels.
    """
    walk = _walk(2.0, margin=10.0)
    target = EntitySpec(
        name="tiger", role="target", position=(120.0, 130.0),
        appearance=Appearance(
            shape="ellipse", size=(56, 32), pattern="perlin", noise_scale=5.0,
            colors=((20, 10, 0), (235, 120, 15), (250, 190, 80)),
        ),
        motion=Motion(x=walk, y=walk, velocity=(2.0, -0.5)),
        depth=((0, 2),),
    )  # fmt: skip

    def leaf(name, pos, size, depth):
        return EntitySpec(
            name=name, role="occluder", position=pos, depth=((0, depth),),
            appearance=Appearance(
                shape="ellipse", size=size, pattern="image", source="skimage:grass",
                fit="tile", tint=(90, 160, 60),
            ),
        )  # fmt: skip

    clutter = ClutterSpec(
        count=60,
        appearance=Appearance(shape="ellipse", size=(24, 24), pattern="perlin", noise_scale=4.0),
        palette=_FOLIAGE,
        n_colors=2,
        min_size=10,
        region=(-64.0, -32.0, 448.0, 304.0),
    )
    return SceneConfig(
        name="tiger-like",
        width=320,
        height=240,
        n_frames=120,
        background=Background(
            kind="image", source="skimage:grass", fit="tile", color=(150, 190, 110)
        ),
        entities=(target, leaf("leaf-1", (200.0, 90.0), (44, 70), 0),
                  leaf("leaf-2", (90.0, 190.0), (70, 36), 1)),  # fmt: skip
        clutter=(clutter,),
        camera=Camera(
            extent=(64, 32),
            x=AR2(boundary="reflect", a1=1.9, a2=-0.9, sigma=0.3),
            y=AR2(boundary="reflect", a1=1.9, a2=-0.9, sigma=0.15),
            velocity=(1.5, 0.5),
        ),
        photometric=Photometric(motion_blur=1.0, jpeg_quality=80),
    )


_REAL_LOOKS = [
    Appearance(shape="ellipse", size=(30, 36), pattern="image", source="skimage:lfw_subset[12]",
               tint=(255, 210, 180)),
    Appearance(shape="rect", size=(30, 30), pattern="image", source="skimage:chelsea",
               crop=(120, 10, 200, 200)),
    Appearance(shape="ellipse", size=(30, 34), pattern="image", source="skimage:astronaut",
               crop=(150, 20, 150, 170)),
    Appearance(shape="rect", size=(30, 30), pattern="image", source="skimage:brick", fit="tile",
               tint=(230, 120, 90)),
    Appearance(shape="diamond", size=(32, 32), pattern="perlin", noise_scale=6.0,
               colors=((0, 60, 120), (0, 190, 190), (240, 250, 250))),
    Appearance(shape="rect", size=(30, 30), pattern="image", source="skimage:coffee",
               crop=(180, 40, 260, 260)),
    Appearance(shape="ellipse", size=(30, 30), pattern="image", source="skimage:rocket",
               crop=(260, 40, 140, 280)),
]  # fmt: skip


@_realistic("dps-synthetic-real")
def dps_synthetic_real() -> SceneConfig:
    """The DPS paper's synthetic scene (§3.2–3.3, preset ``dps-synthetic``) with real
    appearance: seven photographed or textured objects on gravel, a distractor that copies
    object 1, pulls away from it and vanishes; the camera drifts and the light changes.

    360x288, 25 frames, the same motion, starts, depths and distractor as
    ``dps-synthetic`` (AR2 σ = 3 px, damped; distractor at frames 3-8 drifting 8 px/frame
    to the right). Objects: a face (``lfw_subset[12]``, tinted), the cat (``chelsea``),
    the astronaut's face, tinted bricks, blue value noise, the coffee cup, the rocket.
    Background: scikit-image's ``gravel`` texture tiled. The camera pans (scripted: 12 px
    right and 6 px down over the sequence), the gain rises from 0.9 to 1.15, moving
    objects blur over half a frame interval, sensor noise std 4, JPEG quality 90.

    Differs from the paper: the paper's objects are synthetic colour patterns on noise; here
    they are photographs and textures with the same geometry, so colour histograms overlap
    far more between objects and with the background.
    """
    base = _PRESETS["dps-synthetic"]()
    looks = iter(_REAL_LOOKS)
    # The distractor copies object 1's face: an image has no colours to jitter.
    ents = [replace(e, color_jitter=0.0) if e.mimic is not None
            else replace(e, appearance=next(looks)) for e in base.entities]  # fmt: skip
    return replace(
        base,
        name="dps-synthetic-real",
        background=Background(kind="image", source="skimage:gravel", fit="tile"),
        entities=tuple(ents),
        sensor_noise=4.0,
        camera=Camera(extent=(12, 6), keyframes=((0, 0.0, 0.0), (24, 12.0, 6.0))),
        photometric=Photometric(
            keyframes=((0, 0.9, 0.0), (24, 1.15, 0.0)), motion_blur=0.5, jpeg_quality=90
        ),
    )
