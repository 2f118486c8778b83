"""Write the MOTChallenge inputs of the TrackEval oracle from scenegen's fixtures.

Run with the project's environment (it uses scenegen's own exporters)::

    .venv/bin/python tools/trackeval/make_inputs.py

It writes, under ``tests/data/trackeval/``:

* ``gt/<mode>/<fixture>/gt/gt.txt`` and ``seqinfo.ini`` for ``mode`` in ``amodal`` and
  ``visible`` (scenegen's MOT ground-truth export of the fixture, without the frames);
* ``trackers/<tracker>/<fixture>.txt``: the fixture's expected result of each of our
  trackers (``fixtures/expected/<fixture>/<tracker>.npy``) as a MOTChallenge tracker file,
  and a ``scrambled`` tracker made here from the ground truth with a fixed seed (noisy
  boxes, dropped frames, swapped and split identities, a false-positive track, and boxes
  on distractors and occluders) so that every score has something to count;
* ``trackers/tied/<fixture>.txt``: two boxes tied in IoU on every target and distractor,
  each frame's rows in a random order, so that the matchings' ties are broken by the
  file's row order (TrackEval's rule).

Then run ``tools/trackeval/make_oracle.py`` in TrackEval's side environment.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from scenegen.io import read
from scenegen.io.mot import gt_rows, write_mot_tracker

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "tests" / "data" / "trackeval"
FIXTURES = [
    "shm-crossing-small",
    "dps-occlusion-small",
    "full-occlusion",
    "enter-leave",
    "distractor-on-target",
    "kams-b-small",
]
MODES = ("amodal", "visible")


def scrambled(seq, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Tracks (T, H, 4) and ids (H,) that make FP, FN, IDSW, Frag and distractor matches."""
    t_n = seq.n_frames
    box = np.asarray(seq.gt.box, dtype=np.float64)
    present = np.asarray(seq.gt.present, dtype=bool)
    roles = np.asarray(seq.entities.role).astype(str)
    tracks, ids = [], []
    targets = [int(k) for k in np.flatnonzero(roles == "target")]
    for n, k in enumerate(targets):
        b = box[:, k].copy()
        size = np.nan_to_num((b[:, 2] + b[:, 3]) / 2)
        b[:, :2] += rng.normal(0.0, 0.12, (t_n, 2)) * size[:, None]
        b[:, 2:] *= np.exp(rng.normal(0.0, 0.1, (t_n, 2)))
        b[~present[:, k] | (rng.random(t_n) < 0.2)] = np.nan
        tracks.append(b)
        ids.append(10 + n)
    half = t_n // 2
    if len(tracks) >= 2:  # the first two tracks swap identities half way
        a, c = tracks[0].copy(), tracks[1].copy()
        tracks[0][half:], tracks[1][half:] = c[half:], a[half:]
    else:  # the only track changes identity half way (a switch and a fragment)
        late = np.full_like(tracks[0], np.nan)
        late[half:] = tracks[0][half:]
        tracks[0][half:] = np.nan
        tracks.append(late)
        ids.append(50)
    for n, k in enumerate(np.flatnonzero((roles == "distractor") | (roles == "occluder"))):
        b = box[:, k] + rng.normal(0.0, 0.5, (t_n, 4))
        b[~present[:, k]] = np.nan
        tracks.append(b)
        ids.append(70 + n)
    fp = np.full((t_n, 4), np.nan)
    on = rng.random(t_n) < 0.4
    fp[on, 0] = rng.uniform(0, seq.width - 10, on.sum())
    fp[on, 1] = rng.uniform(0, seq.height - 10, on.sum())
    fp[on, 2:] = rng.uniform(4, 20, (on.sum(), 2))
    tracks.append(fp)
    ids.append(99)
    return np.stack(tracks, axis=1), np.asarray(ids)


def tied(seq, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Tracks (T, H, 4) and ids (H,) whose boxes tie: every target and distractor gets two
    boxes shifted by the same amount left and right of its own (equal IoU with it), so
    which one a matching takes is decided by the order of a frame's rows in the file."""
    box = np.asarray(seq.gt.box, dtype=np.float64)
    present = np.asarray(seq.gt.present, dtype=bool)
    roles = np.asarray(seq.entities.role).astype(str)
    tracks, ids = [], []
    for n, k in enumerate(np.flatnonzero((roles == "target") | (roles == "distractor"))):
        for side, ident in ((-1.0, 200 + 2 * n), (1.0, 201 + 2 * n)):
            b = box[:, k].copy()
            b[:, 0] += side * np.maximum(1.0, np.round(0.1 * b[:, 2]))
            b[~present[:, k] | (rng.random(len(b)) < 0.1)] = np.nan
            tracks.append(b)
            ids.append(ident)
    return np.stack(tracks, axis=1), np.asarray(ids)


def shuffle_rows(path: Path, rng: np.random.Generator) -> None:
    """Rewrite a tracker file with each frame's rows in a random order (frames in order)."""
    frames: dict[int, list[str]] = {}
    for line in path.read_text().splitlines(keepends=True):
        frames.setdefault(int(line.split(",")[0]), []).append(line)
    path.write_text("".join(line for t in sorted(frames)
                            for line in rng.permutation(frames[t]).tolist()))  # fmt: skip


def main() -> None:
    shutil.rmtree(OUT / "gt", ignore_errors=True)
    shutil.rmtree(OUT / "trackers", ignore_errors=True)
    for i, name in enumerate(FIXTURES):
        seq = read(ROOT / "fixtures" / f"{name}.h5")
        for mode in MODES:
            folder = OUT / "gt" / mode / name
            (folder / "gt").mkdir(parents=True)
            rows = [r for t in range(seq.n_frames) for r in gt_rows(seq, t, mode)]
            (folder / "gt" / "gt.txt").write_text("".join(r + "\n" for r in rows))
            (folder / "seqinfo.ini").write_text(
                f"[Sequence]\nname={name}\nseqLength={seq.n_frames}\n"
                f"imWidth={seq.width}\nimHeight={seq.height}\n"
            )
        for npy in sorted((ROOT / "fixtures" / "expected" / name).glob("*.npy")):
            folder = OUT / "trackers" / npy.stem
            folder.mkdir(parents=True, exist_ok=True)
            write_mot_tracker(
                folder / f"{name}.txt",
                np.load(npy),
                seq.target_ids()[np.asarray(seq.gt.present)[0, seq.target_indices()]],
            )
        boxes, ids = scrambled(seq, np.random.default_rng(i))
        folder = OUT / "trackers" / "scrambled"
        folder.mkdir(parents=True, exist_ok=True)
        write_mot_tracker(folder / f"{name}.txt", boxes, ids)
        # Ties broken by the rows' order in the file (TrackEval keeps it).
        rng = np.random.default_rng(100 + i)
        boxes, ids = tied(seq, rng)
        folder = OUT / "trackers" / "tied"
        folder.mkdir(parents=True, exist_ok=True)
        write_mot_tracker(folder / f"{name}.txt", boxes, ids)
        shuffle_rows(folder / f"{name}.txt", rng)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
