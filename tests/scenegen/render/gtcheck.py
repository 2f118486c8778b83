"""Independent re-derivation of a sequence's ground truth, used by the generator tests.

Everything here is plain numpy, written without the compiled compositor, so the tests
compare two implementations: the amodal masks of every entity are placed from the plan,
composited by depth rank, and every ground-truth array is recomputed from them. With a
camera, entities are placed at their scene position less the camera offset and the
reference background is the frame's window of the larger background.
"""

from __future__ import annotations

import numpy as np

from scenegen.render.draw import transform_template
from scenegen.render.plan import Scenario


def entity_template(scn: Scenario, t: int, k: int) -> np.ndarray:
    """The template entity ``k`` is drawn with at frame ``t``."""
    s, a, sh = scn.scale[t, k], scn.angle[t, k], scn.shade[t, k]
    varies = (
        np.any(scn.scale[:, k] != 1) or np.any(scn.angle[:, k] != 0) or np.any(scn.shade[:, k] != 1)
    )
    if not varies:
        return scn.templates[k]
    return transform_template(scn.templates[k], scale=float(s), angle=float(a), shade=float(sh))


def placed(scn: Scenario, t: int, k: int) -> tuple[np.ndarray, int, int]:
    tpl = entity_template(scn, t, k)
    th, tw = tpl.shape[:2]
    x0 = int(np.floor(scn.cx[t, k] - tw / 2 + 0.5)) - int(scn.cam_x[t])
    y0 = int(np.floor(scn.cy[t, k] - th / 2 + 0.5)) - int(scn.cam_y[t])
    return tpl, x0, y0


def reference_frame(scn: Scenario, t: int) -> tuple[np.ndarray, np.ndarray, dict[int, int]]:
    """Labels (H, W), colours (H, W, 3) and amodal pixel counts of frame ``t``."""
    h, w = scn.config.height, scn.config.width
    labels = np.zeros((h, w), dtype=np.uint16)
    if scn.zoomed:
        rgb = scn.background_frame(t)  # resampled: pixels only, no ground truth
    else:
        bh, bw = scn.background.shape[:2]
        ys, xs = (bh - h) // 2 + int(scn.view_y[t]), (bw - w) // 2 + int(scn.view_x[t])
        rgb = scn.background[ys : ys + h, xs : xs + w].copy()
    amodal: dict[int, int] = {}
    # Back to front by rank: nearer entities overwrite farther ones.
    for k in np.argsort(-scn.depth_rank[t].astype(np.int64), kind="stable"):
        if not scn.alive[t, k]:
            continue
        tpl, x0, y0 = placed(scn, t, k)
        mask = tpl[..., 3] > 0
        amodal[int(k)] = int(mask.sum())
        th, tw = mask.shape
        r0, r1, c0, c1 = max(0, y0), min(h, y0 + th), max(0, x0), min(w, x0 + tw)
        if r0 >= r1 or c0 >= c1:
            continue
        sub = mask[r0 - y0 : r1 - y0, c0 - x0 : c1 - x0]
        labels[r0:r1, c0:c1][sub] = k + 1
        rgb[r0:r1, c0:c1][sub] = tpl[r0 - y0 : r1 - y0, c0 - x0 : c1 - x0, :3][sub]
    return labels, rgb, amodal


def check_sequence(seq, scn: Scenario, *, pixels: bool = True) -> None:
    """Assert every ground-truth invariant (docs/format.md) of ``seq`` against ``scn``."""
    t_n, k_n = seq.gt.present.shape
    h, w = seq.height, seq.width
    for t in range(t_n):
        ref_labels, ref_rgb, amodal = reference_frame(scn, t)
        lab = np.asarray(seq.labels[t])
        # The pixel shows the nearest entity whose amodal mask covers it.
        np.testing.assert_array_equal(lab, ref_labels, err_msg=f"labels differ at frame {t}")
        if pixels and scn.config.sensor_noise == 0 and scn.config.photometric is None:
            np.testing.assert_array_equal(np.asarray(seq.frames[t]), ref_rgb, err_msg=f"frame {t}")
        counts = np.bincount(lab.ravel(), minlength=k_n + 1)
        for k in range(k_n):
            present = bool(seq.gt.present[t, k])
            box = seq.gt.box[t, k]
            if scn.alive[t, k]:
                tpl, x0, y0 = placed(scn, t, k)
                th, tw = tpl.shape[:2]
                # Present: one of its shape's pixels (alpha > 0) is inside the frame.
                part = tpl[max(0, -y0) : max(0, h - y0), max(0, -x0) : max(0, w - x0), 3]
                inside = bool(part.any())
            else:
                inside = False
            assert present == inside, (t, k)
            if not present:
                assert np.all(np.isnan(box)) and np.all(np.isnan(seq.gt.center[t, k]))
                assert np.all(np.isnan(seq.gt.path_center[t, k]))
                assert seq.gt.visibility[t, k] == 0
                assert np.all(np.isnan(seq.gt.visible_box[t, k]))
                continue
            np.testing.assert_array_equal(box, np.float32([x0, y0, tw, th]))
            np.testing.assert_allclose(seq.gt.center[t, k], [x0 + tw / 2, y0 + th / 2])
            # path_center: the planned centre before position noise, float32.
            np.testing.assert_array_equal(
                seq.gt.path_center[t, k],
                np.float32([scn.path_x[t, k] - scn.cam_x[t], scn.path_y[t, k] - scn.cam_y[t]]),
            )
            # visible_box is the box of the entity's pixels in labels.
            rows, cols = np.nonzero(lab == k + 1)
            if rows.size == 0:
                assert np.all(np.isnan(seq.gt.visible_box[t, k])), (t, k)
            else:
                expect = [
                    cols.min(),
                    rows.min(),
                    cols.max() + 1 - cols.min(),
                    rows.max() + 1 - rows.min(),
                ]
                np.testing.assert_array_equal(seq.gt.visible_box[t, k], np.float32(expect))
            # visibility = visible pixels / amodal pixels.
            np.testing.assert_allclose(
                seq.gt.visibility[t, k], counts[k + 1] / amodal[k], rtol=1e-6, err_msg=str((t, k))
            )
        # depth: a permutation of 0..K-1, 0 = nearest.
        assert sorted(seq.gt.depth[t].tolist()) == list(range(k_n))
