"""What the browser app (issue #15) needs from the service, over plain HTTP: its files served at
/ and /web/{file} (types, ETag and 304, nothing outside the web root), cuts of a coarser pyramid
dataset (`scale` on slice and cut: the same voxels as the array views' datasets), and undo of
a field's last curve (DELETE /v1/fields/{id}/curves/last)."""
from __future__ import annotations

import subprocess

import numpy as np
import pytest
import requests
from solidtex_client import Conflict

from support import RAW, REPO, assert_error, solidtex_bin

SKETCH = {"domain": {"min": [-8, -8, -8], "max": [40, 40, 24], "shortest_side_cells": 6},
          "curves": [{"points": [[0, 4, 8], [16, 12, 8], [30, 4, 8]], "plane_normal": [0, 0, 1], "axis": "x"}]}
CURVE2 = {"points": [[2, 30, 4], [30, 20, 4]], "plane_normal": [0, 0, 1], "axis": "x"}
CURVE3 = {"points": [[4, 2, 12], [4, 30, 12]], "plane_normal": [0, 0, 1], "axis": "y"}


def raw_cut(response):
    assert response.status_code == 200, response.text
    h, w, c = map(int, response.headers["X-Shape"].split(","))
    return np.frombuffer(response.content, np.uint8).reshape(h, w, c)


def test_the_app_is_served_from_the_web_root(shared):
    url = shared.url
    page = requests.get(url + "/", timeout=30)
    assert page.status_code == 200
    assert page.headers["Content-Type"] == "text/html; charset=utf-8"
    assert page.content == (REPO / "web" / "index.html").read_bytes()
    assert page.headers["Cache-Control"] == "no-cache"
    etag = page.headers["ETag"]
    assert etag.startswith('"') and etag.endswith('"')
    # revalidation: 304 without a body, the same ETag
    again = requests.get(url + "/", headers={"If-None-Match": etag}, timeout=30)
    assert again.status_code == 304 and again.content == b"" and again.headers["ETag"] == etag
    head = requests.head(url + "/web/app.js", timeout=30)
    assert head.status_code == 200 and head.content == b""
    assert head.headers["Content-Type"] == "text/javascript; charset=utf-8"
    assert int(head.headers["Content-Length"]) == (REPO / "web" / "app.js").stat().st_size
    for name, kind in (("style.css", "text/css; charset=utf-8"), ("cut_view.js", "text/javascript; charset=utf-8")):
        r = requests.get(f"{url}/web/{name}", timeout=30)
        assert r.status_code == 200 and r.headers["Content-Type"] == kind
        assert r.content == (REPO / "web" / name).read_bytes()


def test_nothing_outside_the_web_root_is_served(shared):
    url = shared.url
    for path in ("/web/missing.js", "/web/..%2FREADME.md", "/web/%2e%2e", "/web/.hidden", "/web/../README.md",
                 "/web/sub/app.js", "/index.html", "/web/"):
        r = requests.get(url + path, timeout=30)
        assert r.status_code == 404, (path, r.status_code, r.text[:200])
    assert_error(requests.get(url + "/web/missing.js", timeout=30), 404, "not_found", "path")
    assert_error(requests.get(url + "/?x=1", timeout=30), 400, "invalid_argument", "x")
    assert_error(requests.post(url + "/", timeout=30), 405, "method_not_allowed")


def test_a_web_root_without_an_index_stops_the_server_naming_the_flag(binary, tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    proc = subprocess.run([str(solidtex_bin()), "serve", "--port", "1", "--data", str(tmp_path / "data"),
                           "--web-root", str(empty)], capture_output=True, text=True, timeout=30)
    assert proc.returncode != 0 and "--web-root" in proc.stderr, proc.stderr
    # an index.html that is a symbolic link would never be served (no link is): refused as well
    linked = tmp_path / "linked"
    linked.mkdir()
    (linked / "index.html").symlink_to(REPO / "web" / "index.html")
    proc = subprocess.run([str(solidtex_bin()), "serve", "--port", "1", "--data", str(tmp_path / "data"),
                           "--web-root", str(linked)], capture_output=True, text=True, timeout=30)
    assert proc.returncode != 0 and "--web-root" in proc.stderr and "symbolic link" in proc.stderr, proc.stderr


def test_coarser_datasets_are_the_array_views_voxels(shared):
    url, vid = shared.url, shared.volume_id
    levels = shared.exemplar["params"]["levels"]
    base = f"{url}/v1/volumes/{vid}"
    for scale in range(levels):
        # dataset s of the precomputed view: the plane z = 3 of x, y in [0, 16) (c, z, y, x)
        chunk = requests.get(f"{base}/precomputed/{scale}/0-16_0-16_3-4", timeout=120)
        assert chunk.status_code == 200, chunk.text
        want = np.frombuffer(chunk.content, np.uint8).reshape(3, 16, 16).transpose(1, 2, 0)
        got = raw_cut(requests.get(f"{base}/slice", params={"axis": "z", "at": 3, "size": "16,16", "scale": scale},
                                   headers=RAW, timeout=120))
        assert np.array_equal(got, want), scale
        # the same plane as a plane cut at that dataset
        cut = raw_cut(requests.post(f"{base}/cut", params={"scale": scale}, headers=RAW, timeout=120,
                                    json={"origin": [0, 0, 3], "u": [1, 0, 0], "v": [0, 1, 0], "size": [16, 16]}))
        assert np.array_equal(cut, want), scale
    # a coarse dataset is its own level, not the finest one again
    finest = raw_cut(requests.get(f"{base}/slice", params={"axis": "z", "at": 0, "size": "16,16"}, headers=RAW, timeout=120))
    coarse = raw_cut(requests.get(f"{base}/slice", params={"axis": "z", "at": 0, "size": "16,16", "scale": levels - 1},
                                  headers=RAW, timeout=120))
    assert not np.array_equal(finest, coarse)
    # scale 0 is the default
    zero = raw_cut(requests.get(f"{base}/slice", params={"axis": "z", "at": 0, "size": "16,16", "scale": 0},
                                headers=RAW, timeout=120))
    assert np.array_equal(zero, finest)


def test_scale_outside_the_pyramid_is_refused_naming_it(shared):
    base = f"{shared.url}/v1/volumes/{shared.volume_id}"
    levels = shared.exemplar["params"]["levels"]
    err = assert_error(requests.get(f"{base}/slice", params={"axis": "z", "at": 0, "size": "8,8", "scale": levels},
                                    timeout=60), 404, "not_found", "scale")
    assert f"0..{levels - 1}" in err["message"]
    for bad in ("-1", "8", "x", "1.5"):
        assert_error(requests.get(f"{base}/slice", params={"axis": "z", "at": 0, "size": "8,8", "scale": bad}, timeout=60),
                     400, "invalid_argument", "scale")
    assert_error(requests.post(f"{base}/cut", params={"scale": levels}, timeout=60,
                               json={"origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0], "size": [8, 8]}),
                 404, "not_found", "scale")


def test_undo_restores_the_revision_before_the_curve_bit_for_bit(shared):
    c, url = shared.client, shared.url
    fid = c.create_field(SKETCH)["id"]
    r1 = requests.get(f"{url}/v1/fields/{fid}/file", timeout=60).content
    assert c.add_curve(fid, CURVE2)["revision"] == 2
    r2 = requests.get(f"{url}/v1/fields/{fid}/file", timeout=60).content
    undone = requests.delete(f"{url}/v1/fields/{fid}/curves/last", timeout=60)
    assert undone.status_code == 200, undone.text
    info = undone.json()
    assert info["id"] == fid and info["revision"] == 3 and info["curves"] == 1
    assert c.get_field(fid)["revision"] == 3
    r3 = requests.get(f"{url}/v1/fields/{fid}/file", timeout=60).content
    assert r3 == r1 and r3 != r2
    # a curve added after the undo builds on the sketch without the removed one
    added = c.add_curve(fid, CURVE3)
    assert added["revision"] == 4 and added["curves"] == 2
    # back to one curve, which cannot be removed (the sketch would be empty)
    assert requests.delete(f"{url}/v1/fields/{fid}/curves/last", timeout=60).status_code == 200
    assert_error(requests.delete(f"{url}/v1/fields/{fid}/curves/last", timeout=60), 409, "failed_precondition", "curves")
    assert c.get_field(fid)["revision"] == 5
    assert_error(requests.delete(f"{url}/v1/fields/fld_nothing/curves/last", timeout=60), 404, "not_found", "id")


def test_undo_of_a_curve_never_stored_without_it_solves_afresh(shared):
    c, url = shared.client, shared.url
    two = dict(SKETCH, curves=SKETCH["curves"] + [CURVE2])
    fid = c.create_field(two)["id"]
    undone = requests.delete(f"{url}/v1/fields/{fid}/curves/last", timeout=60)
    assert undone.status_code == 200, undone.text
    assert undone.json()["revision"] == 2 and undone.json()["curves"] == 1
    # solved from the sketch of the first curve alone: the same field as creating it so
    fresh = c.create_field(SKETCH)["id"]
    a = c.sample_frames(fid, (0, 0, 0), (4, 4, 2), step=8)["quaternions"]
    b = c.sample_frames(fresh, (0, 0, 0), (4, 4, 2), step=8)["quaternions"]
    assert np.allclose(a, b, atol=1e-6)


def test_a_stale_revision_is_refused_by_both_curve_routes_and_changes_nothing(shared):
    """`revision=N` on POST .../curves and DELETE .../curves/last: the change is made only when
    the field is still at N (409 naming `revision` and saying the current one otherwise), so a
    stale page or a retried undo never removes or builds on a curve it did not see."""
    c, url = shared.client, shared.url
    fid = c.create_field(SKETCH)["id"]
    assert c.add_curve(fid, CURVE2, revision=1)["revision"] == 2
    before, file_before = c.get_field(fid), requests.get(f"{url}/v1/fields/{fid}/file", timeout=60).content
    curves, last = f"{url}/v1/fields/{fid}/curves", f"{url}/v1/fields/{fid}/curves/last"
    for stale in (1, 3):
        for response in (requests.post(curves, params={"revision": stale}, json=CURVE3, timeout=60),
                         requests.delete(last, params={"revision": stale}, timeout=60)):
            err = assert_error(response, 409, "failed_precondition")
            assert err["field"] == "revision" and "revision 2" in err["message"], err
    # the client sends it and raises the typed error
    with pytest.raises(Conflict) as info:
        c.undo_curve(fid, revision=1)
    assert info.value.field == "revision"
    with pytest.raises(Conflict):
        c.add_curve(fid, CURVE3, revision=5)
    assert c.get_field(fid) == before
    assert requests.get(f"{url}/v1/fields/{fid}/file", timeout=60).content == file_before
    for bad in ("0", "-1", "x", "1.5", ""):
        assert_error(requests.delete(last, params={"revision": bad}, timeout=60), 400, "invalid_argument", "revision")
        assert_error(requests.post(curves, params={"revision": bad}, json=CURVE3, timeout=60), 400, "invalid_argument",
                     "revision")
    # the revision shown goes through, once: a retry of the same undo is refused
    undone = requests.delete(last, params={"revision": 2}, timeout=60)
    assert undone.status_code == 200 and undone.json()["revision"] == 3, undone.text
    assert_error(requests.delete(last, params={"revision": 2}, timeout=60), 409, "failed_precondition", "revision")
    assert c.get_field(fid)["revision"] == 3
    assert requests.get(f"{url}/v1/fields/{fid}/file", timeout=60).content != file_before
    c.delete_field(fid)
