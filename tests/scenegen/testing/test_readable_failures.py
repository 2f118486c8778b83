"""A failing hypothesis example is short and says how to regenerate its scene."""

from __future__ import annotations

import re

import numpy as np
from hypothesis.vendor.pretty import pretty

import scenegen
from scenegen.cli import main
from scenegen.testing.fixtures import definitions

pytest_plugins = ["pytester"]


def test_configs_and_sequences_print_one_line():
    cfg = definitions()["distractor-on-target"].config
    assert repr(cfg) == (
        "SceneConfig(name='distractor-on-target', 80x60, 12 frames, entities: 1 target, "
        "1 distractor, clutter: 0, background: noise)"
    )
    seq = scenegen.generate(cfg, seed=1)
    # hypothesis prints examples with its pretty printer, not repr
    assert pretty(seq) == repr(seq) and pretty(cfg) == repr(cfg)


def test_failing_example_notes_the_yaml_and_a_regenerate_command(pytester, tmp_path):
    pytester.makepyfile(
        test_it="""
        from hypothesis import given, settings
        from scenegen.testing.strategies import scene_configs, sequences

        @settings(max_examples=30, database=None, derandomize=True)
        @given(sequences(scene_configs(max_frames=3)))
        def test_narrow(seq):
            assert seq.width < 45
        """
    )
    result = pytester.runpytest("-q", "-p", "no:cacheprovider")
    result.assert_outcomes(failed=1)
    out = result.stdout.str()
    assert "scene config (YAML, saved as " in out and "width: 45" in out
    cmd = re.search(r"regenerate: scenegen generate --config (\S+) --seed (\d+) -o scene.h5", out)
    assert cmd is not None, out
    shown = re.search(r"seq = (Sequence\(.*\))", out)
    assert shown is not None and shown.group(1).endswith("entities=1)")
    # The command gives the failing scene back.
    path = tmp_path / "scene.h5"
    assert (
        main(["generate", "--config", cmd.group(1), "--seed", cmd.group(2), "-o", str(path)]) == 0
    )
    seq = scenegen.read(path)
    assert repr(seq) == shown.group(1) and np.asarray(seq.frames).shape[2] == 45
