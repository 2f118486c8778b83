"""A damaged experiment output gives one DataError line naming the file, not a traceback."""

from __future__ import annotations

import pytest

from scenegen.errors import DataError
from scenegen.lab.experiments import names
from scenegen.lab.report import build_report


@pytest.mark.parametrize("content", [b"{\"a\": 1", b"\xff\xfe\x00", b"[1, 2]"])
def test_damaged_results_json_is_one_data_error(tmp_path, content):
    folder = tmp_path / "experiments" / names()[0]
    folder.mkdir(parents=True)
    (folder / "results.json").write_bytes(content)
    with pytest.raises(DataError, match="results.json"):
        build_report(tmp_path)
