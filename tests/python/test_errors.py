"""Error answers: status, code and the {"error": {"code", "message", "field"}} body.

One server with small limits (--max-upload-mb 1, --max-voxels 65536) serves the module; the
last test checks that none of the bad requests disturbed what was stored.
"""
import random

import numpy as np
import pytest
import requests

from solidtex_client import BadRequest, Conflict, NotFound, Unprocessable
from support import (ANALYSIS, assert_error, png_with_header, post_bytes, raw_post, server_with_volume,
                     upload_ready)


@pytest.fixture(scope="module")
def err(binary, exemplars, tmp_path_factory):
    with server_with_volume(tmp_path_factory.mktemp("errors"), exemplars["wood"],
                            "--max-upload-mb", "1", "--max-voxels", "65536", seed=5) as ns:
        ns.slice_before = ns.client.slice(ns.volume_id, "z", 0, (16, 16))
        yield ns


def test_malformed_json(err):
    for path in ("/v1/volumes", "/v1/fields"):
        r = requests.post(err.url + path, data=b'{"exemplar": ',
                          headers={"Content-Type": "application/json"}, timeout=30)
        assert_error(r, 400, "invalid_argument")
    r = requests.post(f"{err.url}/v1/volumes/{err.volume_id}/cut", data=b"[1, 2",
                      headers={"Content-Type": "application/json"}, timeout=30)
    assert_error(r, 400, "invalid_argument")


def test_bad_volume_specs_name_the_key(err):
    url = err.url + "/v1/volumes"
    cases = [
        ({"exemplar": err.exemplar_id, "color": "red"}, "color"),
        ({"exemplar": err.exemplar_id, "params": {"shceme": "grid"}}, "shceme"),
        ({"exemplar": err.exemplar_id, "params": {"scheme": "bogus"}}, "scheme"),
        ({"exemplar": err.exemplar_id, "seed": -1}, "seed"),
        ({"exemplar": err.exemplar_id, "field": {"spec": "quat:1,2"}}, "field"),
        ({"exemplar": err.exemplar_id, "seed": "7"}, "seed"),
    ]
    for body, key in cases:
        assert_error(requests.post(url, json=body, timeout=30), 400, "invalid_argument",
                     field_contains=key)
    with pytest.raises(BadRequest) as info:
        err.client.create_volume({"exemplar": err.exemplar_id, "color": "red"})
    assert info.value.status == 400 and "color" in info.value.field


def test_bad_query_parameters(err, exemplars):
    url = f"{err.url}/v1/volumes/{err.volume_id}/slice"
    base = {"axis": "z", "at": "0", "size": "8,8"}
    assert_error(requests.get(url, params={**base, "bogus": "1"}, timeout=30), 400,
                 "invalid_argument", field_contains="bogus")
    assert_error(requests.get(url, params={"axis": "z", "at": "0"}, timeout=30), 400,
                 "invalid_argument", field_contains="size")
    assert_error(requests.get(url, params={**base, "axis": "w"}, timeout=30), 400,
                 "invalid_argument", field_contains="axis")
    assert_error(requests.get(url, params={**base, "size": "8"}, timeout=30), 400,
                 "invalid_argument", field_contains="size")
    assert_error(requests.get(url, params={**base, "at": "zero"}, timeout=30), 400,
                 "invalid_argument", field_contains="at")
    for timeout in ("0", "-1", "100000"):
        assert_error(requests.get(url, params={**base, "timeout": timeout}, timeout=30), 400,
                     "invalid_argument", field_contains="timeout")
    png = exemplars["wood"].read_bytes()
    n_before = len(err.client.list_exemplars())
    for params, key in (({"levels": "99"}, "levels"), ({"neighborhood": "4"}, "neighborhood"),
                        ({**ANALYSIS, "color": "red"}, "color"),
                        ({**ANALYSIS, "plane_weights": "1,2"}, "plane_weights")):
        r = post_bytes(err.url + "/v1/exemplars", png, params=params, timeout=30)
        assert_error(r, 400, "invalid_argument", field_contains=key)
    assert len(err.client.list_exemplars()) == n_before


def test_unknown_ids_are_404(err):
    for path in ("/v1/volumes/nope", "/v1/exemplars/nope", "/v1/exemplars/nope/table",
                 "/v1/fields/nope", "/v1/fields/nope/file", "/v1/jobs/nope",
                 "/v1/volumes/nope/stats", "/v1/nothing-here"):
        assert_error(requests.get(err.url + path, timeout=30), 404, "not_found")
    r = requests.get(err.url + "/v1/volumes/nope/slice", params={"axis": "z", "at": 0,
                                                                 "size": "8,8"}, timeout=30)
    assert_error(r, 404, "not_found")
    with pytest.raises(NotFound) as info:
        err.client.get_volume("nope")
    assert info.value.code == "not_found" and info.value.status == 404
    r = requests.post(err.url + "/v1/volumes", json={"exemplar": "nope"}, timeout=30)
    assert_error(r, 404, "not_found")


def test_wrong_method_is_405(err):
    cases = [("PUT", "/v1/volumes"), ("DELETE", "/v1/exemplars"), ("PATCH", "/v1/fields"),
             ("GET", f"/v1/volumes/{err.volume_id}/cut"), ("POST", "/healthz"),
             ("PUT", f"/v1/volumes/{err.volume_id}")]
    for method, path in cases:
        r = requests.request(method, err.url + path, timeout=30)
        assert_error(r, 405, "method_not_allowed")
        assert r.headers.get("Allow"), f"405 without Allow header for {method} {path}"
    allow = requests.put(err.url + "/v1/volumes", timeout=30).headers["Allow"]
    assert sorted(m.strip() for m in allow.split(",")) == ["GET", "HEAD", "POST"]  # HEAD with every GET


def test_undecodable_images_are_rejected_at_once(err, exemplars):
    n_before = len(err.client.list_exemplars())
    junk = random.Random(1).randbytes(4096)
    r = post_bytes(err.url + "/v1/exemplars", junk, params=ANALYSIS, timeout=30)
    assert_error(r, {415, 422})

    huge = png_with_header(100000, 100000)
    r = post_bytes(err.url + "/v1/exemplars", huge, params=ANALYSIS, timeout=30)
    assert_error(r, 422)
    with pytest.raises(Unprocessable):
        err.client.upload_exemplar(huge, **ANALYSIS)
    wide = png_with_header(9000, 4)           # one side above --max-image-side 8192
    r = post_bytes(err.url + "/v1/exemplars", wide, params=ANALYSIS, timeout=30)
    assert_error(r, 422)
    assert len(err.client.list_exemplars()) == n_before


def test_truncated_png_never_becomes_ready(err, exemplars):
    data = exemplars["spots"].read_bytes()
    r = post_bytes(err.url + "/v1/exemplars", data[: len(data) // 2], params=ANALYSIS, timeout=30)
    if r.status_code == 202:      # header was fine; the decode fails in the job
        job = r.json()["job"]
        from solidtex_client import JobFailed
        with pytest.raises(JobFailed):
            err.client.wait_for_job(job["id"], timeout=60, poll=0.1)
        ex = err.client.get_exemplar(r.json()["exemplar"]["id"])
        assert ex["state"] == "failed" and ex["error"], ex
    else:
        assert_error(r, {415, 422})


def test_body_over_upload_limit_is_413(err):
    body = b"\x89PNG\r\n\x1a\n" + bytes(int(1.5 * 1024 * 1024))
    assert raw_post(err.url, "/v1/exemplars", body) == 413
    assert raw_post(err.url, "/v1/volumes", b'{"x": "' + b"a" * (2 * 1024 * 1024) + b'"}',
                    content_type="application/json") == 413
    assert requests.get(err.url + "/healthz", timeout=30).status_code == 200


def test_too_many_voxels_is_422(err):
    vid = err.volume_id
    r = requests.get(f"{err.url}/v1/volumes/{vid}/slice",
                     params={"axis": "z", "at": 0, "size": "512,512"}, timeout=30)
    assert_error(r, 422, field_contains="size")
    r = requests.get(f"{err.url}/v1/volumes/{vid}/region",
                     params={"min": "0,0,0", "size": "64,64,64"}, timeout=30)
    assert_error(r, 422, field_contains="size")
    r = requests.post(f"{err.url}/v1/volumes/{vid}/cut",
                      json={"origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0],
                            "size": [300, 300]}, timeout=30)
    assert_error(r, 422, field_contains="size")
    pts = np.zeros((70000, 3), dtype="<f4")
    r = post_bytes(f"{err.url}/v1/volumes/{vid}/points", pts.tobytes(), timeout=30)
    assert_error(r, 422)
    with pytest.raises(Unprocessable) as info:
        err.client.slice(vid, "z", 0, (512, 512))
    assert "size" in info.value.field


def test_points_body_must_be_triples(err):
    r = post_bytes(f"{err.url}/v1/volumes/{err.volume_id}/points", b"\x00" * 13, timeout=30)
    assert_error(r, 400, "invalid_argument")


def test_delete_exemplar_in_use_is_409(err, exemplars):
    c = err.client
    with pytest.raises(Conflict) as info:
        c.delete_exemplar(err.exemplar_id)
    assert info.value.status == 409
    r = requests.delete(f"{err.url}/v1/exemplars/{err.exemplar_id}", timeout=30)
    assert_error(r, 409)
    # once its last volume is gone it can be deleted
    other = upload_ready(c, exemplars["noise"])
    vol = c.create_volume(exemplar=other["id"])
    assert_error(requests.delete(f"{err.url}/v1/exemplars/{other['id']}", timeout=30), 409)
    c.delete_volume(vol["id"])
    assert requests.delete(f"{err.url}/v1/exemplars/{other['id']}", timeout=30).status_code == 204
    assert_error(requests.get(f"{err.url}/v1/exemplars/{other['id']}", timeout=30), 404)


def test_stored_resources_survive_the_errors(err):
    c = err.client
    assert err.exemplar_id in [e["id"] for e in c.list_exemplars()]
    assert c.get_exemplar(err.exemplar_id)["state"] == "ready"
    assert err.volume_id in [v["id"] for v in c.list_volumes()]
    assert np.array_equal(c.slice(err.volume_id, "z", 0, (16, 16)), err.slice_before)
    assert requests.get(err.url + "/healthz", timeout=30).status_code == 200
