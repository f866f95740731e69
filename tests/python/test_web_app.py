"""The browser app (issue #15) in headless Chromium: Debian's chromium-headless-shell driven by
Playwright from PyPI (executable_path; SwiftShader WebGL, as test_neuroglancer.py), the app
served by the same `solidtex serve` from web/. Every page must load and run without a console
error or an uncaught exception, and:
- an exemplar uploaded in the page is analysed with visible progress, a volume created in the
  page shows its first cut coarse to fine, and the canvas then holds exactly the slice
  endpoint's pixels;
- a cached cut appears (the time to its first pixels is measured and reported, not asserted:
  speed targets are the benchmarks' to check); pans, zooms and oblique cuts show the slice and
  cut endpoints' pixels exactly;
- a curve drawn with the mouse adds a field revision and shows a new volume whose cut differs;
  an undo whose request fails changes nothing (the page says why); undo brings back the earlier
  cut, pixel for pixel, and the field's earlier revision; strokes name the revision the page
  shows, so a field changed elsewhere refuses them; the page shows volumes without asking for
  their exemplar (a pyramid's datasets come from the volume's zarr.json);
- the mesh view draws a textured mesh (non-background, varied colours) and orbits it.
Cuts are 64² (32² after a zoom) of small analyses so that the file runs in about half a minute."""
from __future__ import annotations

import io
import json
import math
import re
import shutil
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import requests

from support import RAW, upload_ready

sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (tests/python/requirements.txt)")

CHROMIUM = Path(shutil.which("chromium-headless-shell") or "/usr/bin/chromium-headless-shell")
CHROMIUM_ARGS = ["--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
                 "--no-sandbox"]
SIZE = 64           # finest voxels per side of the cuts (8 CSS pixels per voxel)
VIEW = 512          # CSS pixels per side of the cut panel (web/style.css --view)
WAIT_MS = 60_000
# The stored field the sketch test draws on: one curve along x through the view's middle.
FIELD = {"domain": {"min": [-16, -16, -12], "max": [144, 144, 20], "shortest_side_cells": 4},
         "curves": [{"points": [[8, 64, 3], [64, 60, 3], [120, 64, 3]], "plane_normal": [0, 0, 1], "axis": "x"}]}


def sphere_off(rings=12, segments=24, radius=1.0):
    """A UV sphere as OFF text (poles plus rings x segments vertices)."""
    verts = [(0.0, 0.0, radius)]
    for r in range(1, rings):
        theta = math.pi * r / rings
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            verts.append((radius * math.sin(theta) * math.cos(phi), radius * math.sin(theta) * math.sin(phi),
                          radius * math.cos(theta)))
    verts.append((0.0, 0.0, -radius))
    ring = lambda r, s: 1 + (r - 1) * segments + s % segments  # noqa: E731
    faces = [(0, ring(1, s), ring(1, s + 1)) for s in range(segments)]
    for r in range(1, rings - 1):
        for s in range(segments):
            faces.append((ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)))
            faces.append((ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)))
    last = len(verts) - 1
    faces += [(last, ring(rings - 1, s + 1), ring(rings - 1, s)) for s in range(segments)]
    lines = ["OFF", f"{len(verts)} {len(faces)} 0"] + [f"{x:.6f} {y:.6f} {z:.6f}" for x, y, z in verts]
    lines += [f"3 {a} {b} {c}" for a, b, c in faces]
    return ("\n".join(lines) + "\n").encode()


@pytest.fixture(scope="module")
def chromium():
    if not CHROMIUM.is_file():
        pytest.skip(f"{CHROMIUM} is absent: install the Debian package chromium-headless-shell (scripts/deb-packages.txt)")
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        yield browser
        browser.close()


@pytest.fixture(scope="module")
def app(shared):
    """The shared server with a stored field (revision 1), a volume of it and a sphere mesh."""
    c = shared.client
    field = c.create_field(FIELD)
    # One coarse pass: a stored (varying) field's cuts cost about 4x an identity field's, and the
    # app copies these params into the volumes it makes from strokes.
    volume = requests.post(shared.url + "/v1/volumes", timeout=60, json={
        "exemplar": shared.exemplar_id, "field": {"id": field["id"]}, "seed": 3, "params": {"coarse_passes": 1}})
    assert volume.status_code == 201, volume.text
    volume = volume.json()
    mesh = requests.post(shared.url + "/v1/meshes", params={"name": "sphere"}, data=sphere_off(),
                         headers={"Content-Type": "application/octet-stream"}, timeout=60)
    assert mesh.status_code == 201, mesh.text
    return SimpleNamespace(url=shared.url, client=c, exemplar=shared.exemplar, field_id=field["id"],
                           volume_id=volume["id"], mesh_id=mesh.json()["id"])


class AppPage:
    """A page of the app with its console errors and uncaught exceptions collected."""

    def __init__(self, browser, url):
        self.url = url
        self.page = browser.new_page(viewport={"width": 1280, "height": 900})
        self.errors = []
        self.page.on("console", lambda m: m.type == "error" and self.errors.append(f"console: {m.text}"))
        self.page.on("pageerror", lambda e: self.errors.append(f"pageerror: {e}"))

    def open(self, **view):
        self.page.goto(self.url + "/#" + "&".join(f"{k}={v}" for k, v in view.items()))

    def wait_cut(self, volume=None, not_volume=None):
        """Waits for the finest cut of `volume` (or of any volume but `not_volume`)."""
        self.page.wait_for_function(
            """([volume, notVolume]) => {
                 const panel = document.getElementById('cut-panel'), canvas = document.getElementById('cut-canvas');
                 if (panel.dataset.state === 'error') return true;
                 const v = canvas.dataset.volume;
                 return panel.dataset.state === 'done' && v && (!volume || v === volume) && v !== notVolume;
               }""",
            arg=[volume, not_volume], timeout=WAIT_MS)
        state = self.page.get_attribute("#cut-panel", "data-state")
        assert state == "done", self.page.text_content("#cut-status")
        return self.page.get_attribute("#cut-canvas", "data-volume")

    def request(self):
        return json.loads(self.page.get_attribute("#cut-canvas", "data-request"))

    def pixels(self):
        """The cut canvas's pixels, (H, W, 3) uint8."""
        data = self.page.evaluate("""() => {
            const c = document.getElementById('cut-canvas');
            const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
            return {w: c.width, h: c.height, rgba: Array.from(d)};
        }""")
        rgba = np.array(data["rgba"], np.uint8).reshape(data["h"], data["w"], 4)
        assert (rgba[..., 3] == 255).all()
        return rgba[..., :3]

    def endpoint_pixels(self, volume_id, request):
        base = f"{self.url}/v1/volumes/{volume_id}"
        if request["kind"] == "slice":
            r = requests.get(base + "/slice", headers=RAW, timeout=120,
                             params={"axis": request["axis"], "at": request["at"], "size": "{},{}".format(*request["size"]),
                                     "origin": "{},{}".format(*request["origin"])})
        else:
            r = requests.post(base + "/cut", headers=RAW, timeout=120,
                              json={k: request[k] for k in ("origin", "u", "v", "size")})
        assert r.status_code == 200, r.text
        h, w, _ = map(int, r.headers["X-Shape"].split(","))
        return np.frombuffer(r.content, np.uint8).reshape(h, w, 3)

    def drag(self, selector, points):
        """A left-button drag through `points` (fractions of the element's box)."""
        box = self.page.locator(selector).bounding_box()
        at = [(box["x"] + fx * box["width"], box["y"] + fy * box["height"]) for fx, fy in points]
        self.page.mouse.move(*at[0])
        self.page.mouse.down()
        for x, y in at[1:]:
            self.page.mouse.move(x, y, steps=4)
        self.page.mouse.up()

    def close(self):
        self.page.close()
        assert not self.errors, self.errors


@pytest.fixture
def app_page(chromium, app):
    page = AppPage(chromium, app.url)
    yield page
    page.close()


def test_upload_analyse_create_and_see_the_slice_endpoints_pixels(app_page, app, exemplars):
    p = app_page
    p.open(volume=app.volume_id, cz=3, size=SIZE)  # the cut the next tests show, cached by this one
    p.wait_cut(app.volume_id)
    page = p.page
    page.set_input_files("#exemplar-file", str(exemplars["spots"]))
    page.click("#analysis-details summary")
    # levels stays at auto, the form's default: 64^2 with N = 5 resolves to 3 (auto_levels)
    assert page.input_value("#analysis-levels") == "auto"
    for field, value in (("neighborhood", 5), ("candidates", 4), ("pca-dims", 8)):
        page.fill(f"#analysis-{field}", str(value))
    page.click("#exemplar-upload")
    page.wait_for_function("() => document.getElementById('analysis-status').textContent.includes('ready')", timeout=WAIT_MS)
    assert page.get_attribute("#analysis-progress", "hidden") is None
    assert page.eval_on_selector("#analysis-progress", "e => e.value") == 100
    exemplar_id = page.input_value("#volume-exemplar")
    exemplar = app.client.get_exemplar(exemplar_id)
    assert exemplar["name"] == "spots.png" and exemplar["state"] == "ready" and exemplar["params"]["levels"] == 3
    before = page.get_attribute("#cut-canvas", "data-volume")
    page.click("#volume-new summary")
    page.select_option("#volume-field", "identity")
    page.fill("#volume-seed", "2")
    page.click("#volume-create")
    vid = p.wait_cut(not_volume=before)
    volume = app.client.get_volume(vid)
    assert volume["exemplars"] == [exemplar_id] and volume["seed"] == 2 and volume["field"]["kind"] == "identity"
    # coarse to fine: dataset 2 of the 3-level pyramid, then the finest, each request's voxel count shown
    levels = page.locator("#cut-levels li").all_text_contents()
    assert [t.split(":")[0] for t in levels] == ["dataset 2", "dataset 0"], levels
    assert all("voxels synthesized" in t for t in levels) and f"{SIZE // 4}×{SIZE // 4} px" in levels[0]
    request = p.request()
    assert request == {"kind": "slice", "axis": "z", "at": 3, "origin": [0, 0], "size": [SIZE, SIZE]}
    shown = p.pixels()
    assert np.array_equal(shown, p.endpoint_pixels(vid, request))
    assert shown.std() > 5  # a texture, not a flat fill
    # every level on request: the same finest pixels after dataset 1 too
    page.check("#cut-every-level")
    page.wait_for_function("() => document.querySelectorAll('#cut-levels li').length === 3", timeout=WAIT_MS)
    p.wait_cut(vid)
    assert [t.split(":")[0] for t in page.locator("#cut-levels li").all_text_contents()] == \
        ["dataset 2", "dataset 1", "dataset 0"]
    assert np.array_equal(p.pixels(), shown)


def test_a_cached_cut_appears_and_pans_zooms_and_oblique_cuts_are_exact(app_page, app, record_property):
    p = app_page
    app.client.slice(app.volume_id, "z", 3, (SIZE, SIZE))  # cache the finest cut
    p.open(volume=app.volume_id, axis="z", cx=SIZE // 2, cy=SIZE // 2, cz=3, size=SIZE)
    p.wait_cut(app.volume_id)
    marks = p.page.evaluate("""() => Object.fromEntries(['solidtex:first-cut', 'solidtex:cut-done']
                                 .map(n => [n, performance.getEntriesByName(n)[0].startTime]))""")
    # Measured, not asserted (a loaded CI machine would make a time limit flaky); the wait above
    # bounds it at WAIT_MS.
    print(f"cached {SIZE}² cut: first pixels {marks['solidtex:first-cut']:.0f} ms, finest {marks['solidtex:cut-done']:.0f} ms "
          "after navigation start")
    record_property("cached_cut_first_pixels_ms", round(marks["solidtex:first-cut"]))
    record_property("cached_cut_finest_ms", round(marks["solidtex:cut-done"]))
    request = p.request()
    assert request == {"kind": "slice", "axis": "z", "at": 3, "origin": [0, 0], "size": [SIZE, SIZE]}
    assert np.array_equal(p.pixels(), p.endpoint_pixels(app.volume_id, request))

    # pan: dragging by (-1/8, -1/16) of the panel moves the view by (SIZE/8, SIZE/16) voxels
    p.drag("#cut-stage", [(0.5, 0.5), (0.375, 0.4375)])
    p.page.wait_for_function(f"() => JSON.parse(document.getElementById('cut-canvas').dataset.request).origin[0] === {SIZE // 8}")
    p.wait_cut(app.volume_id)
    request = p.request()
    centre = (SIZE // 2 + SIZE // 8, SIZE // 2 + SIZE // 16)
    assert request["origin"] == [SIZE // 8, SIZE // 16], request
    assert np.array_equal(p.pixels(), p.endpoint_pixels(app.volume_id, request))

    # zoom in: half the voxels per side around the same centre
    p.page.click("#zoom-in")
    p.page.wait_for_function(f"() => document.getElementById('cut-canvas').width === {SIZE // 2}")
    p.wait_cut(app.volume_id)
    request = p.request()
    assert request == {"kind": "slice", "axis": "z", "at": 3, "origin": [centre[0] - SIZE // 4, centre[1] - SIZE // 4],
                       "size": [SIZE // 2, SIZE // 2]}
    assert np.array_equal(p.pixels(), p.endpoint_pixels(app.volume_id, request))

    # oblique: yaw 30, pitch 20 through the same centre
    p.page.check('input[name="cut-mode"][value="oblique"]')
    p.page.wait_for_function("() => JSON.parse(document.getElementById('cut-canvas').dataset.request).kind === 'cut'")
    p.wait_cut(app.volume_id)
    request = p.request()
    u, v, origin = (np.array(request[k]) for k in ("u", "v", "origin"))
    yaw, pitch = np.radians(30), np.radians(20)
    normal = np.array([np.cos(pitch) * np.cos(yaw), np.cos(pitch) * np.sin(yaw), np.sin(pitch)])
    assert np.allclose([u @ u, v @ v, u @ v, u @ normal, v @ normal], [1, 1, 0, 0, 0], atol=1e-9)
    assert np.allclose(origin + SIZE // 4 * (u + v), [*centre, 3], atol=1e-9)
    assert np.array_equal(p.pixels(), p.endpoint_pixels(app.volume_id, request))


def error_body(status, message):
    """A route answer in the service's error form."""
    return {"status": status, "content_type": "application/json",
            "body": json.dumps({"error": {"code": "test", "message": message, "field": ""}})}


def test_a_curve_drawn_with_the_mouse_adds_a_revision_and_undo_restores_the_cut(app_page, app):
    p, c = app_page, app.client
    # No GET /v1/exemplars/{id} is needed to show a volume (as if its exemplar were gone): the
    # pyramid's datasets come from the volume's zarr.json.
    exemplar_gets = []
    p.page.route(re.compile(r".*/v1/exemplars/[^/?#]+$"),
                 lambda route: (exemplar_gets.append(route.request.url), route.fulfill(**error_body(404, "no exemplar"))))
    p.open(volume=app.volume_id, axis="z", cx=SIZE // 2, cy=SIZE // 2, cz=3, size=SIZE)
    p.wait_cut(app.volume_id)
    zarr = requests.get(f"{app.url}/v1/volumes/{app.volume_id}/zarr/zarr.json", timeout=60).json()
    coarsest = min(len(zarr["attributes"]["ome"]["multiscales"][0]["datasets"]) - 1, 4)  # 64 / 2^4 = 4 px
    assert p.page.locator("#cut-levels li").first.text_content().startswith(f"dataset {coarsest}:")
    before = p.pixels()
    revision = c.get_field(app.field_id)["revision"]
    file_before = requests.get(f"{app.url}/v1/fields/{app.field_id}/file", timeout=60).content
    assert p.page.get_attribute("#sketch-status", "data-revision") == str(revision)

    p.page.check("#sketch-mode")
    p.page.select_option("#sketch-axis", "y")
    p.drag("#cut-stage", [(0.2, 0.15), (0.35, 0.4), (0.4, 0.6), (0.3, 0.85)])
    vid = p.wait_cut(not_volume=app.volume_id)
    field = c.get_field(app.field_id)
    assert field["revision"] == revision + 1 and field["curves"] == 2
    made = c.get_volume(vid)
    assert made["field"] == {"kind": "stored", "id": app.field_id, "revision": revision + 1}
    assert made["params"] == c.get_volume(app.volume_id)["params"] and made["params"]["coarse_passes"] == 1
    assert p.page.get_attribute("#sketch-status", "data-revision") == str(revision + 1)
    after = p.pixels()
    assert np.array_equal(after, p.endpoint_pixels(vid, p.request()))
    changed = (after != before).any(axis=-1).mean()
    assert changed > 0.2, changed

    # an undo whose request fails changes nothing: the stroke's volume stays shown and its undo
    # entry stays (undo can be tried again), and the page says why
    p.page.route(re.compile(r".*/curves/last(\?.*)?$"), lambda route: route.fulfill(**error_body(503, "test: refused")))
    p.page.click("#sketch-undo")
    p.page.wait_for_function("() => document.getElementById('message').textContent.includes('test: refused')",
                             timeout=WAIT_MS)
    p.page.wait_for_function("() => !document.getElementById('sketch-undo').disabled", timeout=WAIT_MS)
    assert p.page.get_attribute("#cut-canvas", "data-volume") == vid
    assert p.page.get_attribute("#sketch-status", "data-revision") == str(revision + 1)
    assert c.get_field(app.field_id)["revision"] == revision + 1
    assert requests.get(f"{app.url}/v1/volumes/{vid}", timeout=60).status_code == 200
    p.page.unroute(re.compile(r".*/curves/last(\?.*)?$"))
    # the browser logs the refused request itself: that one console error is expected
    refused = [e for e in p.errors if "status of 503" in e]
    assert len(refused) == 1, p.errors
    p.errors.remove(refused[0])

    p.page.click("#sketch-undo")
    p.wait_cut(app.volume_id)
    assert np.array_equal(p.pixels(), before)
    assert c.get_field(app.field_id)["revision"] == revision + 2
    assert requests.get(f"{app.url}/v1/fields/{app.field_id}/file", timeout=60).content == file_before
    assert requests.get(f"{app.url}/v1/volumes/{vid}", timeout=60).status_code == 404
    assert p.page.is_disabled("#sketch-undo")
    assert exemplar_gets == []

    # The page names the field revision it shows (?revision=): after the undo, the one the undo
    # made (the curves of the volume's copy). A field moved on elsewhere refuses its next stroke
    # and changes nothing.
    assert p.page.get_attribute("#sketch-status", "data-revision") == str(revision + 2)
    c.add_curve(app.field_id, {"points": [[8, 20, 3], [120, 24, 3]], "plane_normal": [0, 0, 1], "axis": "x"})
    p.drag("#cut-stage", [(0.2, 0.15), (0.35, 0.4), (0.4, 0.6), (0.3, 0.85)])
    p.page.wait_for_function("() => document.getElementById('message').textContent.includes('changed since')",
                             timeout=WAIT_MS)
    assert f"not {revision + 2}" in p.page.text_content("#message")
    assert c.get_field(app.field_id)["revision"] == revision + 3
    assert p.page.get_attribute("#cut-canvas", "data-volume") == app.volume_id
    assert p.page.is_disabled("#sketch-undo")
    refused = [e for e in p.errors if "status of 409" in e]
    assert len(refused) == 1, p.errors
    p.errors.remove(refused[0])


def test_the_mesh_view_renders_and_orbits_a_textured_mesh(app_page, app):
    from PIL import Image
    p = app_page
    p.open(volume=app.volume_id, axis="z", cz=3, size=SIZE)
    p.wait_cut(app.volume_id)
    p.page.select_option("#mesh-select", app.mesh_id)
    p.page.fill("#mesh-resolution", "64")
    p.page.click("#mesh-show")
    p.page.wait_for_function("() => ['done', 'error'].includes(document.getElementById('mesh-panel').dataset.state)",
                             timeout=WAIT_MS)
    assert p.page.get_attribute("#mesh-panel", "data-state") == "done", p.page.text_content("#mesh-status")

    def shot():
        time.sleep(0.2)  # the draw is scheduled on the next animation frame
        return np.asarray(Image.open(io.BytesIO(p.page.locator("#mesh-canvas").screenshot())).convert("RGB")).astype(int)

    first = shot()
    background = np.array([28, 31, 36])  # mesh_view.js BACKGROUND
    covered = np.abs(first - background).max(axis=-1) > 12
    print(f"mesh view: {covered.mean():.2f} of the canvas covered")
    assert covered.mean() > 0.1, covered.mean()
    assert first[covered].std(axis=0).max() > 5  # textured and lit, not one flat colour
    p.drag("#mesh-canvas", [(0.5, 0.5), (0.8, 0.45)])
    assert not np.array_equal(shot(), first)
