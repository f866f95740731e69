#!/usr/bin/env python3
"""Reference solids for the grain layouts (issue 12): what simple, perfectly coherent solids
built from a striped exemplar score on bench_quality's four cuts, scored the same way.

  bench_reference_solids.py [--size 256] [--exemplars a.png:x,b.png:y] [--embark-cache F]
                            [--sweep [--sweep-values 0.4,0.55,...]]

A grain layout (`solidtex analyze --grain x|y`) asks two planes for the stripes and the third
for the end grain, an image of E, too. No solid meets all three (docs/quality.md, "How the
grained solids are built"); this measures how close simple coherent solids come. Each
reference solid copies one exemplar pixel per voxel through a linear map of world (x, y, z) to
exemplar (column, row), so it is a voxel solid synthesis could in principle produce, with the
stripes perfectly coherent in 3D. E's stripes run along its columns for grain x, along its rows
for grain y; `across` is the world axis of the xy plane that crosses them (y for grain x, x for
grain y), and each solid says which exemplar coordinate across the stripes a voxel reads:

  extruded      E extruded along z: across. Ideal z cut only.
  sheets+45     sheets tilted 45 degrees between the two striped planes: across + z.
                Both striped cuts show E exactly; the end grain shows diagonal stripes.
  sheets-45     the other tilt: across - z.
  sheets+45/√2  sheets+45 with E's stripe spacing measured along the sheets' normal:
                (across + z)/√2; every axis cut shows stripes √2 wider.
  layers        sheets normal to z: z. The z cut is one stripe's colour.

--sweep scores a family instead, every tilt and spacing of the sheets on a grid: `tilted a,b,±`
reads across = a * across_axis + b * z and shifts the along-stripes coordinate by
±(b * across_axis - a * z), so the sheets' normal and spacing are (a, b) and the end grain
shows E turned and scaled rather than one exemplar column (a = 0, b = 1, +: the x cut of grain
x is E exactly and its z cut one stripe's colour; b = 0: extruded with a shear along the
stripes). With --sweep-values V the grid is V x V x {+, -}; the best solid is reported as for
the named ones.

Cuts and references are bench_quality's: z (xy plane, x right, y down), y (x right, z down), x
(y right, z down), each scored against the image its plane gets under the layout, oriented as the
cut (E, or E transposed where the grain runs across the cut); the oblique (bench_quality.OBLIQUE)
against E. Pixels are nearest (one exemplar pixel per voxel), so no cut is smoothed.

Prints one JSON document: per exemplar and solid, each cut's texmetric scores, the worst of the
four cuts' swd (over Embark's when --embark-cache, bench_quality's file, holds the exemplar) and
oblique / axis. Needs ../shared/tools/texmetric.py; default exemplars: the four shared grained
ones with the layouts `--grain auto` gives them.
"""
from __future__ import annotations

import argparse
import functools
import json
import re
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_quality import OBLIQUE, SHARED, axis_autocorrelation_gap, embark_key, oblique_over_axis, texmetric  # noqa: E402

DEFAULT_EXEMPLARS = "wood_grain.png:x,wood_planks.png:x,stripes_dunes.png:x,tree_bark.png:y"
_OBLIQUE = [float(c) for c in OBLIQUE.split(",")]
ORIGIN = tuple(_OBLIQUE[0:3])  # every cut passes through it
CUT_AXES = {  # pixel (i, j) of a cut is ORIGIN + i * u + j * v
    "z": ((1, 0, 0), (0, 1, 0)),
    "y": ((1, 0, 0), (0, 0, 1)),
    "x": ((0, 1, 0), (0, 0, 1)),
    "oblique": (tuple(_OBLIQUE[3:6]), tuple(_OBLIQUE[6:9])),
}
SQRT2 = float(np.sqrt(2.0))


def laid_map(grain: str, across_of, shift_of=None):
    """f(x, y, z) -> (exemplar column, exemplar row): the coordinate across E's stripes is
    across_of(across axis, z), the one along them the along axis plus shift_of(across axis, z).
    Grain x: E's stripes run along its columns' axis (x), across = y; grain y: across = x."""
    shift_of = shift_of or (lambda across, z: 0)
    if grain == "x":
        return lambda x, y, z: (x + shift_of(y, z), across_of(y, z))
    return lambda x, y, z: (across_of(x, z), y + shift_of(x, z))


def solid_maps(grain: str) -> dict:
    """Solid name -> f(x, y, z) -> (exemplar column, exemplar row), for a layout of `grain`."""
    laid = functools.partial(laid_map, grain)
    return {
        "extruded": laid(lambda across, z: across),
        "sheets+45": laid(lambda across, z: across + z),
        "sheets-45": laid(lambda across, z: across - z),
        "sheets+45/√2": laid(lambda across, z: (across + z) / SQRT2),
        "layers": laid(lambda across, z: z),
    }


def tilted_maps(grain: str, values: list[float]) -> dict:
    """--sweep's family: name -> map, sheets with normal and spacing (a, b) across the stripes
    and E's along-stripes coordinate sheared within them (module docstring)."""
    maps = {}
    for a in values:
        for b in values:
            for sign in (1, -1):
                maps[f"tilted {a:g},{b:g},{'+' if sign > 0 else '-'}"] = laid_map(
                    grain, lambda t, z, a=a, b=b: a * t + b * z, lambda t, z, a=a, b=b, s=sign: s * (b * t - a * z))
    return maps


def cut_references(exemplar: np.ndarray, grain: str) -> dict:
    """The image each axis cut is judged against (bench_quality, `solidtex slice --reference`):
    grain x lays xy = E, zx = E transposed, yz = E (end grain); grain y lays xy = E, yz = E
    transposed, zx = E (end grain). Axis y shows zx transposed; so grain x's y cut and x cut are
    judged against E, grain y's against E transposed."""
    across = exemplar.transpose(1, 0, 2)
    if grain == "x":
        return {"z": exemplar, "y": exemplar, "x": exemplar, "oblique": exemplar}
    return {"z": exemplar, "y": across, "x": across, "oblique": exemplar}


def render_cut(exemplar: np.ndarray, solid, u, v, size: int) -> np.ndarray:
    h, w, _ = exemplar.shape
    i, j = np.meshgrid(np.arange(size, dtype=np.float64), np.arange(size, dtype=np.float64))
    # Voxels first (a cut samples the nearest voxel), then the voxel's exemplar pixel.
    x, y, z = (np.rint(ORIGIN[k] + i * u[k] + j * v[k]) for k in range(3))
    col, row = solid(x, y, z)
    return exemplar[np.rint(row).astype(np.int64) % h, np.rint(col).astype(np.int64) % w]


def write_references(exemplar: np.ndarray, grain: str, tmp: Path, name: str) -> dict:
    """cut_references as PNGs in `tmp`, once per exemplar: cut -> path."""
    paths = {}
    for cut, image in cut_references(exemplar, grain).items():
        paths[cut] = tmp / f"{name}_{cut}_reference.png"
        Image.fromarray(image).save(paths[cut])
    return paths


def score_solid(python: str, exemplar: np.ndarray, solid, references: dict, size: int, tmp: Path, name: str) -> dict:
    """texmetric scores of the solid's four cuts (PNGs `tmp/{name}_{cut}.png`) against `references`."""
    cuts = {}
    for cut, (u, v) in CUT_AXES.items():
        image = tmp / f"{name}_{cut}.png"
        Image.fromarray(render_cut(exemplar, solid, u, v, size)).save(image)
        cuts[cut] = texmetric(python, image, references[cut])
    return cuts


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--exemplars", default=DEFAULT_EXEMPLARS,
                    help="comma-separated PATH:GRAIN (grain x or y); bare names are looked up in ../shared/data/exemplars")
    ap.add_argument("--embark-cache", type=Path, help="bench_quality's Embark scores file, for worst / Embark")
    ap.add_argument("--keep", type=Path, help="keep the cuts' PNGs in this directory")
    ap.add_argument("--sweep", action="store_true", help="score the tilted family (module docstring) instead of the named solids")
    ap.add_argument("--sweep-values", default="0.4,0.55,0.7,0.85,1,1.15,1.3",
                    help="comma-separated values of a and b for --sweep")
    args = ap.parse_args()
    if not (SHARED / "tools" / "texmetric.py").is_file():
        print(f"bench_reference_solids: {SHARED / 'tools' / 'texmetric.py'} not found", file=sys.stderr)
        return 2
    embark = json.loads(args.embark_cache.read_text()) if args.embark_cache and args.embark_cache.is_file() else {}
    out = []
    with tempfile.TemporaryDirectory() as scratch:
        tmp = args.keep or Path(scratch)
        tmp.mkdir(parents=True, exist_ok=True)
        for spec in args.exemplars.split(","):
            path_text, _, grain = spec.rpartition(":")
            if grain not in ("x", "y"):
                ap.error(f"--exemplars: {spec!r} needs a grain, PATH:x or PATH:y")
            path = Path(path_text)
            if not path.is_file():
                path = SHARED / "data" / "exemplars" / path_text
            exemplar = np.asarray(Image.open(path).convert("RGB"))
            entry = {"exemplar": path.stem, "grain": grain, "size": args.size,
                     "axis_autocorrelation_gap": axis_autocorrelation_gap(exemplar), "solids": {}}
            reference = embark.get(embark_key(path.stem, args.size, 1), {}).get("swd")
            references = write_references(exemplar, grain, tmp, path.stem)
            maps = tilted_maps(grain, [float(v) for v in args.sweep_values.split(",")]) if args.sweep else solid_maps(grain)
            for solid_name, solid in maps.items():
                cuts = score_solid(sys.executable, exemplar, solid, references, args.size, tmp,
                                   f"{path.stem}_{re.sub(r'[/ ,]', '_', solid_name)}")
                worst = max(c["swd"] for c in cuts.values())
                entry["solids"][solid_name] = {
                    "cuts": cuts,
                    "worst_swd": round(worst, 4),
                    "worst_swd_over_embark": round(worst / reference, 3) if reference else None,
                    "oblique_over_axis_swd": oblique_over_axis([cuts]),
                }
                print(f"{path.stem} grain {grain} {solid_name}: " + " ".join(f"{c}={cuts[c]['swd']:.3f}" for c in cuts)
                      + f" worst={worst:.3f}", file=sys.stderr)
            best = min(entry["solids"], key=lambda s: entry["solids"][s]["worst_swd"])
            entry["best_worst_swd"] = {"solid": best, "swd": entry["solids"][best]["worst_swd"],
                                       "over_embark": entry["solids"][best]["worst_swd_over_embark"]}
            out.append(entry)
    print(json.dumps({"size": args.size, "exemplars": out}, indent=1, ensure_ascii=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
