"""Built-in fixtures ship with the package: regenerated on first use, checked, cached."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from scenegen.errors import DataError
from scenegen.io import read
from scenegen.testing import builtin
from scenegen.testing.fixtures import definitions

pytest_plugins = ["pytester"]
REPO_FIXTURES = Path(__file__).resolve().parents[3] / "fixtures"


def test_shipped_digests_are_the_registrys():
    reg = json.loads((REPO_FIXTURES / "registry.json").read_text())["fixtures"]
    shipped = builtin.shipped_digests()
    assert list(shipped) == list(definitions()) == list(reg), (
        "run `scenegen fixtures regen` (it rewrites scenegen/testing/builtin_digests.json)"
    )
    for name, entry in reg.items():
        assert shipped[name] == {"seed": entry["seed"], "digests": entry["digests"]}, name


def test_builtin_fixture_regenerates_checks_and_caches(tmp_path):
    seq = builtin.builtin_fixture("one-pixel", cache=tmp_path)
    committed = read(REPO_FIXTURES / "one-pixel.h5")
    np.testing.assert_array_equal(np.asarray(seq.frames), np.asarray(committed.frames))
    np.testing.assert_array_equal(seq.gt.box, committed.gt.box)
    assert (tmp_path / "one-pixel.h5").exists()
    # A damaged cache entry is regenerated.
    (tmp_path / "one-pixel.h5").write_bytes(b"not hdf5")
    again = builtin.builtin_fixture("one-pixel", cache=tmp_path)
    assert again.n_frames == 8 and read(tmp_path / "one-pixel.h5").n_frames == 8


def test_wrong_digests_are_named(tmp_path, monkeypatch):
    real = builtin.shipped_digests()
    real["single-frame"]["digests"]["frames"] = "0" * 64
    monkeypatch.setattr(builtin, "shipped_digests", lambda: real)
    with pytest.raises(DataError, match="'single-frame': regenerating it gives different frames"):
        builtin.builtin_fixture("single-frame", cache=tmp_path)
    with pytest.raises(KeyError, match="known: dps-synthetic-small"):
        builtin.builtin_fixture("nope", cache=tmp_path)


def test_cache_dir_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("SCENEGEN_CACHE", str(tmp_path))
    assert builtin.cache_dir() == tmp_path / "fixtures"
    monkeypatch.delenv("SCENEGEN_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "x"))
    assert builtin.cache_dir() == tmp_path / "x" / "scenegen" / "fixtures"


def test_plugin_serves_builtin_fixtures_without_a_fixtures_folder(pytester):
    pytester.makepyfile(
        test_user="""
        import pytest

        def test_edge(scenegen_fixture):
            seq = scenegen_fixture("one-pixel")
            assert seq.frames.shape == (8, 48, 64, 3) and not seq.frames.flags.writeable

        def test_unknown(scenegen_fixture):
            with pytest.raises(FileNotFoundError, match="known: .*one-pixel"):
                scenegen_fixture("missing")
        """
    )
    pytester.runpytest("-q").assert_outcomes(passed=2)
