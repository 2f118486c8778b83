"""The README's YAML scenario example loads, validates and renders as written."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import yaml

import scenegen

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_yaml_example_generates():
    block = re.search(r"```yaml\n(.*?)```", README.read_text(), re.S)
    assert block is not None, "README.md has no yaml example"
    cfg = scenegen.from_dict(yaml.safe_load(block.group(1)))
    seq = scenegen.generate(cfg, seed=0)
    ball = seq.entities.index_of("ball")
    pillar = seq.entities.index_of("pillar")
    assert seq.n_frames == 50 and (seq.entities.role == "clutter").sum() == 30
    # The ball is in front of the pillar before frame 25 and behind it from frame 25 on.
    assert np.all(seq.gt.depth[:25, ball] < seq.gt.depth[:25, pillar])
    assert np.all(seq.gt.depth[25:, ball] > seq.gt.depth[25:, pillar])
