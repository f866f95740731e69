"""Neuroglancer itself opens a volume (issue #14): the PyPI neuroglancer package serves its
client on 127.0.0.1, Debian's chromium-headless-shell runs it (driven by Playwright from PyPI
through executable_path; WebGL on SwiftShader, no GPU), and a screenshot of the xy cross-section
of the RGB layer must show the voxels of that plane: non-black, the same mean colour as the
`region` endpoint's voxels there and an overlapping colour histogram, for the precomputed raw and
jpeg sources and the OME-Zarr (zarr3) source.

The view is zoomed to SCALE screen pixels per voxel around CENTER, so each voxel covers a block
of pixels; at those voxels' centres the screenshot is compared voxel by voxel as well (raw and
zarr exact up to a few rounding steps, jpeg within its loss), which fails on a shifted, mirrored
or transposed view that the colour statistics alone would pass."""
from __future__ import annotations

import io
import shutil
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from support import ServerFactory, upload_ready

neuroglancer = pytest.importorskip("neuroglancer", reason="neuroglancer is not installed (tests/python/requirements.txt)")
sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (tests/python/requirements.txt)")

CHROMIUM = Path(shutil.which("chromium-headless-shell") or "/usr/bin/chromium-headless-shell")
# SwiftShader: software WebGL, the same in CI as here (no GPU, no display).
CHROMIUM_ARGS = ["--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
                 "--no-sandbox"]
VIEW = 400          # viewport side, pixels
SCALE = 10          # screen pixels per voxel
CENTER = (32, 32)   # x, y of the view centre (a voxel corner)
Z = 5               # the voxel plane shown: z in [5, 6)
SHADER = "void main() { emitRGB(vec3(toNormalized(getDataValue(0)), toNormalized(getDataValue(1)), toNormalized(getDataValue(2)))); }"
LOAD_TIMEOUT = 60.0


@pytest.fixture(scope="module")
def chromium():
    if not CHROMIUM.is_file():
        pytest.skip(f"{CHROMIUM} is absent: install the Debian package chromium-headless-shell (scripts/deb-packages.txt)")
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        yield browser
        browser.close()


@pytest.fixture(scope="module")
def volume(tmp_path_factory, binary, exemplars):
    factory = ServerFactory(tmp_path_factory.mktemp("neuroglancer"))
    srv = factory.start("--array-extent", 64)
    ex = upload_ready(srv.client, exemplars["spots"])
    vid = srv.client.create_volume(exemplar=ex["id"], seed=5)["id"]
    yield srv, vid
    factory.close()


@pytest.fixture(scope="module")
def viewer():
    neuroglancer.set_server_bind_address("127.0.0.1")
    v = neuroglancer.Viewer()
    with v.config_state.txn() as c:  # the panel alone: no layer bar, no borders
        c.show_ui_controls = False
        c.show_panel_borders = False
        c.show_layer_panel = False
    yield v
    neuroglancer.stop()


def plane(srv, vid, x0, x1, y0, y1):
    """The region endpoint's sRGB voxels of plane Z, x in [x0, x1), y in [y0, y1): (y, x, 3)."""
    return srv.client.region(vid, (x0, y0, Z), (x1 - x0, y1 - y0, 1), fmt="uint8")[0]


def show(viewer, page, source, dims, unit):
    source_url = source
    console = []
    page.on("console", lambda m: console.append(m.text[:300]))
    """Opens `source` (global dimensions `dims`, voxels 1 `unit` wide) in the xy layout at SCALE
    pixels per voxel; returns the settled screenshot (VIEW, VIEW, 3) and the seconds it took."""
    with viewer.txn() as s:
        s.layers.clear()
        s.dimensions = neuroglancer.CoordinateSpace(names=list(dims), units=unit, scales=[1] * len(dims))
        s.display_dimensions = ["x", "y", "z"]
        if "zarr" in source:
            # Neuroglancer makes the OME channel axis a local dimension c' (one channel at a time);
            # renamed c^ it is a channel dimension, whose three values getDataValue(0..2) reads
            space = neuroglancer.CoordinateSpace(names=["c^", "z", "y", "x"], units="", scales=[1, 1, 1, 1])
            source = neuroglancer.LayerDataSource(url=source, transform=neuroglancer.CoordinateSpaceTransform(
                output_dimensions=space))
        s.layers["volume"] = neuroglancer.ImageLayer(source=source, shader=SHADER)
        s.layout = "xy"
        # precomputed voxel i spans [i, i + 1); OME-Zarr puts voxel centres on integers (i - 0.5, i + 0.5)
        corner = 0.0 if source_url.startswith("precomputed") else -0.5
        at = {"x": CENTER[0] + corner, "y": CENTER[1] + corner, "z": Z + 0.5 + corner}
        s.position = [at[d] for d in dims]
        s.cross_section_scale = 1 / SCALE
        s.show_axis_lines = False
        s.show_scale_bar = False
        s.show_default_annotations = False
    from PIL import Image
    start = time.monotonic()
    page.goto(viewer.get_viewer_url())
    # Neuroglancer answers a screenshot request once every visible chunk has loaded (coarser
    # scales are drawn while the finest ones are still being synthesized, seconds per chunk).
    loaded = threading.Event()
    viewer.async_screenshot(lambda reply: loaded.set())
    if not loaded.wait(LOAD_TIMEOUT):
        pytest.fail(f"{source}: Neuroglancer did not load the visible chunks within {LOAD_TIMEOUT} s; console: {console}")
    last = None
    while time.monotonic() - start < LOAD_TIMEOUT:
        shot = np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB"))
        inner = shot[VIEW // 4: 3 * VIEW // 4, VIEW // 4: 3 * VIEW // 4]
        if inner.max() > 40 and last is not None and np.array_equal(shot, last):  # non-black and drawn
            return shot, time.monotonic() - start
        last = shot
        time.sleep(0.2)
    pytest.fail(f"{source}: the panel stayed black for {LOAD_TIMEOUT} s; console: {console}")


def compare(shot, srv, vid, tolerance):
    """The screenshot against the voxels it shows: voxel i covers screen pixels
    [VIEW/2 + (i - CENTER) * SCALE, + SCALE) along x and y."""
    half = VIEW // (2 * SCALE)
    x0, y0 = CENTER[0] - half, CENTER[1] - half
    want = plane(srv, vid, x0, x0 + 2 * half, y0, y0 + 2 * half).astype(int)
    # the top-left corner holds the coordinate widget: compare the voxels of the inner region
    inner = slice(4, 2 * half - 1)
    centres = shot[SCALE // 2::SCALE, SCALE // 2::SCALE][: 2 * half, : 2 * half].astype(int)
    err = np.abs(centres[inner, inner] - want[inner, inner]).max(axis=-1)
    shown = shot[4 * SCALE: (2 * half - 1) * SCALE, 4 * SCALE: (2 * half - 1) * SCALE].reshape(-1, 3).astype(float)
    voxels = want[inner, inner].reshape(-1, 3).astype(float)
    assert shown.mean() > 20, "the panel is black"
    mean_gap = np.abs(shown.mean(axis=0) - voxels.mean(axis=0)).max()
    overlap = min(histogram_overlap(shown[:, c], voxels[:, c]) for c in range(3))
    matching = float((err <= tolerance).mean())
    return mean_gap, overlap, matching


def histogram_overlap(a, b):
    ha = np.histogram(a, bins=16, range=(0, 256))[0] / len(a)
    hb = np.histogram(b, bins=16, range=(0, 256))[0] / len(b)
    return float(np.minimum(ha, hb).sum())


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["precomputed", "precomputed-jpeg", "zarr3"])
def test_neuroglancer_shows_the_volume_s_voxels(chromium, viewer, volume, kind):
    srv, vid = volume
    base = f"{srv.url}/v1/volumes/{vid}"
    # precomputed voxels are nanometres (resolution 1); the OME-Zarr axes carry no unit
    # jpeg: quality 90 moves flat colours across histogram bins and edges by tens of levels
    source, dims, unit, tolerance, min_overlap = {
        "precomputed": (f"precomputed://{base}/precomputed", "xyz", "nm", 2, 0.9),
        "precomputed-jpeg": (f"precomputed://{base}/precomputed-jpeg", "xyz", "nm", 24, 0.6),
        "zarr3": (f"zarr3://{base}/zarr/", "zyx", "", 2, 0.9),
    }[kind]
    page = chromium.new_page(viewport={"width": VIEW, "height": VIEW})
    try:
        shot, seconds = show(viewer, page, source, dims, unit)
    finally:
        page.close()
    mean_gap, overlap, matching = compare(shot, srv, vid, tolerance)
    print(f"{kind}: settled in {seconds:.1f} s, mean colour gap {mean_gap:.2f}, histogram overlap {overlap:.3f}, "
          f"voxels within {tolerance}: {matching:.3f}")
    assert mean_gap < 6, mean_gap
    assert overlap > min_overlap, overlap
    assert matching > 0.9, matching
