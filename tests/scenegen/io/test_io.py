"""HDF5 round trips, lazy reading and result files (the layout of docs/format.md)."""

from __future__ import annotations

import dataclasses
import re

import h5py
import numpy as np
import pytest

import scenegen
from scenegen.errors import DataError
from scenegen.io import LazyArray, TrackerResult, read, read_result, write, write_result
from scenegen.io.integrity import as_text, attrs_digest, put_attrs_digest, put_text
from scenegen.io.validate import check_file


@pytest.fixture(scope="module")
def seq():
    return scenegen.generate("shm-crossing", seed=3, frames=12)


@pytest.mark.parametrize("compression", ["gzip", "lzf", "none"])
def test_round_trip(tmp_path, seq, compression):
    path = tmp_path / "s.h5"
    write(path, seq, compression=compression)
    back = read(path)
    assert isinstance(back.frames, LazyArray)
    np.testing.assert_array_equal(np.asarray(back.frames), seq.frames)
    np.testing.assert_array_equal(np.asarray(back.labels), seq.labels)
    for key, arr in seq.gt.as_dict().items():
        np.testing.assert_array_equal(getattr(back.gt, key), arr)
    assert back.config == seq.config and back.seed == 3 and back.preset == "shm-crossing"
    np.testing.assert_array_equal(back.entities.role, seq.entities.role)
    for eid, tpl in seq.templates.items():
        np.testing.assert_array_equal(back.templates[eid], tpl)
    assert check_file(path) == []


def test_layout_matches_contract(tmp_path, seq):
    path = tmp_path / "s.h5"
    write(path, seq)
    with h5py.File(path) as f:
        assert as_text(f.attrs["schema"]) == "scenegen/1" and f.attrs["generator_version"]
        g = f["sequences/shm-crossing"]
        for attr in ("seed", "config", "preset", "n_frames", "height", "width"):
            assert attr in g.attrs
        t, h, w, k = 12, 288, 360, len(seq.entities)
        expect = {
            "frames": ((t, h, w, 3), np.uint8), "labels": ((t, h, w), np.uint16),
            "entities/id": ((k,), np.int32), "gt/box": ((t, k, 4), np.float32),
            "gt/visible_box": ((t, k, 4), np.float32), "gt/center": ((t, k, 2), np.float32),
            "gt/visibility": ((t, k), np.float32), "gt/present": ((t, k), np.bool_),
            "gt/depth": ((t, k), np.int16), "gt/path_center": ((t, k, 2), np.float32),
        }  # fmt: skip
        for key, (shape, dtype) in expect.items():
            assert g[key].shape == shape and g[key].dtype == dtype, key
        assert g["frames"].chunks == (1, h, w, 3) and g["labels"].chunks == (1, h, w)
        assert g["entities/role"][0].decode() == "target"
        assert g["templates/1"].dtype == np.uint8 and g["templates/1"].shape[2] == 4


def test_lazy_read_of_a_range(tmp_path, seq):
    path = tmp_path / "s.h5"
    write(path, seq)
    back = read(path)
    np.testing.assert_array_equal(back.frames[4:7], seq.frames[4:7])
    assert back.frames.shape == seq.frames.shape and len(back.frames) == 12


@pytest.mark.parametrize("name", ["no/such/dataset", "sequences/shm-crossing", ""])
def test_lazy_array_of_a_missing_dataset_is_a_data_error(tmp_path, seq, name):
    # Was h5py's raw KeyError (missing) or an AttributeError (a group has no shape).
    path = tmp_path / "s.h5"
    write(path, seq)
    with pytest.raises(DataError, match=f"holds no dataset {re.escape(repr(name))}"):
        LazyArray(path, name)


@pytest.mark.parametrize("key", [
    np.s_[::-1], np.s_[9:2:-3], [0, 3, 3], [5, 1], [-1, 0], [], np.s_[::-2, 5:9],
    ([4, 2], slice(None), 7), np.array([[0, 1], [1, 0]]), np.arange(12) % 3 == 0,
    np.s_[2:8:2], [1, 4, 6], 5, -2, np.s_[..., 0],
])  # fmt: skip
def test_lazy_arrays_index_as_numpy_arrays_do(tmp_path, seq, key):
    # A reversed slice or a list out of order was h5py's ValueError / TypeError.
    path = tmp_path / "s.h5"
    write(path, seq)
    back = read(path)
    for lazy, mem in ((back.frames, seq.frames), (back.labels, seq.labels)):
        np.testing.assert_array_equal(lazy[key], np.asarray(mem)[key])


def test_several_sequences_need_a_name(tmp_path, seq):
    other = scenegen.generate("kams-a", seed=0, frames=3)
    path = tmp_path / "two.h5"
    write(path, seq, other)
    with pytest.raises(DataError, match="holds 2 sequences; name one of"):
        read(path)
    assert read(path, "kams-a").n_frames == 3
    with pytest.raises(DataError, match="no sequence 'zzz'"):
        read(path, "zzz")


def test_not_hdf5_and_other_schema(tmp_path):
    junk = tmp_path / "junk.h5"
    junk.write_bytes(b"hello")
    with pytest.raises(DataError, match="not an HDF5 file"):
        read(junk)
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f.attrs["schema"] = "somebody/2"
    with pytest.raises(DataError, match="schema is 'somebody/2', expected 'scenegen/1'"):
        read(other)


def test_result_round_trip(tmp_path):
    res = TrackerResult(
        tracker="shm", params={"n": 3}, seed=7, sequence="x",
        target_ids=np.array([1, 2], np.int32), boxes=np.ones((4, 2, 4), np.float32),
        orderings=np.array([[0, 1], [1, 0]], np.int16), order_prob=np.full((4, 2), 0.5, np.float32),
    )  # fmt: skip
    path = tmp_path / "r.h5"
    write_result(path, res)
    back = read_result(path)
    assert back.tracker == "shm" and back.params == {"n": 3} and back.seed == 7
    np.testing.assert_array_equal(back.orderings, res.orderings)
    with h5py.File(path) as f:
        g = f["results/shm"]
        assert g["boxes"].dtype == np.float32 and g["orderings"].dtype == np.int16
        assert g["order_prob"].shape == (4, 2)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"tracker": "a/b"}, "tracker: must not contain '/', got 'a/b'"),  # nested groups
        ({"tracker": ""}, "tracker: must not be empty"),  # h5py's ValueError
        ({"tracker": 3}, "tracker must be a string, got 3"),  # h5py's TypeError
        ({"seed": 2**64}, "seed must be an integer in [0, 2**64 - 1], got 18446744073709551616"),
        ({"seed": "7"}, "seed must be an integer in [0, 2**64 - 1], got '7'"),
        ({"target_ids": np.array([1, 2**32 + 2])}, "target_ids must be integers within int32, "
                                                   "got 4294967298"),  # stored as 2
        ({"target_ids": np.array([1, 2.5])}, "target_ids must be integers within int32, "
                                             "got 2.5"),  # stored as 2
        ({"boxes": np.full((4, 2, 4), 1e39)}, "boxes has values beyond float32's range"),
    ],
)
def test_write_result_refuses_what_it_cannot_store(tmp_path, change, message):
    """A result whose tracker name, seed, ids or boxes cannot be stored as given is refused
    with one line naming the value: it was a raw h5py/numpy error, or stored changed (a
    tracker 'a/b' as nested groups, read back as damaged; ids cast to int32)."""
    res = TrackerResult(
        tracker="shm", params={}, seed=7, sequence="x",
        target_ids=np.array([1, 2], np.int32), boxes=np.ones((4, 2, 4), np.float32),
    )  # fmt: skip
    path = tmp_path / "r.h5"
    with pytest.raises(scenegen.ConfigError, match=re.escape(message)):
        write_result(path, dataclasses.replace(res, **change))
    assert not path.exists()
    with pytest.raises(scenegen.ConfigError,
                       match="^write_result takes TrackerResult objects, got a str$"):
        write_result(path, "shm")
    write_result(path, dataclasses.replace(res, seed=2**64 - 1, target_ids=np.array([1.0, 2.0])))
    assert read_result(path).seed == 2**64 - 1


def test_write_refuses_what_is_not_a_sequence(tmp_path, seq):
    # write(path, [seq]) and write(path, "kams-a") were AttributeErrors from inside write.
    for bad, kind in (([seq], "list"), ("kams-a", "str"), (None, "NoneType")):
        with pytest.raises(scenegen.ConfigError,
                           match=f"^write takes Sequence objects, got a {kind}$"):
            write(tmp_path / "s.h5", seq, bad)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("value", ["", "plain", "é ∑ 漢字", "x" * 5000])
def test_put_text_is_the_attribute_h5py_makes_and_replaces(tmp_path, value):
    """put_text's low-level path stores what ``attrs.create`` with the fixed-length UTF-8
    dtype stores (type, value, read-back), replaces an existing attribute, and the
    attributes' digest computed from the texts equals the one read back."""
    raw = value.encode("utf-8")
    with h5py.File(tmp_path / "a.h5", "w") as f:
        ref = f.create_dataset("ref", data=np.zeros(2))
        ours = f.create_dataset("ours", data=np.zeros(2))
        ref.attrs.create("k", np.bytes_(raw), dtype=h5py.string_dtype("utf-8", max(1, len(raw))))
        put_text(ours, "k", "old value, replaced")
        put_text(ours, "k", value)
        assert list(ours.attrs) == ["k"]
        assert ours.attrs.get_id("k").get_type() == ref.attrs.get_id("k").get_type()
        assert as_text(ours.attrs["k"]) == value
        assert repr(ours.attrs["k"]) == repr(ref.attrs["k"])
        put_attrs_digest(ours, {"k": value})
        assert as_text(ours.attrs["attrs_sha256"]) == attrs_digest(ref.attrs)


def test_validate_names_infinite_or_off_frame_ground_truth_where_present(tmp_path, seq):
    # A sequence written through the API is sealed with its digests: only the ground-truth
    # checks can tell. Before, an infinite path centre, or an infinite or far-away box of a
    # fully occluded entity (no visible box to compare with), was called valid.
    import dataclasses

    gt = seq.gt
    k = int(np.flatnonzero(gt.present[3])[0])
    box, center = np.array(gt.box), np.array(gt.center)
    path, vbox = np.array(gt.path_center), np.array(gt.visible_box)
    vis = np.array(gt.visibility)
    path[3, k, 1] = np.inf
    box[4, k, :2] = 1e30
    center[4, k] = box[4, k, :2] + box[4, k, 2:] / 2
    box[5, k, 0] = center[5, k, 0] = np.inf
    vbox[4:6, k], vis[4:6, k] = np.nan, 0.0
    bad_gt = dataclasses.replace(
        gt, box=box, center=center, path_center=path, visible_box=vbox, visibility=vis
    )
    bad = dataclasses.replace(seq, gt=bad_gt)
    write(tmp_path / "bad.h5", bad)
    problems = "\n".join(check_file(tmp_path / "bad.h5", check_pixels=False))
    assert "gt/path_center is infinite where present at frames 3" in problems
    assert "gt/box is infinite where present at frames 5" in problems
    assert "gt/center is infinite where present at frames 5" in problems
    assert "gt/box lies outside the frame where present at frames 4" in problems


@pytest.mark.parametrize("value", [1.5, -0.25, np.nan, np.inf])
def test_order_prob_must_hold_probabilities(tmp_path, value):
    """A result whose ``order_prob`` is not in [0, 1] is refused when written, and a file
    holding one (its digest resealed, as another writer would) is not valid."""
    from scenegen.io import integrity

    prob = np.full((4, 2), 0.5, np.float32)
    res = TrackerResult(
        tracker="shm", params={}, seed=0, sequence="x",
        target_ids=np.array([1, 2], np.int32), boxes=np.ones((4, 2, 4), np.float32),
        orderings=np.array([[0, 1], [1, 0]], np.int16), order_prob=prob,
    )  # fmt: skip
    path = tmp_path / "r.h5"
    write_result(path, res)
    assert check_file(path) == []
    bad = prob.copy()
    bad[2, 1] = value
    problem = "order_prob holds values that are not probabilities in [0, 1] (first at frame 2: "
    assert any(p.startswith(problem) for p in dataclasses.replace(res, order_prob=bad).problems())
    with h5py.File(path, "r+") as f:
        ds = f["results/shm/order_prob"]
        ds[...] = bad
        integrity.put_text(ds, integrity.DIGEST, integrity.digest(ds[()]))
    assert any(problem in line for line in check_file(path)), check_file(path)
