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


def test_the_overview_names_the_software_once_or_per_experiment():
    # One line when every experiment was computed by the same installation; when they
    # differ (one rerun elsewhere, one from an older scenegen), which by which.
    from scenegen.lab.report import _overview

    def res(**who):
        return {"scenes": 1, "runs": 1, "quick": True, "claims": [],
                **({"written_by": who} if who else {})}  # fmt: skip

    same = "\n".join(_overview({"a": res(scenegen="0.1.0", numpy="2.4.6"),
                                "b": res(numpy="2.4.6", scenegen="0.1.0")}))  # fmt: skip
    assert "<p>Computed with scenegen 0.1.0, numpy 2.4.6.</p>" in same
    mixed = "\n".join(_overview({"a": res(scenegen="0.1.0", numpy="2.4.6"),
                                 "b": res(scenegen="0.1.0", numpy="1.26.4"), "c": res()}))
    assert ("<p>Computed with different software: a: scenegen 0.1.0, numpy 2.4.6; b: scenegen "
            "0.1.0, numpy 1.26.4; c: no versions recorded (an older scenegen).</p>") in mixed
    assert "Computed with" not in "\n".join(_overview({"a": res()}))
