"""Damaged variants of scenegen files, and the verdict of every verb on each.

:func:`variants` makes seeded, reproducible damage of a valid file: truncations, zeroed
blocks (at random offsets, over whole chunks, over metadata structures and the global
heap when there is one), bit flips in metadata and in chunks, values and attributes
edited through HDF5 (valid HDF5 checksums), edits with the digests recomputed too (only
``validate --deep`` can tell), deleted datasets and attributes, datasets rewritten with
another dtype. :func:`run_case` runs the verbs on one variant inside a guarded child
(:func:`scenegen.io.guard.call`), so a hang is a timeout of that case, never of the
suite; :func:`same_content` tells a variant whose damage fell on unused bytes (nothing
readable changed: "valid" is right) from a wrong "valid".
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from scenegen.io import integrity

SIGNATURES = (b"OHDR", b"OCHK", b"FRHP", b"FHDB", b"FHIB", b"BTHD", b"BTIN", b"BTLF",
              b"FAHD", b"FADB", b"EAHD", b"EADB", b"SNOD", b"TREE", b"HEAP", b"GCOL",
              b"\x89HDF")  # fmt: skip
KINDS = ("truncate", "zero", "zero_meta", "zero_heap", "flip_meta", "flip_chunk",
         "zero_chunk", "edit_value", "edit_attr", "resealed", "delete_dataset",
         "delete_attr", "wrong_dtype")  # fmt: skip
RESULT_KINDS = tuple(k if k != "resealed" else "edit_value" for k in KINDS)
"""Result files: no re-render can tell a forged result whose digests were recomputed
(it would take re-running the tracker), so their resealed edits are plain edits."""


@dataclass(frozen=True)
class Variant:
    """One damaged copy: ``apply(dst)`` writes it; ``deep`` when only a re-render can
    tell (an edit whose digests were recomputed)."""

    name: str
    kind: str
    apply: Callable[[Path], None]
    deep: bool = False


def _datasets(path: Path) -> list[tuple[str, tuple[int, ...], str, bool]]:
    out: list[tuple[str, tuple[int, ...], str, bool]] = []
    with h5py.File(path, "r") as f:

        def visit(name: str, obj: Any) -> None:
            if isinstance(obj, h5py.Dataset):
                out.append((name, obj.shape, obj.dtype.str, obj.chunks is not None))

        f.visititems(visit)
    return out


def _chunks(path: Path) -> list[tuple[str, int, int]]:
    """(dataset, byte offset, size) of every stored chunk."""
    out = []
    with h5py.File(path, "r") as f:
        for name, _, _, chunked in _datasets(path):
            ds = f[name]
            if chunked and ds.size:
                for i in range(ds.id.get_num_chunks()):
                    info = ds.id.get_chunk_info(i)
                    out.append((name, info.byte_offset, info.size))
    return out


def _signatures(data: bytes) -> list[tuple[bytes, int]]:
    out = []
    for sig in SIGNATURES:
        at = data.find(sig)
        while at >= 0:
            out.append((sig, at))
            at = data.find(sig, at + 1)
    return sorted(out, key=lambda s: s[1])


def _bytes_variant(src: bytes, fn: Callable[[bytearray], bytearray]) -> Callable[[Path], None]:
    def apply(dst: Path) -> None:
        dst.write_bytes(bytes(fn(bytearray(src))))

    return apply


def _h5_variant(src: Path, fn: Callable[[h5py.File], None]) -> Callable[[Path], None]:
    def apply(dst: Path) -> None:
        shutil.copyfile(src, dst)
        with h5py.File(dst, "r+") as f:
            fn(f)

    return apply


def _changed(value: Any, rng: np.random.Generator) -> Any:
    """A value of the same type that differs from ``value``."""
    if isinstance(value, (bool, np.bool_)):
        return not value
    if isinstance(value, (bytes, np.bytes_)):
        raw = bytes(value) or b"x"
        i = int(rng.integers(len(raw)))
        return raw[:i] + bytes([(raw[i] ^ 0x01) or 0x41]) + raw[i + 1 :]
    if isinstance(value, str):
        return value + "x"
    if isinstance(value, (float, np.floating)):
        return 7.0 if np.isnan(value) else (np.nan if rng.random() < 0.3 else value + 1.0)
    with np.errstate(over="ignore"):
        return value + 1  # wraps at the top of an integer type: still another value


def _edit_value(name: str, rng: np.random.Generator, reseal: bool) -> Callable[[h5py.File], None]:
    def fn(f: h5py.File) -> None:
        ds = f[name]
        arr = ds[()]
        flat = arr.reshape(-1)
        i = int(rng.integers(flat.size))
        flat[i] = _changed(flat[i], rng)
        ds[...] = arr
        if reseal and integrity.DIGEST in ds.attrs:
            integrity.put_text(ds, integrity.DIGEST, integrity.digest(ds[()]))

    return fn


def _edit_attr(rng: np.random.Generator) -> Callable[[h5py.File], None]:
    def fn(f: h5py.File) -> None:
        objs = [f]
        for top in ("sequences", "results"):
            if top in f:
                objs += list(f[top].values())
        obj = objs[int(rng.integers(len(objs)))]
        keys = [k for k in obj.attrs if k not in ("attrs_sha256",)]
        key = keys[int(rng.integers(len(keys)))]
        value = obj.attrs[key]
        new = _changed(value, rng)
        if isinstance(new, bytes):
            integrity.put_text(obj, key, new.decode("utf-8", "replace"))
        else:
            obj.attrs[key] = new

    return fn


def _delete(name: str) -> Callable[[h5py.File], None]:
    return lambda f: f.__delitem__(name)


def _delete_attr(rng: np.random.Generator) -> Callable[[h5py.File], None]:
    def fn(f: h5py.File) -> None:
        objs: list[Any] = []
        f.visititems(lambda _n, o: objs.append(o))
        objs = [o for o in [f, *objs] if len(o.attrs)]
        obj = objs[int(rng.integers(len(objs)))]
        keys = list(obj.attrs)
        del obj.attrs[keys[int(rng.integers(len(keys)))]]

    return fn


def _wrong_dtype(name: str, rng: np.random.Generator) -> Callable[[h5py.File], None]:
    def fn(f: h5py.File) -> None:
        ds = f[name]
        arr, attrs = ds[()], dict(ds.attrs)
        choices = [np.float64, np.int64, np.uint8, np.float32, np.int16]
        choices = [c for c in choices if np.dtype(c) != arr.dtype]
        if arr.dtype.kind in "SOU":
            new = np.arange(arr.size).reshape(arr.shape)
        else:
            new = arr.astype(choices[int(rng.integers(len(choices)))])
        del f[name]
        out = f.create_dataset(name, data=new)
        for k, v in attrs.items():
            out.attrs[k] = v

    return fn


def variants(src: Path, n: int, seed: int, kinds: tuple[str, ...] = KINDS) -> list[Variant]:
    """``n`` seeded damaged variants of the valid file ``src``, cycling through ``kinds``."""
    rng = np.random.default_rng(seed)
    data = src.read_bytes()
    size = len(data)
    sigs = _signatures(data)
    heaps = [at for sig, at in sigs if sig == b"GCOL"]
    chunks = _chunks(src)
    sets = _datasets(src)
    out: list[Variant] = []
    for i in range(n):
        kind = kinds[i % len(kinds)]
        if kind == "zero_heap" and not heaps:
            kind = "zero_meta"
        name = f"{i:04d}-{kind}"
        if kind == "truncate":
            cut = int(rng.integers(0, size))
            out.append(Variant(f"{name}@{cut}", kind, _bytes_variant(data, lambda b, c=cut: b[:c])))
        elif kind in ("zero", "zero_meta", "zero_heap"):
            if kind == "zero":
                at = int(rng.integers(0, size))
            elif kind == "zero_meta":
                at = sigs[int(rng.integers(len(sigs)))][1] + int(rng.integers(0, 64))
            else:
                at = heaps[int(rng.integers(len(heaps)))] + int(rng.choice([0, 16, 24]))
            length = int(rng.choice([8, 64, 512, 4096, 65536]))

            def zero(b: bytearray, a: int = at, n_: int = length) -> bytearray:
                end = min(len(b), a + n_)
                b[a:end] = bytes(end - a)
                return b

            out.append(Variant(f"{name}@{at}+{length}", kind, _bytes_variant(data, zero)))
        elif kind in ("flip_meta", "flip_chunk"):
            if kind == "flip_meta" or not chunks:
                base, span = sigs[int(rng.integers(len(sigs)))][1], 256
            else:
                _, base, span = chunks[int(rng.integers(len(chunks)))]
            flips = [(base + int(rng.integers(span)), 1 << int(rng.integers(8)))
                     for _ in range(int(rng.integers(1, 4)))]  # fmt: skip

            def flip(b: bytearray, fl: list[tuple[int, int]] = flips) -> bytearray:
                for at, bit in fl:
                    if at < len(b):
                        b[at] ^= bit
                return b

            out.append(Variant(f"{name}@{flips[0][0]}", kind, _bytes_variant(data, flip)))
        elif kind == "zero_chunk":
            ds_name, at, length = chunks[int(rng.integers(len(chunks)))]

            def zero_all(b: bytearray, a: int = at, n_: int = length) -> bytearray:
                b[a : a + n_] = bytes(n_)
                return b

            out.append(Variant(f"{name}:{ds_name}", kind, _bytes_variant(data, zero_all)))
        elif kind in ("edit_value", "resealed"):
            cands = [s for s in sets if int(np.prod(s[1])) > 0]
            ds_name = cands[int(rng.integers(len(cands)))][0]
            fn = _edit_value(
                ds_name, np.random.default_rng(rng.integers(2**32)), kind == "resealed"
            )
            out.append(Variant(f"{name}:{ds_name}", kind, _h5_variant(src, fn), kind == "resealed"))
        elif kind == "edit_attr":
            fn = _edit_attr(np.random.default_rng(rng.integers(2**32)))
            out.append(Variant(name, kind, _h5_variant(src, fn)))
        elif kind == "delete_dataset":
            ds_name = sets[int(rng.integers(len(sets)))][0]
            out.append(Variant(f"{name}:{ds_name}", kind, _h5_variant(src, _delete(ds_name))))
        elif kind == "delete_attr":
            fn = _delete_attr(np.random.default_rng(rng.integers(2**32)))
            out.append(Variant(name, kind, _h5_variant(src, fn)))
        elif kind == "wrong_dtype":
            ds_name = sets[int(rng.integers(len(sets)))][0]
            fn = _wrong_dtype(ds_name, np.random.default_rng(rng.integers(2**32)))
            out.append(Variant(f"{name}:{ds_name}", kind, _h5_variant(src, fn)))
    return out


def old_format(src: Path, dst: Path) -> None:
    """Copy ``src`` as files of older versions were: variable-length strings (on the
    global heap), no digests."""
    shutil.copyfile(src, dst)
    with h5py.File(dst, "r+") as f:
        integrity.strip(f)
        groups = [*f.get("sequences", {}).values(), *f.get("results", {}).values()]
        for obj in (f, *groups):
            for key in list(obj.attrs):
                if isinstance(obj.attrs[key], bytes):
                    obj.attrs[key] = obj.attrs[key].decode()
        for g in f.get("sequences", {}).values():
            for key in ("entities/role", "entities/name"):
                values = [v.decode() for v in g[key][()]]
                del g[key]
                g.create_dataset(key, data=values, dtype=h5py.string_dtype("utf-8"))


# ---------------------------------------------------------------------------------------
# Running the verbs on a variant (inside a guarded child)


def content(path: str) -> str:
    """Digest of everything readable in a file: every object's attributes, every
    dataset's dtype, shape and values. Raises on anything unreadable."""
    h = hashlib.sha256()
    with h5py.File(path, "r") as f:
        objs: list[tuple[str, Any]] = [("/", f)]
        f.visititems(lambda n, o: objs.append((n, o)))
        for name, obj in sorted(objs, key=lambda x: x[0]):
            h.update(name.encode())
            h.update(integrity.attrs_digest(obj.attrs).encode())
            h.update(repr(sorted(obj.attrs)).encode())
            if isinstance(obj, h5py.Dataset):
                h.update(f"{obj.dtype.str}{obj.shape}".encode())
                h.update(np.ascontiguousarray(obj[()]).tobytes())
    return h.hexdigest()


def run_case(argvs: list[list[str]], inner_timeout: float) -> list[tuple[int, str]]:
    """Run ``scenegen`` verbs in this (guarded) process: their exit codes and stderr.

    The verbs run as in a program of their own. A guarded child skips the metadata
    preflight of :func:`scenegen.io.guard.preflight` (it is time-boxed already); a user's
    process does not, so the preflight is restored here: the readers' guarded children
    are forked from this process, each with ``inner_timeout``. Without it, a verb that
    opens the file before its check (``export`` asking whether it holds results) ran its
    first read unguarded, and a looping file stalled the whole case (seen at
    ``SCENEGEN_DAMAGE_SCALE=8``: an old-format file with a zeroed global heap).
    """
    import multiprocessing

    from scenegen.io import guard

    os.environ["SCENEGEN_READ_TIMEOUT"] = str(inner_timeout)
    if guard.in_child():
        import threading

        from tqdm import tqdm

        guard._conn = None  # preflight runs: this process no longer counts as a child
        guard._context = lambda: multiprocessing.get_context("fork")  # as in a child
        # A progress bar's default lock is a semaphore registered with multiprocessing's
        # resource tracker; this child ends by os._exit, which leaves it registered (the
        # tracker then warns of "leaked semaphore objects" at the end of the session).
        tqdm.set_lock(threading.RLock())
    from scenegen.cli import main

    out = []
    for argv in argvs:
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            try:
                code = main(argv)
            except BaseException as exc:  # noqa: BLE001 - counted as a traceback
                code = 99
                err.write(f"Traceback: {type(exc).__name__}: {exc}\n")
        out.append((code, err.getvalue()))
    return out


# ---------------------------------------------------------------------------------------
# Experiment outputs: a folder of sealed JSON run records, results.json and table.md

FOLDER_KINDS = ("truncate", "zero", "flip", "edit_value", "edit_unsealed", "edit_badseal",
                "resealed", "wrong_type", "delete_key", "delete_file", "unsealed", "replaced",
                "not_object")  # fmt: skip
"""Damage of one file of an experiment folder. ``edit_value``: a value changed, the old
digest kept; ``edit_unsealed``: changed and the digest removed; ``edit_badseal``: changed
and a digest recomputed the wrong way (over indented text); ``resealed``, ``wrong_type``,
``delete_key``: changed with a correct digest (only the cross-checks of the folder can
tell); ``unsealed``: only the digest removed (an old file); ``replaced``: a record
overwritten by another run's sound record; ``not_object``: a sealed JSON array."""

_SEAL = "sha256"


def _json_paths(x: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Paths of every value (containers and leaves) under ``x``, the seal excluded."""
    out = [prefix] if prefix else []
    if isinstance(x, dict):
        for k, v in x.items():
            if not (prefix == () and k == _SEAL):
                out += _json_paths(v, (*prefix, k))
    elif isinstance(x, list):
        for i, v in enumerate(x):
            out += _json_paths(v, (*prefix, i))
    return out


def _get(x: Any, path: tuple[Any, ...]) -> Any:
    for p in path:
        x = x[p]
    return x


def _put(x: Any, path: tuple[Any, ...], value: Any) -> None:
    _get(x, path[:-1])[path[-1]] = value


def _other_leaf(v: Any, rng: np.random.Generator) -> Any:
    if isinstance(v, bool):
        return not v
    if isinstance(v, int):
        return v + int(rng.integers(1, 5))
    if isinstance(v, float):
        return v + 0.5
    if isinstance(v, str):
        return v + "x"
    if v is None:
        return 0
    return None


def _other_type(v: Any) -> Any:
    if isinstance(v, bool):
        return "true"
    if isinstance(v, (int, float)):
        return str(v)
    if isinstance(v, str):
        return [v]
    if isinstance(v, list):
        return {"0": v[:1]}
    if isinstance(v, dict):
        return list(v.values())[:1]
    return []


def _sealed(body: dict[str, Any]) -> dict[str, Any]:
    from scenegen.io.sealed import seal

    return seal(body)


def _write(path: Path, doc: Any, indent: bool) -> None:
    path.write_text(json.dumps(doc, sort_keys=True, indent=1 if indent else None) + "\n")


def _json_variant(kind: str, target: str, rng: np.random.Generator,
                  others: list[str]) -> Callable[[Path], None]:  # fmt: skip
    """Damage ``DIR/target`` (a sealed JSON file) of a copied folder."""

    def apply(d: Path) -> None:
        p = d / target
        indent = target == "results.json"
        doc = json.loads(p.read_text())
        body = {k: v for k, v in doc.items() if k != _SEAL}
        paths = _json_paths(body)
        if kind in ("edit_value", "edit_unsealed", "edit_badseal", "resealed"):
            leaves = [q for q in paths if not isinstance(_get(body, q), (dict, list))]
            q = leaves[int(rng.integers(len(leaves)))]
            _put(body, q, _other_leaf(_get(body, q), rng))
            if kind == "edit_value":
                body[_SEAL] = doc[_SEAL]
            elif kind == "edit_badseal":
                text = json.dumps(body, sort_keys=True, indent=1)
                body[_SEAL] = hashlib.sha256(text.encode()).hexdigest()
            elif kind == "resealed":
                body = _sealed(body)
            _write(p, body, indent)
        elif kind == "wrong_type":
            q = paths[int(rng.integers(len(paths)))]
            _put(body, q, _other_type(_get(body, q)))
            _write(p, _sealed(body), indent)
        elif kind == "delete_key":
            keyed = [q for q in paths if isinstance(q[-1], str)]
            q = keyed[int(rng.integers(len(keyed)))]
            del _get(body, q[:-1])[q[-1]]
            _write(p, _sealed(body), indent)
        elif kind == "unsealed":
            _write(p, body, indent)
        elif kind == "replaced":
            shutil.copyfile(d / others[int(rng.integers(len(others)))], p)
        elif kind == "not_object":
            p.write_text(json.dumps([body]) + "\n")

    return apply


def _file_bytes_variant(kind: str, target: str, rng: np.random.Generator) -> Callable[[Path], None]:
    seed = int(rng.integers(2**32))

    def apply(d: Path) -> None:
        p = d / target
        if kind == "delete_file":
            p.unlink()
            return
        r = np.random.default_rng(seed)
        data = bytearray(p.read_bytes())
        if kind == "truncate":
            data = data[: int(r.integers(0, len(data)))]
        elif kind == "zero":
            at = int(r.integers(0, len(data)))
            n = int(r.choice([1, 8, 64, 512, 4096]))
            data[at : at + n] = bytes(len(data[at : at + n]))
        else:  # flip
            for _ in range(int(r.integers(1, 4))):
                data[int(r.integers(len(data)))] ^= 1 << int(r.integers(8))
        p.write_bytes(bytes(data))

    return apply


EXPERIMENT_FILES = ("runs/*.json", ("table.md",))
"""An experiment folder's run records (a glob) and its text files."""
BENCHMARK_FILES = ("runs/*/*.json", ("scores.csv", "leaderboard.md", "index.html"))
"""A benchmark folder's run records (a glob) and its text files."""


def folder_variants(src: Path, n: int, seed: int, kinds: tuple[str, ...] = FOLDER_KINDS,
                    layout: tuple[str, tuple[str, ...]] = EXPERIMENT_FILES) -> list[Variant]:
    """``n`` seeded damaged variants of the experiment (or, with ``layout`` =
    :data:`BENCHMARK_FILES`, benchmark) folder ``src``: each damages one file
    (``results.json``, a run record or a text file); ``apply(dst)`` writes the damaged
    copy into the folder ``dst`` (which must not exist)."""
    rng = np.random.default_rng(seed)
    runs = sorted(str(p.relative_to(src)) for p in src.glob(layout[0]))
    out = []
    for i in range(n):
        kind = kinds[i % len(kinds)]
        byte_kind = kind in ("truncate", "zero", "flip", "delete_file")
        files = ["results.json", *runs, *(layout[1] if byte_kind else [])]
        if kind == "replaced":
            files = runs
        target = files[int(rng.integers(len(files)))]
        sub = np.random.default_rng(rng.integers(2**32))
        if byte_kind:
            fn = _file_bytes_variant(kind, target, sub)
        else:
            fn = _json_variant(kind, target, sub, [r for r in runs if r != target])

        def apply(dst: Path, fn_: Callable[[Path], None] = fn) -> None:
            shutil.copytree(src, dst)
            fn_(dst)

        out.append(Variant(f"{i:04d}-{kind}:{target}", kind, apply, kind in (
            "resealed", "wrong_type", "delete_key")))  # fmt: skip
    return out


def folder_content(folder: str,
                   layout: tuple[str, tuple[str, ...]] = EXPERIMENT_FILES) -> str:  # fmt: skip
    """Digest of everything readable in an experiment (or benchmark) folder: the parsed
    content of every JSON file (its raw bytes if it does not parse) and the text files."""
    h = hashlib.sha256()
    root = Path(folder)
    texts = [root / t for t in layout[1]]
    for p in sorted([root / "results.json", *texts, *root.glob(layout[0])]):
        h.update(str(p.relative_to(root)).encode())
        if not p.exists():
            h.update(b"<missing>")
            continue
        raw = p.read_bytes()
        try:
            value = json.loads(raw) if p.suffix == ".json" else raw
        except ValueError:
            value = raw
        h.update(repr(value).encode() if p.suffix == ".json" else raw)
    return h.hexdigest()


def run_folder_case(argvs: list[list[str]], report: Path | None) -> list[tuple[int, str]]:
    """Like :func:`run_case`, then (if ``report``) :func:`scenegen.lab.report.build_report`
    on that report folder: (0, "") or (1, its DataError line)."""
    out = run_case(argvs, 3.0)
    if report is not None:
        from scenegen.errors import DataError
        from scenegen.lab.report import build_report

        try:
            build_report(report)
            out.append((0, ""))
        except DataError as err:
            out.append((1, f"{err}\n"))
        except BaseException as exc:  # noqa: BLE001 - counted as a traceback
            out.append((99, f"Traceback: {type(exc).__name__}: {exc}\n"))
    return out
