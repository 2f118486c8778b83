"""The layout is defined once (scenegen.io.schema): files, reader, validator and docs agree."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

import scenegen
from scenegen.io import TrackerResult, read, write, write_result
from scenegen.io.integrity import as_text, strip
from scenegen.io.schema import (
    RESULT_FIELDS,
    ROLES,
    SEQUENCE_FIELDS,
    field,
    render_markdown,
)
from scenegen.io.validate import check_file

DOC = Path(__file__).resolve().parents[3] / "docs" / "format.md"


@pytest.fixture(scope="module")
def seq():
    return scenegen.generate("dps-occlusion", seed=2, frames=6)


def _datasets(group: h5py.Group) -> dict[str, h5py.Dataset]:
    out: dict[str, h5py.Dataset] = {}
    group.visititems(
        lambda name, obj: out.update({name: obj}) if isinstance(obj, h5py.Dataset) else None
    )
    return out


def test_every_dataset_has_the_schema_description_and_units(tmp_path, seq):
    path = tmp_path / "s.h5"
    write(path, seq)
    with h5py.File(path) as f:
        assert as_text(f.attrs["conventions"]).count("\n") >= 3
        g = f[f"sequences/{seq.name}"]
        t, h, w, k = seq.n_frames, seq.height, seq.width, len(seq.entities)
        found = _datasets(g)
        assert len(found) == len(SEQUENCE_FIELDS) - 1 + k  # one template per entity
        for name, ds in found.items():
            f_ = field("templates/<id>" if name.startswith("templates/") else name)
            assert as_text(ds.attrs["description"]) == f_.description
            assert as_text(ds.attrs["units"]) == f_.units
            assert ds.dtype.kind in "OS" if f_.dtype == "string" else ds.dtype == f_.dtype
            if "<" not in f_.path:
                assert ds.shape == f_.shape_for(T=t, H=h, W=w, K=k), name


def test_result_datasets_have_description_and_units(tmp_path):
    res = TrackerResult(
        tracker="shm", params={}, seed=0, sequence="x",
        target_ids=np.array([1, 2], np.int32), boxes=np.zeros((3, 2, 4), np.float32),
        orderings=np.array([[0, 1]], np.int16), order_prob=np.ones((3, 1), np.float32),
    )  # fmt: skip
    write_result(tmp_path / "r.h5", res)
    with h5py.File(tmp_path / "r.h5") as f:
        found = _datasets(f["results/shm"])
        assert sorted(found) == sorted(r.path for r in RESULT_FIELDS)
        for name, ds in found.items():
            assert as_text(ds.attrs["units"]) == field(f"results/{name}").units


def test_file_without_path_center_or_attrs_reads_as_nan_and_validates(tmp_path, seq):
    path = tmp_path / "old.h5"
    write(path, seq)
    with h5py.File(path, "r+") as f:  # what files written before the field looked like
        strip(f)  # nor digests
        g = f[f"sequences/{seq.name}"]
        del g["gt/path_center"]
        del f.attrs["conventions"]
        for ds in _datasets(g).values():
            del ds.attrs["description"], ds.attrs["units"]
    back = read(path)
    assert back.gt.path_center.shape == seq.gt.center.shape
    assert back.gt.path_center.dtype == np.float32 and np.isnan(back.gt.path_center).all()
    np.testing.assert_array_equal(back.gt.box, seq.gt.box)
    assert check_file(path) == []


def test_validate_checks_path_center(tmp_path, seq):
    path = tmp_path / "bad.h5"
    write(path, seq)
    with h5py.File(path, "r+") as f:
        ds = f[f"sequences/{seq.name}/gt/path_center"]
        ds[0, 0] = np.nan
    assert any("gt/path_center NaN pattern" in line for line in check_file(path))
    with h5py.File(path, "r+") as f:
        g = f[f"sequences/{seq.name}/gt"]
        del g["path_center"]
        g.create_dataset("path_center", data=np.zeros((2, 2), np.float64))
    problems = check_file(path)
    assert any("gt/path_center has shape (2, 2), expected" in line for line in problems)
    assert any("gt/path_center has dtype float64, expected float32" in line for line in problems)


def test_roles_are_the_config_roles():
    assert ROLES == ("target", "distractor", "occluder", "clutter")


def test_docs_format_is_rendered_from_the_schema():
    assert DOC.read_text(encoding="utf-8") == render_markdown(), (
        "docs/format.md is out of date: run "
        "python -c 'from scenegen.io.schema import render_markdown as r; "
        'open("docs/format.md", "w").write(r())\''
    )


def test_docs_format_h5py_example_runs(tmp_path, seq, capsys):
    import re

    path = tmp_path / "scene.h5"
    write(path, seq)
    code = re.search(r"```python\n(.*?)```", render_markdown(), re.S)
    assert code is not None
    exec(code[1].replace('"scene.h5"', repr(str(path))), {})  # noqa: S102
    assert "Amodal box" in capsys.readouterr().out


def test_streamed_writer_uses_the_schema_too(tmp_path):
    from scenegen.io import write_scenario
    from scenegen.render.plan import plan
    from scenegen.testing.fixtures import definitions

    d = definitions()["distractor-on-target"]
    scn = plan(d.config, d.seed)
    write_scenario(tmp_path / "s.h5", scn, chunk=5)
    with h5py.File(tmp_path / "s.h5") as f:
        found = _datasets(f[f"sequences/{d.config.name}"])
        assert all("description" in ds.attrs and "units" in ds.attrs for ds in found.values())
    back = read(tmp_path / "s.h5")
    whole = scenegen.generate(d.config, seed=d.seed)
    np.testing.assert_array_equal(back.gt.path_center, whole.gt.path_center)


def test_ground_truth_docstring_lists_the_layout_s_gt_fields():
    """GroundTruth documents exactly the schema's gt/* datasets, with their dtype and shape."""
    import re

    from scenegen.sequence import GroundTruth

    doc = GroundTruth.__doc__ or ""
    lines = re.findall(r"^    (\w+) : ndarray of shape (\([^)]*\)), (\w+)$", doc, re.M)
    listed = {name for name, _, _ in lines}
    want = {}
    for f in SEQUENCE_FIELDS:
        if f.path.startswith("gt/"):
            shape = "(" + ", ".join(str(d) for d in f.shape) + ")"
            want[f.path[3:]] = shape
            assert f"``{f.path}``" in doc
    assert listed == set(want)
    for name, shape, dtype in lines:
        assert shape == want[name] and dtype == field(f"gt/{name}").dtype
