"""Verbs on sequences and files: presets, generate, inspect, validate, preview, export."""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path
from typing import Any

from scenegen import presets
from scenegen.cli.options import picked_by, seed_arg
from scenegen.cli.progress import bar
from scenegen.errors import ConfigError, DataError

__all__ = ["register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("presets", help="list the presets")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.set_defaults(func=cmd_presets)

    p = sub.add_parser("generate", help="generate a sequence into an HDF5 file")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--preset", help="preset name (see `scenegen presets`)")
    src.add_argument("--config", type=Path, help="scenario config, .yaml or .json")
    p.add_argument("--seed", type=seed_arg, default=None, help="random seed (default: fresh)")
    p.add_argument("-o", "--output", type=Path, required=True, help="output .h5 file")
    p.add_argument("--frames", type=int, default=None, help="override the frame count")
    p.add_argument("--compression", default="gzip", help="gzip | lzf | none (default gzip)")
    p.set_defaults(func=cmd_generate)

    p = sub.add_parser("inspect", help="summarise a scenegen file")
    p.add_argument("file", type=Path)
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.set_defaults(func=cmd_inspect)

    p = sub.add_parser(
        "validate", help="check a scenegen file, dataset, experiment, report or benchmark "
        "folder; exit 1 on any problem",
    )  # fmt: skip
    p.add_argument("file", type=Path)
    p.add_argument(
        "--deep", action="store_true",
        help="also re-render each sequence from its config and seed and compare (an "
        "experiment or benchmark folder: run every run again and compare with its record)",
    )  # fmt: skip
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser("preview", help="PNG contact sheet, GIF or MP4 with ground truth drawn")
    p.add_argument("file", type=Path)
    p.add_argument("-o", "--output", type=Path, required=True, help=".png, .gif or .mp4")
    p.add_argument("--result", type=Path, default=None, help="tracker result file to overlay")
    p.add_argument("--sequence", default=None, help="sequence name if the file holds several")
    p.set_defaults(func=cmd_preview)

    p = sub.add_parser(
        "export",
        help="export a sequence (mot, otb, got10k, vot) or a result (mot tracker file)",
    )
    p.add_argument("file", type=Path, help="scenegen .h5 file, or a result .h5 file")
    p.add_argument(
        "--format", required=True, choices=["mot", "otb", "got10k", "vot"], help="output format"
    )
    p.add_argument(
        "-o", "--output", type=Path, required=True,
        help="output folder (a .txt file for a result exported to MOT)",
    )  # fmt: skip
    p.add_argument("--sequence", default=None, help="sequence name if the file holds several")
    p.add_argument("--tracker", default=None, help="tracker name if the result holds several")
    p.add_argument(
        "--image-format", choices=["png", "jpg"], default=None,
        help="frame files (default: png for mot and vot, jpg for otb and got10k)",
    )  # fmt: skip
    p.add_argument(
        "--gt-mode", choices=["amodal", "visible"], default=None,
        help="mot: amodal boxes in every frame (default) or MOTChallenge's visible convention",
    )  # fmt: skip
    p.add_argument(
        "--visibility-threshold", type=float, default=None,
        help="visible mode: rows with visibility at most this get conf 0 (default 0)",
    )  # fmt: skip
    p.set_defaults(func=cmd_export)


def _refuse_unused_options(args: argparse.Namespace, result: bool) -> None:
    """An export option that the chosen export would ignore is refused (exit 2)."""
    what = "a tracker result's export (a MOT tracker file)" if result else f"--format {args.format}"
    unused = ["--image-format"] if result and args.image_format is not None else []
    if result or args.format != "mot":
        unused += [o for o, v in (("--gt-mode", args.gt_mode),
                                  ("--visibility-threshold", args.visibility_threshold))
                   if v is not None]  # fmt: skip
    if unused:
        raise ConfigError(f"{unused[0]} does not apply to {what}; leave it out")


def cmd_presets(args: argparse.Namespace) -> int:
    rows = []
    for name in presets.all_names():
        cfg = presets.get(name)
        rows.append(
            {
                "name": name,
                "width": cfg.width,
                "height": cfg.height,
                "n_frames": cfg.n_frames,
                "entities": len(cfg.entities) + sum(c.count for c in cfg.clutter),
                "description": presets.describe(name),
            }
        )
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    wide = max((len(r["name"]) for r in rows), default=14)
    for r in rows:
        size = f"{r['width']}x{r['height']}x{r['n_frames']}"
        print(f"{r['name']:<{wide}} {size:<12} {r['entities']:>4} entities  {r['description']}")
    return 0


def load_source(preset: str | None, config: Path | None) -> tuple[Any, str]:
    from scenegen.config import load_config

    if preset is not None:
        return presets.get(preset), preset
    assert config is not None
    return load_config(config), ""


def cmd_generate(args: argparse.Namespace) -> int:
    from scenegen.io import COMPRESSIONS, write_scenario
    from scenegen.io.mot import writable
    from scenegen.render.plan import plan

    if args.compression not in COMPRESSIONS:
        raise ConfigError(
            f"--compression must be one of {', '.join(COMPRESSIONS)}; got {args.compression!r}"
        )
    cfg, preset = load_source(args.preset, args.config)
    if args.frames is not None:
        if args.frames < 1:
            raise ConfigError(f"--frames must be >= 1, got {args.frames}")
        cfg = replace(cfg, n_frames=args.frames)
    try:  # a config that parses may still fail when planned (a runaway path, an image)
        scn = plan(cfg, args.seed, preset=preset)
    except ConfigError as err:
        if args.config is None:
            raise
        raise ConfigError(f"{args.config}: {err}") from None
    # A full disk or a read-only folder: one line naming the output, exit 2.
    with bar(cfg.n_frames, f"generate {cfg.name}", unit="frame") as pb, writable(args.output):
        write_scenario(
            args.output, scn, compression=args.compression, progress=lambda n: pb.update(n - pb.n)
        )
    print(f"wrote {args.output} ({cfg.n_frames} frames, seed {scn.seed})")
    return 0


_DAMAGE = (KeyError, OSError, RuntimeError, TypeError, ValueError)


def _inspect(path: str) -> dict[str, Any]:
    """Summary of a file; runs in a guarded child (``cmd_inspect``)."""
    from scenegen.io import open_checked
    from scenegen.io.integrity import as_text

    out: dict[str, Any] = {"file": path}
    with open_checked(path) as f:
        try:
            out["schema"] = as_text(f.attrs["schema"])
            out["generator_version"] = as_text(f.attrs.get("generator_version", ""))
        except _DAMAGE as err:
            raise DataError(f"{path}: damaged file attributes: {_first_line(err)}") from None
        out["sequences"] = []
        for name in _keys(path, f, "sequences"):
            try:
                g = f[f"sequences/{name}"]
                roles = [
                    r.decode() if isinstance(r, bytes) else str(r) for r in g["entities/role"][()]
                ]
                frames = g["frames"]
                out["sequences"].append(
                    {
                        "name": name,
                        "preset": as_text(g.attrs["preset"]),
                        "seed": int(g.attrs["seed"]),
                        "n_frames": int(g.attrs["n_frames"]),
                        "height": int(g.attrs["height"]),
                        "width": int(g.attrs["width"]),
                        "entities": {r: roles.count(r) for r in sorted(set(roles))},
                        "compression": frames.compression or "none",
                        "chunks": list(frames.chunks or ()),
                    }
                )
            except _DAMAGE as err:
                raise DataError(
                    f"{path}: sequence {name!r} is damaged: {_first_line(err)}"
                ) from None
        out["results"] = []
        for name in _keys(path, f, "results"):
            try:
                g = f[f"results/{name}"]
                out["results"].append(
                    {"tracker": name, "sequence": as_text(g.attrs.get("sequence", "")),
                     "shape": list(g["boxes"].shape) if "boxes" in g else None}
                )  # fmt: skip
            except _DAMAGE as err:
                raise DataError(f"{path}: result {name!r} is damaged: {_first_line(err)}") from None
    return out


def _keys(path: str, f: Any, group: str) -> list[str]:
    try:
        return list(f[group].keys()) if group in f else []
    except _DAMAGE as err:
        raise DataError(f"{path}: /{group} is damaged: {_first_line(err)}") from None


def _first_line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return text[0][:200] if text else type(err).__name__


def cmd_inspect(args: argparse.Namespace) -> int:
    from scenegen.io import guard

    info = guard.call(_inspect, str(args.file), label=str(args.file))
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    print(f"{info['file']}: schema {info['schema']}, generator {info['generator_version']}")
    for s in info["sequences"]:
        ents = ", ".join(f"{n} {r}" for r, n in s["entities"].items())
        print(
            f"  sequence {s['name']}: {s['n_frames']} frames {s['width']}x{s['height']}, "
            f"seed {s['seed']}, preset {s['preset'] or '-'}, {ents}; "
            f"compression {s['compression']}"
        )
    for r in info["results"]:
        print(f"  result {r['tracker']} on {r['sequence']}: boxes {r['shape']}")
    return 0


def cmd_validate(args: argparse.Namespace) -> int:
    import sys

    folder = args.file
    if folder.is_dir():
        from scenegen.lab.benchmark_outputs import check_benchmark, is_benchmark_folder

        if is_benchmark_folder(folder):  # its sealed records, results.json and pages
            skipped: list[str] = []
            problems = check_benchmark(folder, deep=args.deep, skipped=skipped)
            for line in problems:
                print(line, file=sys.stderr)
            if not problems:
                note = (f" ({len(skipped)} runs of trackers that are not deterministic not "
                        "run again)" if skipped else "")  # fmt: skip
                print(f"{folder}: valid benchmark folder{note}")
            return 1 if problems else 0
    if folder.is_dir() and not (folder / "manifest.json").exists() and (
        (folder / "results.json").exists() or (folder / "runs").is_dir()
        or (folder / "experiments").is_dir()
    ):  # an experiment or report folder: its sealed records, results.json and table.md
        from scenegen.lab.demo_presets import presets_problems
        from scenegen.lab.experiments.outputs import check_experiment, check_report
        from scenegen.lab.report import index_problem

        report = (folder / "experiments").is_dir()
        problems = (check_report(folder, index_problem) + presets_problems(folder) if report
                    else check_experiment(folder, deep=args.deep))  # fmt: skip
        for line in problems:
            print(line, file=sys.stderr)
        if not problems:
            print(f"{folder}: valid {'report' if report else 'experiment'} folder")
        return 1 if problems else 0
    if folder.is_dir() and not (folder / "manifest.json").exists():
        print(f"{folder}: not a scenegen folder (no manifest.json of a dataset, results.json "
              "of an experiment, report or benchmark, or runs/)", file=sys.stderr)  # fmt: skip
        return 1
    if folder.is_dir():  # a dataset folder (scenegen dataset): every shard and digest
        from scenegen.cli.dataset import cmd_validate_dataset

        return cmd_validate_dataset(args)
    from scenegen.io.validate import check_file

    problems = check_file(args.file, isolate=True, deep=args.deep)
    if problems:
        for line in problems:
            print(line, file=sys.stderr)
        return 1
    print(f"{args.file}: valid")
    return 0


def _read(path: Path, name: str | None) -> Any:
    from scenegen.io import read
    from scenegen.io.validate import require_valid

    require_valid(path)  # no computing on a damaged or inconsistent file
    with picked_by("--sequence"):
        return read(path, name)


def cmd_preview(args: argparse.Namespace) -> int:
    from scenegen.io import read_result
    from scenegen.io.preview import write_preview

    seq = _read(args.file, args.sequence)
    boxes = None
    if args.result is not None:
        from scenegen.io.validate import require_valid

        require_valid(args.result)
        res = read_result(args.result)
        if res.boxes.shape[0] != seq.n_frames:
            raise DataError(
                f"{args.result}: {res.boxes.shape[0]} frames, but {args.file} has {seq.n_frames}"
            )
        boxes = res.boxes
    write_preview(seq, args.output, boxes=boxes)
    print(f"wrote {args.output}")
    return 0


def _is_result_file(path: Path, output: Path) -> bool:
    """True if ``path`` should be exported as a tracker result (it holds results, and
    either no sequence or the output is a ``.txt`` file)."""
    from scenegen.io import open_checked

    with open_checked(path) as f:
        has_results = "results" in f and len(f["results"]) > 0
        has_sequences = "sequences" in f and len(f["sequences"]) > 0
    return has_results and (not has_sequences or output.suffix == ".txt")


def _refuse_replacing_input(source: Path, output: Path) -> None:
    """An export replaces its output: refuse one that is, or holds, the file it reads."""
    src, out = source.resolve(), output.resolve()
    if src == out or out in src.parents:
        raise ConfigError(
            f"-o {output}: would replace {'' if src == out else 'the folder of '}the input "
            f"{source}; choose another output"
        )


def cmd_export(args: argparse.Namespace) -> int:
    from scenegen.io.mot import write_mot_tracker

    _refuse_replacing_input(Path(args.file), Path(args.output))
    result = _is_result_file(args.file, args.output)
    if not result or args.format == "mot":
        _refuse_unused_options(args, result)
    if result:
        from scenegen.io import read_result

        if args.format != "mot":
            raise ConfigError(
                f"{args.file}: a tracker result exports only to --format mot, not {args.format}"
            )
        with picked_by("--tracker"):
            res = read_result(args.file, args.tracker)
        n = write_mot_tracker(args.output, res.boxes, res.target_ids)
        print(f"wrote {args.output} ({n} boxes of {res.tracker!r}, MOTChallenge tracker file)")
        return 0
    from scenegen.io.benchmarks import export_benchmark
    from scenegen.io.export import export_mot

    seq = _read(args.file, args.sequence)
    with bar(seq.n_frames, f"export {args.format}", unit="frame") as pb:

        def progress(n: int) -> None:
            pb.update(n - pb.n)

        if args.format == "mot":
            export_mot(
                seq, args.output, gt_mode=args.gt_mode or "amodal",
                visibility_threshold=args.visibility_threshold or 0.0,
                image_format=args.image_format or "png", progress=progress,
            )  # fmt: skip
        else:
            export_benchmark(
                seq, args.output, args.format, image_format=args.image_format, progress=progress
            )
    print(f"wrote {args.output}")
    return 0
