"""The compiled compositor and the ground truth made from it, on scenes that the drawn
configs of test_generator.py do not reach, checked against gtcheck.py's plain-numpy
compositing of the same plan.

The drawn entities are at most half the frame's side, so none crosses two opposite
edges: a scan that started one column or row before the frame (reading the last column
or row through a negative index) went unnoticed. Nor was an absent entity's 0/0.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from gtcheck import check_sequence

import scenegen
from scenegen.config import AR2, Appearance, EntitySpec, Motion, SceneConfig
from scenegen.render.plan import plan


@pytest.mark.parametrize("shape", ["rect", "ellipse"])
@pytest.mark.parametrize("moving", [False, True])
def test_entities_larger_than_the_frame(shape, moving):
    # Static entities are drawn once into the static layer and scanned there; moving
    # ones are drawn and scanned per frame: both scans see an entity crossing all four
    # edges, behind and in front of a smaller one.
    w, h = 40, 30
    motion = (
        Motion(x=AR2(boundary="free"), y=AR2(boundary="free"), velocity=(1.0, -1.0))
        if moving
        else None
    )
    big = EntitySpec(
        name="big", role="occluder", position=(20.0, 15.0), motion=motion, depth=((0, 5),),
        appearance=Appearance(shape=shape, size=(70, 52), pattern="stripes",
                              colors=((200, 30, 30), (30, 200, 30)), stripe_width=3),
    )  # fmt: skip
    small = EntitySpec(
        name="small", role="target", position=(8.0, 24.0), depth=((0, 1),),
        motion=Motion(x=AR2(boundary="free"), y=AR2(boundary="free"), velocity=(3.0, 0.0)),
        appearance=Appearance(shape="rect", size=(6, 5), pattern="solid",
                              colors=((10, 10, 250),)),
    )  # fmt: skip
    cfg = SceneConfig(width=w, height=h, n_frames=4, entities=(big, small), sensor_noise=0.0)
    seq = scenegen.generate(cfg, seed=3)
    scn = plan(cfg, 3)
    check_sequence(seq, scn)
    k = seq.entities.index_of("big")
    # The big entity covers every pixel the small one does not.
    lab = np.asarray(seq.labels)
    assert np.all((lab == k + 1) | (lab == seq.entities.index_of("small") + 1))
    if shape == "rect":
        np.testing.assert_array_equal(seq.gt.visible_box[:, k], np.float32([[0, 0, w, h]] * 4))


def test_absent_entities_raise_no_warning():
    # The visibility divides the visible count by the silhouette's pixels; an absent
    # entity (before it appears, after it disappears, outside the frame) has neither and
    # must not turn into a 0/0 RuntimeWarning on the user's console.
    free = Motion(x=AR2(boundary="free"), y=AR2(boundary="free"), velocity=(4.0, 0.0))
    walker = EntitySpec(
        name="walker", role="target", position=(5.0, 10.0), appear=1, disappear=3,
        motion=free, appearance=Appearance(shape="ellipse", size=(6, 6)),
    )  # fmt: skip
    leaver = EntitySpec(
        name="leaver", role="distractor", position=(13.0, 4.0), motion=free, depth=((0, 1),),
        appearance=Appearance(shape="rect", size=(6, 6)),
    )  # fmt: skip
    cfg = SceneConfig(width=20, height=20, n_frames=6, entities=(walker, leaver),
                      sensor_noise=0.0)  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        seq = scenegen.generate(cfg, seed=0)
    check_sequence(seq, plan(cfg, 0))
    assert seq.gt.present.tolist() == [[False, True], [True, True], [True, True],
                                       [False, False], [False, False], [False, False]]  # fmt: skip
