"""Previews: tracker boxes far off the image are drawn clipped, not an internal error."""

from __future__ import annotations

import numpy as np
import pytest

import scenegen
from scenegen.cli import main
from scenegen.io import TrackerResult, write_result
from scenegen.io.preview import annotate


@pytest.fixture(scope="module")
def seq():
    return scenegen.generate("shm-crossing", seed=2, frames=2)


def test_boxes_beyond_int32_are_drawn_as_clipped(seq):
    # cv2.rectangle takes C ints: 1e30 or 3e9 was "error: (-5:Bad argument)".
    far = np.array([[10, 12, 1e30, 1e30], [-1e30, -1e30, 1e29, 1e29], [3e9, 5, 4, 4],
                    [-3e9, 20, 3e9 + 40, 1e38]])  # fmt: skip
    near = np.array([[10, 12, 5000, 5000], [-5000, -5000, 10, 10], [5000, 5, 4, 4],
                     [-5000, 20, 5040, 5000]])  # fmt: skip
    drawn = annotate(seq, 1, boxes=far)
    np.testing.assert_array_equal(drawn, annotate(seq, 1, boxes=near))
    assert not np.array_equal(drawn, annotate(seq, 1))  # the edges on the image are drawn


def test_preview_of_a_result_with_huge_boxes(seq, tmp_path, capsys):
    scenegen.write(tmp_path / "s.h5", seq)
    targets = seq.initial_targets(0)
    boxes = seq.gt.box[:, targets].astype(np.float32)
    boxes[1, 0] = [1e30, -3e38, 3e38, 3e38]
    res = TrackerResult(tracker="x", params={}, seed=0, sequence=seq.name,
                        target_ids=seq.entities.id[targets], boxes=boxes)  # fmt: skip
    write_result(tmp_path / "r.h5", res)
    code = main(["preview", str(tmp_path / "s.h5"), "--result", str(tmp_path / "r.h5"),
                 "-o", str(tmp_path / "p.png")])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / "p.png").stat().st_size > 0
