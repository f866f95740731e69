"""Frame fields from sketches: create, add and undo curves, sample, download, use in volumes."""
import copy

import numpy as np
import pytest
import requests

from solidtex_client import Conflict, NotFound
from support import assert_error, file_pixels, png_pixels, run_cli

# One straight curve along the diagonal x = y (in the plane z = 16): the frame's x axis
# follows it, so the field turns the texture by 45 degrees about z.
SKETCH = {
    "domain": {"min": [0, 0, 0], "max": [32, 32, 32], "shortest_side_cells": 8},
    "curves": [{"points": [[4, 4, 16], [16, 16, 16], [28, 28, 16]], "plane_normal": [0, 0, 1],
                "axis": "x"}],
}
CURVE2 = {"points": [[4, 28, 6], [28, 28, 6]], "plane_normal": [0, 0, 1]}


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    w, x, y, z = q / np.linalg.norm(q)
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    return r @ v


def test_field_lifecycle_and_volume_matches_cli(shared, tmp_path):
    c, url = shared.client, shared.server.url
    r = requests.post(url + "/v1/fields", json=SKETCH, timeout=60)
    assert r.status_code == 201, r.text
    assert r.headers.get("Location")
    fld = r.json()
    fid = fld["id"]
    assert fld["revision"] == 1
    assert fld["curves"] == 1
    assert c.get_field(fid)["revision"] == 1
    assert fid in [f["id"] for f in c.list_fields()]

    # the frame's x axis follows the diagonal curve
    on_curve = c.sample_frames(fid, (16, 16, 16), (1, 1, 1))
    axis = rotate(on_curve["quaternions"][0], np.array([1.0, 0, 0]))
    assert abs(axis @ np.array([1, 1, 0]) / np.sqrt(2)) > 0.9, (on_curve, axis)

    f2 = c.add_curve(fid, CURVE2)
    assert f2["id"] == fid
    assert f2["revision"] == 2
    assert f2["curves"] == 2
    assert c.get_field(fid)["revision"] == 2

    frames = c.sample_frames(fid, (2, 2, 2), (4, 3, 2), step=8)
    q = frames["quaternions"]
    assert q.shape == (24, 4)
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-4)
    pts = frames["points"]
    assert pts.shape == (24, 3)
    assert {tuple(p) for p in pts.tolist()} == {(2 + 8 * i, 2 + 8 * j, 2 + 8 * k)
                                               for i in range(4) for j in range(3) for k in range(2)}
    assert frames["scales"].shape == (24, 3)
    assert np.allclose(frames["scales"], 1.0)

    stf = c.get_field_file(fid)
    assert stf[:8] == b"STXFIELD"
    stf_path = tmp_path / "f.stf"
    stf_path.write_bytes(stf)

    vol = c.create_volume(exemplar=shared.exemplar_id, field={"id": fid}, seed=7)
    png = c.slice(vol["id"], "z", 16, (32, 24), dtype="png_bytes")
    out = tmp_path / "cli.png"
    run_cli("slice", shared.table_path, "--axis", "z", "--at", "16", "--size", "32,24",
            "--seed", "7", "--field", stf_path, "-o", out)
    assert np.array_equal(file_pixels(out), png_pixels(png)), "service != CLI --field FILE.stf"
    plain = c.slice(shared.volume_id, "z", 16, (32, 24))
    assert not np.array_equal(plain, png_pixels(png)), "the field changed nothing"

    # volumes keep their own copy of the field
    assert requests.delete(f"{url}/v1/fields/{fid}", timeout=60).status_code == 204
    assert_error(requests.get(f"{url}/v1/fields/{fid}", timeout=60), 404, "not_found")
    vol_png = c.slice(vol["id"], "z", 16, (32, 24), dtype="png_bytes")
    assert np.array_equal(png_pixels(vol_png), png_pixels(png))

    # contract: Volume.field names where the field came from (the stored field and revision)
    assert vol["field"] == {"kind": "stored", "id": fid, "revision": 2}, vol
    assert isinstance(vol["field_description"], str) and vol["field_description"], vol


def test_malformed_sketches(shared):
    url = shared.server.url + "/v1/fields"
    one_point = copy.deepcopy(SKETCH)
    one_point["curves"][0]["points"] = [[4, 4, 16]]
    assert_error(requests.post(url, json=one_point, timeout=60), 400, "invalid_argument",
                 field_contains="curves[0]")
    unknown = copy.deepcopy(SKETCH)
    unknown["curves"][0]["color"] = "red"
    err = assert_error(requests.post(url, json=unknown, timeout=60), 400, "invalid_argument",
                       field_contains="curves[0]")
    assert "color" in err["field"] + err["message"]
    no_curves = {"domain": SKETCH["domain"]}
    assert_error(requests.post(url, json=no_curves, timeout=60), 400, "invalid_argument",
                 field_contains="curves")
    flat = copy.deepcopy(SKETCH)
    flat["domain"]["max"] = [32, 32, 0]
    assert_error(requests.post(url, json=flat, timeout=60), 400, "invalid_argument",
                 field_contains="domain")

    fld = shared.client.create_field(SKETCH)
    bad_curve = {"points": [[1, 1, 1]], "plane_normal": [0, 0, 1]}
    assert_error(requests.post(f"{url}/{fld['id']}/curves", json=bad_curve, timeout=60), 400)
    assert shared.client.get_field(fld["id"])["revision"] == 1


def test_quaternion_spec_volume_matches_cli(shared, tmp_path):
    c = shared.client
    spec = "quat:0.7071,0,0.7071,0"
    vol = c.create_volume({"exemplar": shared.exemplar_id, "field": {"spec": spec}, "seed": 7})
    png = c.slice(vol["id"], "z", 0, (24, 16), dtype="png_bytes")
    out = tmp_path / "q.png"
    run_cli("slice", shared.table_path, "--axis", "z", "--at", "0", "--size", "24,16",
            "--seed", "7", "--field", spec, "-o", out)
    assert np.array_equal(file_pixels(out), png_pixels(png))


def test_undo_curve_through_the_client_is_the_raw_route(shared):
    """Client.undo_curve answers the Field of DELETE /v1/fields/{id}/curves/last: the new
    revision is the one before the curve, a volume keeps the revision it copied, and the
    errors are the typed ones naming what is wrong."""
    c, url = shared.client, shared.server.url
    fid = c.create_field(SKETCH)["id"]
    rev1 = c.get_field_file(fid)
    assert c.add_curve(fid, CURVE2)["revision"] == 2
    vol = c.create_volume(exemplar=shared.exemplar_id, field={"id": fid}, seed=7)

    undone = c.undo_curve(fid)
    assert c.last_response.status_code == 200
    assert undone["id"] == fid and undone["revision"] == 3 and undone["curves"] == 1, undone
    assert undone == c.get_field(fid)
    assert c.get_field_file(fid) == rev1

    # the raw route on a twin field: the same answer but for the id and the solve time, the
    # same file bytes
    twin = c.create_field(SKETCH)["id"]
    c.add_curve(twin, CURVE2)
    raw = requests.delete(f"{url}/v1/fields/{twin}/curves/last", timeout=60)
    assert raw.status_code == 200, raw.text

    def same(d):
        return {k: v for k, v in d.items() if k not in ("id", "seconds")}
    assert same(raw.json()) == same(undone)
    assert c.get_field_file(twin) == rev1

    # the volume made from revision 2 keeps it
    assert c.get_volume(vol["id"])["field"] == {"kind": "stored", "id": fid, "revision": 2}

    # one curve left: nothing removed, no new revision
    with pytest.raises(Conflict) as info:
        c.undo_curve(fid)
    assert info.value.status == 409 and info.value.field == "curves", info.value
    assert c.get_field(fid)["revision"] == 3
    with pytest.raises(NotFound) as info:
        c.undo_curve("fld_nothing")
    assert info.value.field == "id", info.value
    c.delete_volume(vol["id"])
    for f in (fid, twin):
        c.delete_field(f)
