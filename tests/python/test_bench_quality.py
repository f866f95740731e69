"""bench/bench_quality.py's cut set: --shifts translates all four cuts together, and the
per-shift summary is the worst of four averaged over seeds."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import bench_quality as bq  # noqa: E402
from support import run_cli  # noqa: E402


def cut_pixels(table: Path, flags: list[str], out: Path, size: int = 12) -> np.ndarray:
    run_cli("slice", table, *flags, "--size", f"{size},{size}", "--seed", 3, "-o", out)
    return np.asarray(Image.open(out).convert("RGB")).astype(int)


def test_a_shift_translates_the_four_cuts_together(binary, cli_table, tmp_path):
    """Each cut of cut_set(d) starts at voxel (d, d, d): the z and y cuts share their first row
    (voxels (d + i, d, d)), the z cut's first column is the x cut's first row ((d, d + i, d)),
    the x and y cuts share their first column ((d, d, d + j)), and the oblique, sampled
    nearest, starts with that voxel too. A translation only along the cut axis, or none,
    breaks all but one of these."""
    for shift in (0, 5):
        cuts = {name: cut_pixels(cli_table, [str(f) for f in flags], tmp_path / f"{name}{shift}.png")
                for name, flags in bq.cut_set(shift, "nearest").items()}
        z, y, x, oblique = cuts["z"], cuts["y"], cuts["x"], cuts["oblique"]
        assert np.array_equal(z[0], y[0]), f"shift {shift}: z and y cuts do not share voxels (d+i, d, d)"
        assert np.array_equal(z[:, 0], x[0]), f"shift {shift}: z and x cuts do not share voxels (d, d+i, d)"
        assert np.array_equal(x[:, 0], y[:, 0]), f"shift {shift}: x and y cuts do not share voxels (d, d, d+j)"
        assert np.array_equal(oblique[0, 0], z[0, 0]), f"shift {shift}: the oblique does not pass through (d, d, d)"
        if shift == 0:
            unshifted_z = z
    assert not np.array_equal(unshifted_z, z), "a shift of 5 voxels left the z cut as it was"


def test_worst_by_shift_averages_each_shifts_worst_of_four_over_seeds():
    def cuts(*swd):
        return {name: {"swd": s} for name, s in zip(("z", "y", "x", "oblique"), swd)}

    samples = {(1, 0): cuts(0.1, 0.3, 0.2, 0.2), (2, 0): cuts(0.1, 0.1, 0.5, 0.2),
               (1, 24): cuts(0.2, 0.1, 0.1, 0.1), (2, 24): cuts(0.4, 0.1, 0.1, 0.1)}
    assert [bq.sample_key(*k) for k in samples] == ["1", "2", "1+24", "2+24"]
    worst = {k: bq.worst_of_four(c) for k, c in samples.items()}
    assert worst == {(1, 0): 0.3, (2, 0): 0.5, (1, 24): 0.2, (2, 24): 0.4}
    assert bq.worst_by_shift(worst) == {"0": 0.4, "24": 0.3}


def test_embark_runs_keep_seed_one_where_the_cache_had_it_and_average_into_the_denominator():
    assert bq.embark_key("bricks", 256, 1) == "bricks@256", "seed 1's key must stay the one older caches hold"
    keys = {bq.embark_key("bricks", 256, s) for s in (1, 2, 3)} | {bq.embark_key("bricks", 128, 2)}
    assert len(keys) == 4, "seeds and sizes must not share a cache entry"
    assert bq.embark_swd({1: {"swd": 0.13}, 2: {"swd": 0.12}, 3: {"swd": 0.11}}) == 0.12
