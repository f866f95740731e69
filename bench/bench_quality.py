#!/usr/bin/env python3
"""Quality benchmark (issue 12): cuts of solid textures scored against their exemplars, next to
Embark's 2D texture-synthesis on the same exemplar and size.

  bench_quality.py BUILD [--size 256] [--exemplars a.png,b.png] [--out DIR] [--no-embark]
                  [--typicality T]   (synthesis' typicality weight; default: the CLI's default)
                  [--seeds 1,2,3]    (volume seeds; a single cut's swd varies by seed, so an
                                      exemplar's score is its worst-of-four swd averaged over them,
                                      and over --shifts)
                  [--resample auto|nearest|cubic] (the oblique cut's sampling; default auto)
                  [--analyze-args "--grain crossed"] (extra analyze flags, for the exemplars
                                      not analysed with --grain x)
                  [--embark-cache F] (Embark's scores per exemplar and size, kept in F and reused:
                                      Embark takes minutes on the large exemplars)
                  [--embark-seeds 1,2,3] (Embark's seeds; its swd varies by seed and from run
                                      to run (it is multi-threaded), so the ratio's denominator is
                                      its swd averaged over them; default 1, the seed the
                                      benchmark has always used)
                  [--oriented]       (also score every cut against the exemplar turned to the
                                      cut's own dominant orientation: see oriented_reference)
                  [--shifts 0,24,48] (translate all four cuts by (d, d, d) finest voxels as well:
                                      a sample per seed and shift; see cut_set. Grain layouts'
                                      slabs make a z cut's score depend on its depth, and the
                                      origin lies on a layer boundary: docs/quality.md)

For every exemplar in ../shared/data/exemplars (wood_grain and wood_planks analysed with
--grain x, as the issue asks, the rest with defaults; --grain auto, the default, gives
stripes_dunes grain x and tree_bark grain y, and wood grain x too): z, y and x cuts and one oblique cut of SIZE^2 through the
origin, scored with ../shared/tools/texmetric.py (swd, coverage, energy, sharp; read its header:
energy alone rewards blur): an axis cut against the exemplar its plane was synthesized from,
oriented as the cut (`solidtex slice --reference`; it differs from the exemplar as given only in
cuts along a grain that runs across the image, e.g. an x cut of tree bark's y grain, which then
also report `as_given`), the oblique cut against the exemplar as given. Embark 2D (../shared/tools/embark-ref, built into BUILD/embark-ref
with cargo on first use) synthesizes SIZE^2 from the same exemplar. Prints one JSON document
with per-cut scores, per-exemplar worst-of-four swd over Embark's and axis_autocorrelation_gap
(see that function), and the issue's summary measures; writes a montage PNG per exemplar
(exemplar repeated at 1:1 | z | y | x | oblique | Embark) into DIR.
"""
from __future__ import annotations

import argparse
import json
import itertools
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
GRAIN_X = {"wood_grain", "wood_planks"}
# The oblique cut: the plane through the origin spanned by two orthonormal steps.
OBLIQUE = "0,0,0,0.6,0.8,0,-0.48,0.36,0.8"


def run(cmd, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([str(c) for c in cmd], check=True, capture_output=True, text=True, **kw)


def same_pixels(a: Path, b: Path) -> bool:
    x, y = (np.asarray(Image.open(p).convert("RGB")) for p in (a, b))
    return x.shape == y.shape and bool(np.array_equal(x, y))


def texmetric(python: str, image: Path, exemplar: Path) -> dict:
    out = run([python, SHARED / "tools" / "texmetric.py", image, exemplar]).stdout
    return json.loads(out.strip().splitlines()[-1])


def dominant_orientation(path: Path) -> tuple[float, float]:
    """The angle (radians, image columns right and rows down) of the luminance gradients'
    dominant direction, from the structure tensor summed over the image (gradients of a
    1-pixel Gaussian), and its coherence in [0, 1] (0: no dominant direction)."""
    from scipy.ndimage import gaussian_filter
    a = gaussian_filter(np.asarray(Image.open(path).convert("L"), dtype=np.float64), 1.0)
    gy, gx = np.gradient(a)
    jxx, jyy, jxy = float((gx * gx).mean()), float((gy * gy).mean()), float((gx * gy).mean())
    coherence = float(np.hypot(jxx - jyy, 2 * jxy) / (jxx + jyy + 1e-12))
    return 0.5 * float(np.arctan2(2 * jxy, jxx - jyy)), coherence


def oriented_reference(exemplar: Path, exemplar_orientation: tuple[float, float], cut: Path, out: Path,
                       size: int = 512) -> dict:
    """The exemplar (its dominant_orientation given: one per exemplar, not per cut) turned so
    its dominant orientation is the cut's, SIZE^2, sampled cubically
    and periodically (texmetric treats the exemplar as periodic too). Why: a grained solid is
    made of sheets whose tilt synthesis chooses (docs/quality.md, "How the grained solids are
    built"), so an oblique cut shows the grain turned by an angle no layout fixes beforehand,
    and the exemplar as given scores the turn, not the texture. The cubic resampling smooths
    the reference a little (a 0.3 degree turn of tree_bark lowers its z cut's swd 0.111 ->
    0.100), so compare these scores with each other, not with the others."""
    from scipy.ndimage import map_coordinates
    ex_angle, ex_coherence = exemplar_orientation
    cut_angle, cut_coherence = dominant_orientation(cut)
    turn = cut_angle - ex_angle
    e = np.asarray(Image.open(exemplar).convert("RGB"), dtype=np.float64)
    rows, cols = np.mgrid[0:size, 0:size].astype(np.float64)
    c, s = np.cos(turn), np.sin(turn)
    # Reference pixel (col, row) shows the exemplar at the pixel turned back by `turn`.
    src_cols, src_rows = c * cols + s * rows, -s * cols + c * rows
    ref = np.stack([map_coordinates(e[..., k], [src_rows, src_cols], order=3, mode="grid-wrap") for k in range(3)], -1)
    Image.fromarray(np.clip(ref, 0, 255).round().astype(np.uint8)).save(out)
    return {"turn_deg": round(float(np.degrees(turn)), 1), "cut_coherence": round(cut_coherence, 3),
            "exemplar_coherence": round(ex_coherence, 3)}


def axis_autocorrelations(image: np.ndarray, max_lag: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """Normalised autocorrelation of an RGB image (values 0-255 or 0-1) along its rows (lags
    between columns, the image's u axis) and along its columns (lags between rows, v), for lags
    1..max_lag, each channel's mean removed, periodic."""
    a = np.asarray(image, dtype=np.float64)
    a = a - a.mean(axis=(0, 1))
    var = float((a * a).sum(axis=2).mean()) + 1e-12
    lags = range(1, max_lag + 1)
    along_u = np.array([(a * np.roll(a, -t, axis=1)).sum(axis=2).mean() / var for t in lags])
    along_v = np.array([(a * np.roll(a, -t, axis=0)).sum(axis=2).mean() / var for t in lags])
    return along_u, along_v


def axis_autocorrelation_gap(image: np.ndarray, max_lag: int = 16) -> float:
    """max over lags 1..max_lag of |autocorrelation along u - along v| (0-2): how far the
    exemplar is from looking alike along its two axes. Why it bounds every solid: the three axis
    cuts share each world axis between two cuts, and each cut's reference (the exemplar in any
    of its 8 turns and flips) puts its u profile on one of the cut's axes and its v profile on
    the other; three u's over three axes of two slots each leave some axis with a u profile from
    one cut and a v profile from the other. A stationary solid has one autocorrelation along
    that axis, so one of those two cuts misses its reference's by at least half this gap at
    some lag (docs/quality.md, "No solid shows a striped exemplar on all three axis cuts")."""
    along_u, along_v = axis_autocorrelations(image, max_lag)
    return round(float(np.abs(along_u - along_v).max()), 3)


def cut_set(shift: int, resample: str) -> dict[str, list[str]]:
    """The four cuts' `solidtex slice` placement flags, every cut translated by (shift, shift,
    shift) finest voxels: each cut's first pixel is voxel (shift, shift, shift), so axis cuts
    lie at depth `shift` with their in-plane origin at (shift, shift) and the oblique passes
    through that voxel. Shift 0 is the cut set the benchmark has always used."""
    d = str(shift)
    u_v = OBLIQUE.split(",")[3:]
    axis = {a: ["--axis", a, "--at", d, "--origin", f"{d},{d}"] for a in ("z", "y", "x")}
    return {**axis, "oblique": ["--plane", ",".join([d, d, d, *u_v]), "--resample", resample]}


def sample_key(seed: int, shift: int) -> str:
    """A sample's key in an exemplar's "seeds": the seed alone at shift 0 (as before shifts), else SEED+SHIFT."""
    return str(seed) if shift == 0 else f"{seed}+{shift}"


def worst_of_four(cuts: dict[str, dict], score=lambda c: c["swd"]) -> float:
    """A sample's score: its worst cut."""
    return max(score(c) for c in cuts.values())


def worst_by_shift(worst: dict[tuple[int, int], float]) -> dict[str, float]:
    """Per shift, the worst-of-four scores (keyed by (seed, shift)) averaged over the seeds: how
    a translation of the cut set moves the exemplar's score (a stationary solid's hardly moves)."""
    by_shift: dict[str, list[float]] = {}
    for (_, shift), w in worst.items():
        by_shift.setdefault(str(shift), []).append(w)
    return {shift: round(float(np.mean(w)), 4) for shift, w in by_shift.items()}


def oblique_over_axis(cuts_by_seed: list[dict], score=lambda c: c["swd"]) -> float:
    """Mean oblique swd over mean axis-cut swd, over seeds; `score` picks which swd of a cut."""
    axis = np.mean([score(s[c]) for s in cuts_by_seed for c in ("z", "y", "x")])
    return round(float(np.mean([score(s["oblique"]) for s in cuts_by_seed])) / float(axis), 3)


def embark_key(name: str, size: int, seed: int) -> str:
    """An Embark run's key in --embark-cache: NAME@SIZE for seed 1 (as before seeds), else NAME@SIZE#SEED."""
    return f"{name}@{size}" if seed == 1 else f"{name}@{size}#{seed}"


def embark_swd(runs: dict[int, dict]) -> float:
    """The ratios' denominator: Embark's swd averaged over its seeds' runs."""
    return round(float(np.mean([r["swd"] for r in runs.values()])), 4)


def embark_binary(build: Path) -> Path | None:
    binary = build / "embark-ref" / "release" / "embark-ref"
    if binary.exists():
        return binary
    manifest = SHARED / "tools" / "embark-ref" / "Cargo.toml"
    if not manifest.exists():
        return None
    subprocess.run(["cargo", "build", "--release", "--manifest-path", str(manifest), "--target-dir",
                    str(build / "embark-ref")], check=True, capture_output=True)
    return binary


def montage(paths: list[Path], out: Path, tile: int = 256) -> None:
    """paths[0] is the exemplar: repeated at 1:1 to the cuts' size (a resized exemplar would show
    its features at another scale than the cuts, one voxel being one exemplar pixel)."""
    images = [Image.open(p).convert("RGB") for p in paths]
    cut = images[1].size if len(images) > 1 else images[0].size
    ex = np.asarray(images[0])
    reps = (-(-cut[1] // ex.shape[0]), -(-cut[0] // ex.shape[1]), 1)
    images[0] = Image.fromarray(np.tile(ex, reps)[:cut[1], :cut[0]])
    images = [im.resize((tile, tile), Image.NEAREST) for im in images]
    sheet = Image.new("RGB", (len(images) * (tile + 4) - 4, tile), (255, 255, 255))
    for k, im in enumerate(images):
        sheet.paste(im, (k * (tile + 4), 0))
    sheet.save(out)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("build", type=Path)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--exemplars", default="")
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--no-embark", action="store_true")
    ap.add_argument("--typicality", type=float, default=None)
    ap.add_argument("--table-cache", type=Path, default=None,
                    help="keep analysed tables here and reuse them (analysis dominates short runs)")
    ap.add_argument("--slice-args", default="", help="extra `solidtex slice` flags, e.g. \"--passes 1\"")
    ap.add_argument("--analyze-args", default="",
                    help="extra `solidtex analyze` flags for the exemplars analysed with defaults, e.g. \"--grain crossed\"")
    ap.add_argument("--resample", default="auto", choices=["auto", "nearest", "cubic"],
                    help="how the oblique cut samples the voxels (solidtex slice --resample)")
    ap.add_argument("--seeds", default="1", help="comma-separated volume seeds")
    ap.add_argument("--shifts", default="0",
                    help="comma-separated translations d of the cut set by (d, d, d) finest voxels (cut_set)")
    ap.add_argument("--embark-cache", type=Path, default=None)
    ap.add_argument("--embark-seeds", default="1", help="comma-separated Embark seeds; the ratios use its mean swd")
    ap.add_argument("--oriented", action="store_true",
                    help="also score every cut against the exemplar turned to the cut's dominant orientation")
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    embark_seeds = [int(s) for s in args.embark_seeds.split(",")]
    shifts = [int(d) for d in args.shifts.split(",")]
    embark_cache = json.loads(args.embark_cache.read_text()) if args.embark_cache and args.embark_cache.exists() else {}
    build = args.build.resolve()
    solidtex = build / "bin" / "solidtex"
    python = str(build / "venv" / "bin" / "python") if (build / "venv").exists() else sys.executable
    ex_dir = SHARED / "data" / "exemplars"
    if args.exemplars:
        exemplars = [Path(p) for p in args.exemplars.split(",")]
    elif ex_dir.exists():
        exemplars = sorted(ex_dir.glob("*.png"))
    else:
        print(json.dumps({"skipped": "no ../shared/data/exemplars"}))
        return 0
    out_dir = args.out or build / "bench-quality"
    out_dir.mkdir(parents=True, exist_ok=True)
    embark = None if args.no_embark else embark_binary(build)
    n = args.size
    tuning = ([] if args.typicality is None else ["--typicality", args.typicality]) + shlex.split(args.slice_args)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for ex in exemplars:
            name = ex.stem
            grain = ["--grain", "x"] if name in GRAIN_X else shlex.split(args.analyze_args)
            tag = "x" if name in GRAIN_X else ("auto" + ("_" + "_".join(a.strip("-") for a in grain) if grain else ""))
            table = (args.table_cache or tmp) / f"{name}_grain_{tag}.stx"
            if not (args.table_cache and table.exists()):
                table.parent.mkdir(parents=True, exist_ok=True)
                run([solidtex, "analyze", ex, *grain, "-o", table])
            entry = {"exemplar": name, "grain": "x" if name in GRAIN_X else "", "analyze_args": [] if name in GRAIN_X else grain, "size": n, "seeds": {}}
            entry["axis_autocorrelation_gap"] = axis_autocorrelation_gap(np.asarray(Image.open(ex).convert("RGB")))
            images = [ex]
            ex_orientation = dominant_orientation(ex) if args.oriented else None
            for seed, shift in itertools.product(seeds, shifts):
                per_seed = {}
                first = seed == seeds[0] and shift == shifts[0]
                for cut, where in cut_set(shift, args.resample).items():
                    suffix = ("" if seed == seeds[0] else f"_seed{seed}") + ("" if shift == 0 else f"_shift{shift}")
                    image = out_dir / (f"{name}_{cut}.png" if first else f"{name}_{cut}{suffix}.png")
                    stats = tmp / f"{name}_{cut}.json"
                    # Axis cuts are judged against the exemplar their plane was synthesized from,
                    # oriented as the cut (solidtex slice --reference): a cut along a y grain shows
                    # the grain across the image, as its plane's image (E transposed) has it.
                    reference = tmp / f"{name}_{cut}_reference.png"
                    ref_args = [] if cut == "oblique" else ["--reference", reference]
                    t0 = time.monotonic()
                    run([solidtex, "slice", table, *where, "--size", f"{n},{n}", "--seed", seed, *tuning, "-o", image,
                         "--stats", stats, *ref_args])
                    seconds = time.monotonic() - t0
                    if cut == "oblique" or same_pixels(reference, ex):
                        scores = texmetric(python, image, ex)
                    else:
                        scores = texmetric(python, image, reference)
                        scores["reference"] = "the exemplar as laid on the cut's plane (transposed)"
                        scores["as_given"] = texmetric(python, image, ex)
                    if args.oriented:
                        oriented = tmp / f"{name}_{cut}_oriented.png"
                        turn = oriented_reference(ex, ex_orientation, image, oriented)
                        scores["oriented"] = {**texmetric(python, image, oriented), **turn}
                    scores["seconds"] = round(seconds, 2)
                    st = json.loads(stats.read_text())
                    scores["voxels"] = st["voxels"]
                    if "resample" in st:  # plane cuts: what --resample (auto) sampled
                        scores["resample"] = st["resample"]
                    per_seed[cut] = scores
                    if first:
                        images.append(image)
                entry["seeds"][sample_key(seed, shift)] = per_seed
            entry["cuts"] = entry["seeds"][sample_key(seeds[0], shifts[0])]
            samples = {(seed, shift): entry["seeds"][sample_key(seed, shift)] for seed, shift in itertools.product(seeds, shifts)}
            worst = {key: worst_of_four(cuts) for key, cuts in samples.items()}
            if shifts != [0]:
                entry["worst_swd_by_shift"] = worst_by_shift(worst)
            entry["worst_swd_mean_over_seeds"] = round(float(np.mean(list(worst.values()))), 4)
            # The same with every cut scored against the exemplar as given (before --reference).
            worsts_as_given = [worst_of_four(cuts, lambda c: c.get("as_given", c)["swd"]) for cuts in samples.values()]
            entry["worst_swd_as_given_mean_over_seeds"] = round(float(np.mean(worsts_as_given)), 4)
            if embark:
                runs = {}
                for k, embark_seed in enumerate(embark_seeds):
                    image = out_dir / (f"{name}_embark.png" if k == 0 else f"{name}_embark_seed{embark_seed}.png")
                    key = embark_key(name, n, embark_seed)
                    if key not in embark_cache:
                        run([embark, ex, n, image, embark_seed])
                        embark_cache[key] = texmetric(python, image, ex)
                        if args.embark_cache:
                            args.embark_cache.write_text(json.dumps(embark_cache, indent=1))
                    runs[embark_seed] = embark_cache[key]
                    if k == 0 and image.exists():  # a cached score's image may live elsewhere
                        images.append(image)
                entry["embark"] = runs[embark_seeds[0]]
                entry["embark_swd_by_seed"] = {str(k): r["swd"] for k, r in runs.items()}
                entry["embark_swd"] = embark_swd(runs)
                entry["worst_swd_over_embark"] = round(entry["worst_swd_mean_over_seeds"] / entry["embark_swd"], 3)
                entry["worst_swd_as_given_over_embark"] = round(entry["worst_swd_as_given_mean_over_seeds"] / entry["embark_swd"], 3)
            cuts_all = list(entry["seeds"].values())
            entry["oblique_over_axis_swd"] = oblique_over_axis(cuts_all)
            if args.oriented:  # the same with every cut against its oriented reference
                entry["oblique_over_axis_swd_oriented"] = oblique_over_axis(cuts_all, lambda c: c["oriented"]["swd"])
            montage(images, out_dir / f"{name}_montage.png")
            results.append(entry)
            print(f"{name}: " + " ".join(f"{c}={v['swd']:.3f}/{v['sharp']:.2f}" for c, v in entry["cuts"].items())
                  + (f" embark={entry['embark']['swd']:.3f}/{entry['embark']['sharp']:.2f}" if embark else ""),
                  file=sys.stderr)
    sharp = [c["sharp"] for e in results for s in e["seeds"].values() for c in s.values()]
    summary = {"median_sharp": float(np.median(sharp)), "min_sharp": float(np.min(sharp)),
               "max_oblique_over_axis_swd": max(e["oblique_over_axis_swd"] for e in results)}
    if args.oriented:
        summary["max_oblique_over_axis_swd_oriented"] = max(e["oblique_over_axis_swd_oriented"] for e in results)
    ratios = [e["worst_swd_over_embark"] for e in results if "worst_swd_over_embark" in e]
    if ratios:
        as_given = [e["worst_swd_as_given_over_embark"] for e in results if "worst_swd_as_given_over_embark" in e]
        summary.update({"median_worst_swd_over_embark": float(np.median(ratios)),
                        "max_worst_swd_over_embark": float(np.max(ratios)),
                        "median_worst_swd_as_given_over_embark": float(np.median(as_given))})
    print(json.dumps({"size": n, "typicality": args.typicality, "slice_args": args.slice_args, "resample": args.resample, "analyze_args": args.analyze_args, "seeds": seeds, "shifts": shifts, "embark_seeds": embark_seeds,
                      "montages": str(out_dir), "exemplars": results, "summary": summary}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
