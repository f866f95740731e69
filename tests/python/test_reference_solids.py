"""bench/bench_reference_solids.py: its solids are the 3D stripes they claim, its cuts are
bench_quality's, and texmetric sees what the geometry says (the end grain cannot match)."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

BENCH = Path(__file__).resolve().parents[2] / "bench"
sys.path.insert(0, str(BENCH))
import bench_quality as bq  # noqa: E402
import bench_reference_solids as refs  # noqa: E402


def striped_exemplar(across_rows: bool) -> np.ndarray:
    """32x24 RGB stripes of period 8 that vary down the rows (grain x) or across the columns
    (grain y), with per-pixel noise so that no two stripes' pixels are alike."""
    rng = np.random.default_rng(7)
    rows, cols = np.mgrid[0:24, 0:32]
    across = rows if across_rows else cols
    base = 128 + 90 * np.sin(2 * np.pi * across / 8.0)
    image = np.stack([base, 0.6 * base + 40, 255 - base], -1) + rng.normal(0, 12, (24, 32, 3))
    return np.clip(image, 0, 255).astype(np.uint8)


def tiled(image: np.ndarray, size: int) -> np.ndarray:
    h, w, _ = image.shape
    return np.tile(image, (size // h + 1, size // w + 1, 1))[:size, :size]


@pytest.mark.parametrize("grain", ["x", "y"])
def test_tilted_sheets_show_the_exemplar_on_both_striped_cuts_and_not_on_the_end_grain(grain):
    e = striped_exemplar(across_rows=grain == "x")
    sheets = refs.solid_maps(grain)["sheets+45"]
    references = refs.cut_references(e, grain)
    # The two striped planes: grain x stripes xy (z cut) and zx (y cut), grain y xy and yz (x cut).
    striped = ["z", "y"] if grain == "x" else ["z", "x"]
    end_grain = "x" if grain == "x" else "y"
    for cut in striped:
        u, v = refs.CUT_AXES[cut]
        image = refs.render_cut(e, sheets, u, v, 48)
        # The cut is the reference shifted (periodically): some offset matches it pixel for pixel.
        ref = references[cut]
        h, w, _ = ref.shape
        assert any(np.array_equal(image, tiled(np.roll(ref, (dy, dx), (0, 1)), 48)) for dy in range(h) for dx in range(w)), cut
    u, v = refs.CUT_AXES[end_grain]
    end = refs.render_cut(e, sheets, u, v, 48)
    # The end grain's stripes run diagonally: constant along one diagonal, not along the rows.
    assert np.array_equal(end[1:, :-1], end[:-1, 1:])
    assert not np.array_equal(end[:, 1:], end[:, :-1])


@pytest.mark.parametrize("grain", ["x", "y"])
def test_tilted_sheets_turn_the_exemplar_onto_the_end_grain_and_off_the_z_cut(grain):
    """--sweep's family at a = 0, b = 1: the sheets lie normal to z with E's along-stripes axis
    on the end-grain cut's other axis, so the end grain is its reference exactly and the z cut
    shows one exemplar line (a row for grain x, a column for grain y), sheared."""
    e = striped_exemplar(across_rows=grain == "x")
    maps = refs.tilted_maps(grain, [0.0, 1.0])
    assert len(maps) == 8
    end_grain = "x" if grain == "x" else "y"
    u, v = refs.CUT_AXES[end_grain]
    ref = refs.cut_references(e, grain)[end_grain]
    image = refs.render_cut(e, maps["tilted 0,1,+"], u, v, 48)
    h, w, _ = ref.shape
    assert any(np.array_equal(image, tiled(np.roll(ref, (dy, dx), (0, 1)), 48)) for dy in range(h) for dx in range(w))
    u, v = refs.CUT_AXES["z"]
    z_cut = refs.render_cut(e, maps["tilted 0,1,+"], u, v, 48)
    assert np.array_equal(z_cut[1:, :-1], z_cut[:-1, 1:])  # each row the previous one shifted by one
    assert not np.array_equal(z_cut[1:], z_cut[:-1])
    # The other sign turns the end grain the other way: not the reference.
    turned = refs.render_cut(e, maps["tilted 0,1,-"], *refs.CUT_AXES[end_grain], 48)
    assert not any(np.array_equal(turned, tiled(np.roll(ref, (dy, dx), (0, 1)), 48)) for dy in range(h) for dx in range(w))


def test_texmetric_scores_the_end_grain_of_sheets_far_from_their_striped_cuts(tmp_path):
    if not (refs.SHARED / "tools" / "texmetric.py").is_file():
        pytest.skip(f"{refs.SHARED / 'tools' / 'texmetric.py'} not found: needs ../shared")
    e = striped_exemplar(across_rows=True)
    references = refs.write_references(e, "x", tmp_path, "stripes")
    sheets = refs.score_solid(sys.executable, e, refs.solid_maps("x")["sheets+45"], references, 64, tmp_path, "sheets")
    extruded = refs.score_solid(sys.executable, e, refs.solid_maps("x")["extruded"], references, 64, tmp_path, "extruded")
    assert sheets["z"]["swd"] < 0.15 and sheets["y"]["swd"] < 0.15, sheets
    assert sheets["x"]["swd"] > 2 * max(sheets["z"]["swd"], sheets["y"]["swd"]), sheets
    # Extruded along z, the y cut is one stripe colour per row: the stripes are gone.
    assert extruded["y"]["swd"] > 2 * extruded["z"]["swd"], extruded
    assert Image.open(tmp_path / "sheets_oblique.png").size == (64, 64)


def test_one_world_axis_carries_two_cuts_and_the_gap_says_what_that_costs():
    """The argument behind axis_autocorrelation_gap, on the bench's own cut conventions: under
    either layout, one world axis is the reference's u axis in one cut and its v axis in the
    other, so every (stationary) solid misses one of the two by at least half the gap."""
    e = striped_exemplar(across_rows=True)
    gap = bq.axis_autocorrelation_gap(e, max_lag=8)
    assert gap > 1.0
    assert bq.axis_autocorrelation_gap(e.transpose(1, 0, 2), max_lag=8) == gap
    noise = np.random.default_rng(3).integers(0, 256, (64, 64, 3))
    assert bq.axis_autocorrelation_gap(noise, max_lag=8) < 0.1
    # (cut, its axis that is world `shared`): grain x shares y between the z cut's rows (v) and
    # the x cut's columns (u); grain y shares x between the z cut's columns and the y cut's.
    shared = {"x": (("z", "v"), ("x", "u")), "y": (("z", "u"), ("y", "u"))}
    size = 96  # a multiple of the exemplar's periods, so that integer-map solids tile the cut
    for grain, pair in shared.items():
        e = striped_exemplar(across_rows=grain == "x")
        references = refs.cut_references(e, grain)
        # The reference's profile along each cut's shared axis: per layout, not per solid.
        wanted = {cut: bq.axis_autocorrelations(references[cut], 8)[0 if axis == "u" else 1] for cut, axis in pair}
        solids = refs.solid_maps(grain)
        for name in ("extruded", "sheets+45", "sheets-45", "layers"):
            profiles, misses = [], []
            for cut, axis in pair:
                u, v = refs.CUT_AXES[cut]
                along_u, along_v = bq.axis_autocorrelations(refs.render_cut(e, solids[name], u, v, size), 8)
                profiles.append(along_u if axis == "u" else along_v)
                misses.append(np.abs(profiles[-1] - wanted[cut]).max())
            # The same world axis: equal up to the cuts being finite samples of the solid.
            np.testing.assert_allclose(profiles[0], profiles[1], atol=0.05, err_msg=f"{grain} {name}")
            assert max(misses) >= gap / 2, (grain, name, misses, gap)
