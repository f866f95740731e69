"""Volumes: slices, cuts, caching, and bit identity across request kinds and with the CLI.

Each test reads its own far-apart part of the shared volume so that caching by one test does
not hide synthesis in another.
"""
import json

import numpy as np
import pytest
import requests

from solidtex_client import BadRequest, NotFound, Unprocessable
from support import RAW, RAW_F32, assert_error, file_pixels, png_pixels, run_cli, solidtex_bin, srgb8, upload_ready

OBLIQUE = dict(origin=(1, 2, 3), u=(0.6, 0.8, 0), v=(-0.48, 0.36, 0.8), size=(32, 24))


def test_create_get_delete_volume(shared):
    url = shared.server.url
    r = requests.post(url + "/v1/volumes", json={"exemplar": shared.exemplar_id, "seed": 11,
                                                  "name": "tmp"}, timeout=60)
    assert r.status_code == 201, r.text
    assert r.headers.get("Location")
    vol = r.json()
    assert vol["id"] and vol["seed"] == 11 and vol["name"] == "tmp"
    assert vol["exemplars"] == [shared.exemplar_id]
    c = shared.client
    assert c.get_volume(vol["id"])["id"] == vol["id"]
    assert vol["id"] in [v["id"] for v in c.list_volumes()]
    r = requests.delete(f"{url}/v1/volumes/{vol['id']}", timeout=60)
    assert r.status_code == 204
    assert_error(requests.get(f"{url}/v1/volumes/{vol['id']}", timeout=60), 404, "not_found")
    assert vol["id"] not in [v["id"] for v in c.list_volumes()]
    assert shared.volume_id in [v["id"] for v in c.list_volumes()]


def test_slice_variants_agree_and_match_cli(shared, tmp_path):
    c, vid = shared.client, shared.volume_id
    u8 = c.slice(vid, "z", 3, (32, 24))
    assert c.last_response.headers["X-Shape"].replace(" ", "") == "24,32,3"
    assert u8.dtype == np.uint8 and u8.shape == (24, 32, 3)
    assert u8.std() > 1.0, "slice is constant"
    f32 = c.slice(vid, "z", 3, (32, 24), dtype="float32")
    assert f32.dtype == np.float32 and f32.shape == (24, 32, 3)
    assert np.all(np.isfinite(f32))
    assert np.abs(srgb8(f32) - u8).max() <= 1, "uint8 answer is not the sRGB encoding of float32"
    png = c.slice(vid, "z", 3, (32, 24), dtype="png_bytes")
    assert c.last_response.headers["Content-Type"].startswith("image/png")
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert np.array_equal(png_pixels(png), u8)
    img = c.slice(vid, "z", 3, (32, 24), dtype="png")
    assert img.size == (32, 24)

    out = tmp_path / "cli.png"
    run_cli("slice", shared.table_path, "--axis", "z", "--at", "3", "--size", "32,24",
            "--seed", "7", "-o", out)
    assert np.array_equal(file_pixels(out), png_pixels(png)), "service slice != CLI slice"


def test_cli_color_and_finest_subpass_flags_match_the_service(shared, tmp_path):
    # the CLI's --color and --finest-subpass-size at each of their values give the service's
    # bits for a volume with the same params; other values are errors naming the flag
    import subprocess
    c = shared.client
    for color, s in (("mean", 2), ("medoid", 1), ("vote", 1), ("auto", 1), ("mean", 1), ("medoid", 2), ("vote", 2)):
        vid = c.create_volume(exemplar=shared.exemplar_id, seed=7, params={"color": color, "finest_subpass_size": s})["id"]
        out = tmp_path / f"{color}{s}.png"
        run_cli("slice", shared.table_path, "--axis", "z", "--at", "3", "--size", "16,12", "--seed", "7",
                "--color", color, "--finest-subpass-size", s, "-o", out)
        assert np.array_equal(file_pixels(out), c.slice(vid, "z", 3, (16, 12))), (color, s)
    # --finest-typicality-scale likewise (the default, 0.7, is the first volume's above)
    for scale in (0, 1):
        vid = c.create_volume(exemplar=shared.exemplar_id, seed=7, params={"finest_typicality_scale": scale})["id"]
        out = tmp_path / f"scale{scale}.png"
        run_cli("slice", shared.table_path, "--axis", "z", "--at", "3", "--size", "16,12", "--seed", "7",
                "--finest-typicality-scale", scale, "-o", out)
        assert np.array_equal(file_pixels(out), c.slice(vid, "z", 3, (16, 12))), scale
    for flag, bad, named in (("--color", "median", "color: unknown color 'median'"),
                             ("--finest-subpass-size", "3", "--finest-subpass-size: is 3"),
                             ("--finest-subpass-size", "0", "--finest-subpass-size: is 0"),
                             ("--finest-typicality-scale", "1.5", "--finest-typicality-scale: is 1.5; out of range"),
                             ("--finest-typicality-scale", "auto", "--finest-typicality-scale: 'auto' is not a number")):
        proc = subprocess.run([str(solidtex_bin()), "slice", str(shared.table_path), "--axis", "z", "--at", "0",
                               "--size", "4,4", flag, bad, "-o", str(tmp_path / "x.png")], capture_output=True, text=True)
        assert proc.returncode != 0 and named in proc.stderr, proc.stderr


def test_default_answer_is_png(shared):
    r = requests.get(f"{shared.server.url}/v1/volumes/{shared.volume_id}/slice",
                     params={"axis": "z", "at": 3, "size": "32,24"}, timeout=60)
    assert r.status_code == 200
    assert r.headers["Content-Type"].startswith("image/png")
    assert np.array_equal(png_pixels(r.content), shared.client.slice(shared.volume_id, "z", 3, (32, 24)))


def test_other_axes(shared):
    c, vid = shared.client, shared.volume_id
    x = c.slice(vid, "x", 5, (20, 12), origin=(-3, 4), dtype="float32")
    y = c.slice(vid, "y", 4, (20, 12), origin=(5, -2), dtype="float32")
    assert x.shape == y.shape == (12, 20, 3)
    # pixel (i, j) (array [j, i]) of axis x is voxel (at, U+i, V+j), of axis y (U+i, at, V+j):
    # voxel (5, 4, 6) is x[2, 7] and y[8, 0]; voxel (5, 10, 9) is x[5, 13]
    assert np.array_equal(x[2, 7], y[8, 0])
    p = c.points(vid, [[5, 4, 6], [5, 10, 9]])
    assert np.array_equal(p[0], x[2, 7])
    assert np.array_equal(p[1], x[5, 13])


def test_repeated_slice_is_cached(shared):
    """The answer's X-Voxels-Synthesized is what the volume's stats add up; a repeat is all
    cache hits (one per target voxel) and synthesizes nothing."""
    c, vid = shared.client, shared.volume_id
    url = f"{shared.server.url}/v1/volumes/{vid}/slice"
    params = {"axis": "z", "at": 61, "origin": "400,400", "size": "16,16"}

    def synthesized(stats):
        return sum(lv["voxels_synthesized"] for lv in stats["levels"])

    before = c.volume_stats(vid)
    r1 = requests.get(url, params=params, headers=RAW, timeout=60)
    assert r1.status_code == 200, r1.text
    first = int(r1.headers["X-Voxels-Synthesized"])
    assert first >= 16 * 16, r1.headers          # at least the target's own voxels
    mid = c.volume_stats(vid)
    assert synthesized(mid) - synthesized(before) == first, (before["levels"], mid["levels"])
    assert mid["recent"][-1]["kind"] == "slice" and mid["recent"][-1]["voxels"] == first, mid
    assert mid["recent"][-1]["target_voxels"] == 16 * 16, mid["recent"][-1]

    r2 = requests.get(url, params=params, headers=RAW, timeout=60)
    assert r2.status_code == 200
    assert r2.content == r1.content
    assert r2.headers["X-Voxels-Synthesized"].strip() == "0"
    after = c.volume_stats(vid)
    assert after["volume"] == vid
    assert synthesized(after) == synthesized(mid), (mid["levels"], after["levels"])
    # every voxel the colors read (the cut and, for patch votes, one step around it) is a hit
    support = mid["recent"][-1]["support_voxels"]
    assert support >= 16 * 16, mid["recent"][-1]
    assert after["cache"]["hits"] - mid["cache"]["hits"] == support, (mid["cache"], after["cache"])
    assert after["cache"]["misses"] == mid["cache"]["misses"], (mid["cache"], after["cache"])
    assert after["cache"]["bytes"] > 0, after
    cached = sum(lv["cached_voxels"] for lv in after["levels"])
    assert after["cache"]["bytes_per_voxel"] == pytest.approx(after["cache"]["bytes"] / cached), after
    assert after["cache"]["bytes_per_voxel"] >= 12, after  # three planes' 16-bit x, y per voxel
    assert after["requests"] == mid["requests"] + 1 == before["requests"] + 2, after
    assert after["recent"][-1]["voxels"] == 0, after["recent"][-1]


def test_cut_matches_cli_plane_and_slice(shared, tmp_path):
    c, vid = shared.client, shared.volume_id
    png = c.cut(vid, dtype="png_bytes", **OBLIQUE)
    u8 = c.cut(vid, **OBLIQUE)
    assert u8.shape == (24, 32, 3) and u8.std() > 1.0
    assert np.array_equal(png_pixels(png), u8)
    out = tmp_path / "c.png"
    plane = ",".join(str(x) for x in (*OBLIQUE["origin"], *OBLIQUE["u"], *OBLIQUE["v"]))
    run_cli("slice", shared.table_path, "--plane", plane, "--size", "32,24", "--seed", "7",
            "-o", out)
    assert np.array_equal(file_pixels(out), u8), "service cut != CLI --plane (both resample auto)"
    # an axis-aligned cut is the slice
    flat = c.cut(vid, origin=(0, 0, 3), u=(1, 0, 0), v=(0, 1, 0), size=(32, 24), dtype="float32")
    assert np.array_equal(flat, c.slice(vid, "z", 3, (32, 24), dtype="float32"))
    # cubic resampling: the same bytes from the service and the CLI, different from nearest,
    # exactly the slice along the axes; any other name is a 400 naming the field
    cubic = c.cut(vid, resample="cubic", **OBLIQUE)
    nearest = c.cut(vid, resample="nearest", **OBLIQUE)
    assert cubic.shape == u8.shape and not np.array_equal(cubic, nearest)
    assert np.array_equal(u8, cubic), "the wood exemplar has little 1-pixel detail: auto is cubic"
    out_cubic = tmp_path / "cubic.png"
    run_cli("slice", shared.table_path, "--plane", plane, "--resample", "cubic", "--size", "32,24", "--seed", "7",
            "-o", out_cubic)
    assert np.array_equal(file_pixels(out_cubic), cubic), "service cubic cut != CLI --plane --resample cubic"
    flat_cubic = c.cut(vid, origin=(0, 0, 3), u=(1, 0, 0), v=(0, 1, 0), size=(32, 24), dtype="float32", resample="cubic")
    assert np.array_equal(flat_cubic, flat)
    r = requests.post(f"{shared.server.url}/v1/volumes/{vid}/cut", json={**{k: list(v) for k, v in OBLIQUE.items()}, "resample": "lanczos"},
                      timeout=60)
    assert r.status_code == 400 and r.json()["error"]["field"] == "resample", r.text


def test_auto_resample_follows_the_exemplars_pixel_detail(shared, tmp_path):
    """`resample` auto, the default, is cubic for an exemplar whose contrast lies above the
    pixel scale (a smooth wave) and nearest for per-pixel speckle (voxel_sampling.h); the answer
    says which in X-Resample, equals the explicit choice bit for bit, and the CLI's --plane
    (also auto by default) agrees and reports it in --stats."""
    c = shared.client
    yy, xx = np.mgrid[0:48, 0:48]
    wave = 128 + 80 * np.sin(2 * np.pi * xx / 24) * np.cos(2 * np.pi * yy / 24)
    images = {"cubic": np.repeat(wave[..., None], 3, axis=2).astype(np.uint8),
              "nearest": np.random.default_rng(5).integers(0, 256, (48, 48, 3), dtype=np.uint8)}
    plane = ",".join(str(x) for x in (*OBLIQUE["origin"], *OBLIQUE["u"], *OBLIQUE["v"]))
    for expected, image in images.items():
        ex = upload_ready(c, image)
        vid = c.create_volume(exemplar=ex["id"], seed=3)["id"]
        body = {**{k: list(v) for k, v in OBLIQUE.items()}}
        auto = requests.post(f"{shared.server.url}/v1/volumes/{vid}/cut", json=body, headers=RAW, timeout=120)
        assert auto.status_code == 200 and auto.headers["X-Resample"] == expected, (auto.status_code, auto.headers)
        explicit = requests.post(f"{shared.server.url}/v1/volumes/{vid}/cut", json={**body, "resample": expected},
                                 headers=RAW, timeout=120)
        other = requests.post(f"{shared.server.url}/v1/volumes/{vid}/cut",
                              json={**body, "resample": "nearest" if expected == "cubic" else "cubic"}, headers=RAW, timeout=120)
        assert explicit.content == auto.content and other.content != auto.content
        table = tmp_path / f"{expected}.stx"
        table.write_bytes(c.get_exemplar_table(ex["id"]))
        out, stats = tmp_path / f"{expected}.png", tmp_path / f"{expected}.json"
        run_cli("slice", table, "--plane", plane, "--size", "32,24", "--seed", "3", "-o", out, "--stats", stats)
        assert json.loads(stats.read_text())["resample"] == expected
        assert np.array_equal(file_pixels(out), np.frombuffer(auto.content, np.uint8).reshape(24, 32, 3))


def test_scale_slice_and_cut_are_the_raw_routes_bytes(shared):
    """``scale=s`` on Client.slice and Client.cut gives the bytes of the raw routes with
    scale=s, for every dataset of the pyramid and every answer type."""
    c, vid = shared.client, shared.volume_id
    base = f"{shared.server.url}/v1/volumes/{vid}"
    levels = shared.exemplar["params"]["levels"]
    cut = dict(origin=(-70, -90, 40), u=(0.8, 0, 0.6), v=(0, 1, 0), size=(12, 10))
    cut_body = {"origin": list(cut["origin"]), "u": list(cut["u"]), "v": list(cut["v"]), "size": [12, 10]}
    slices = []
    for scale in range(levels):
        params = {"axis": "y", "at": -90, "origin": "-70,40", "size": "12,10", "scale": scale}
        raw = requests.get(f"{base}/slice", params=params, headers=RAW, timeout=60)
        assert raw.status_code == 200, raw.text
        u8 = c.slice(vid, "y", -90, (12, 10), origin=(-70, 40), scale=scale)
        assert u8.shape == (10, 12, 3) and u8.tobytes() == raw.content, scale
        raw_f32 = requests.get(f"{base}/slice", params=params, headers=RAW_F32, timeout=60)
        f32 = c.slice(vid, "y", -90, (12, 10), origin=(-70, 40), scale=scale, dtype="float32")
        assert f32.astype("<f4").tobytes() == raw_f32.content, scale
        raw_png = requests.get(f"{base}/slice", params=params, timeout=60)
        assert c.slice(vid, "y", -90, (12, 10), origin=(-70, 40), scale=scale, dtype="png_bytes") == raw_png.content
        slices.append(u8)

        raw_cut = requests.post(f"{base}/cut", params={"scale": scale}, json=cut_body, headers=RAW, timeout=60)
        assert raw_cut.status_code == 200, raw_cut.text
        got = c.cut(vid, **cut, scale=scale)
        assert got.shape == (10, 12, 3) and got.tobytes() == raw_cut.content, scale
        # an axis-aligned cut of the dataset is its slice
        flat = c.cut(vid, origin=(-70, -90, 40), u=(1, 0, 0), v=(0, 0, 1), size=(12, 10), scale=scale)
        assert np.array_equal(flat, u8), scale
    assert not np.array_equal(slices[0], slices[-1]), "the coarsest dataset is the finest again"

    # bad scales: refused by the client before sending, or by the server naming the parameter
    sent = c.last_response
    for bad, error in ((-1, ValueError), (1.5, TypeError), ("1", TypeError)):
        with pytest.raises(error, match="scale"):
            c.slice(vid, "y", -90, (12, 10), scale=bad)
        with pytest.raises(error, match="scale"):
            c.cut(vid, **cut, scale=bad)
    assert c.last_response is sent, "a bad scale was sent"
    with pytest.raises(NotFound) as info:
        c.slice(vid, "y", -90, (12, 10), scale=levels)
    assert info.value.field == "scale" and f"0..{levels - 1}" in info.value.message, info.value
    with pytest.raises(NotFound) as info:
        c.cut(vid, **cut, scale=levels)
    assert info.value.field == "scale", info.value
    with pytest.raises(BadRequest) as info:                  # past the contract's maximum, 7
        c.slice(vid, "y", -90, (12, 10), scale=8)
    assert info.value.field == "scale", info.value


def test_points_region_slice_agree(shared):
    c, vid = shared.client, shared.volume_id
    x0, y0, z0 = 200, -40, 30
    w, h, d = 12, 8, 3
    k = z0 + 1
    row = 5
    pts = np.array([[x0 + i, y0 + row, k] for i in range(w)], dtype=np.float64)
    p = c.points(vid, pts)                      # first: nothing of this box is cached yet
    assert p.shape == (w, 3) and p.dtype == np.float32
    assert c.last_response.headers["X-Shape"].replace(" ", "") == f"{w},3"
    box = c.region(vid, (x0, y0, z0), (w, h, d), fmt="float32")
    assert box.shape == (d, h, w, 3)
    assert c.last_response.headers["X-Shape"].replace(" ", "") == f"{d},{h},{w},3"
    sl = c.slice(vid, "z", k, (w, h), origin=(x0, y0), dtype="float32")
    assert np.array_equal(p, sl[row]), "points != slice pixels"
    assert np.array_equal(box[k - z0], sl), "region != slice of the same plane"
    box8 = c.region(vid, (x0, y0, z0), (w, h, d), fmt="uint8")
    assert box8.dtype == np.uint8 and box8.shape == (d, h, w, 3)
    assert np.array_equal(box8[k - z0], c.slice(vid, "z", k, (w, h), origin=(x0, y0)))
    # world points round to the nearest voxel
    assert np.array_equal(c.points(vid, pts + [0.3, -0.3, 0.2]), p)
    # JSON variant
    r = requests.post(f"{shared.server.url}/v1/volumes/{vid}/points",
                      json={"points": pts.tolist()}, headers={"Accept": "application/json"},
                      timeout=60)
    assert r.status_code == 200, r.text
    assert np.array_equal(np.asarray(r.json()["rgb"], dtype=np.float32), p)


def test_region_default_is_vdb(shared):
    c, vid = shared.client, shared.volume_id
    data = c.region(vid, (-8, 60, 0), (8, 8, 8))
    assert isinstance(data, bytes) and len(data) > 64
    assert data[:4] == b" BDV", data[:16]
    r = requests.get(f"{shared.server.url}/v1/volumes/{vid}/region",
                     params={"min": "-8,60,0", "size": "8,8,8"}, timeout=60)
    assert r.status_code == 200
    assert r.headers["Content-Type"].startswith("application/x-vdb")
    assert r.content[:4] == b" BDV"


def test_old_scheme_name_is_rejected_and_plain_works(shared, tmp_path):
    """'standard' was renamed 'plain': the old name is refused with a message naming the new
    one (and creates nothing); 'plain' makes a volume whose slice is the CLI's --scheme plain."""
    c = shared.client
    n_before = len(c.list_volumes())
    r = requests.post(shared.server.url + "/v1/volumes",
                      json={"exemplar": shared.exemplar_id, "params": {"scheme": "standard"}},
                      timeout=60)
    err = assert_error(r, {400, 422}, field_contains="scheme")
    assert "'plain'" in err["message"], err
    with pytest.raises((BadRequest, Unprocessable)) as info:
        c.create_volume(exemplar=shared.exemplar_id, params={"scheme": "standard"})
    assert "plain" in info.value.message and "scheme" in info.value.field, info.value
    assert len(c.list_volumes()) == n_before, "a refused volume was stored"

    vol = c.create_volume(exemplar=shared.exemplar_id, seed=7, params={"scheme": "plain"})
    assert c.last_response.status_code == 201
    assert vol["params"]["scheme"] == "plain", vol
    assert c.get_volume(vol["id"])["params"]["scheme"] == "plain"
    png = c.slice(vol["id"], "z", 3, (32, 24), dtype="png_bytes")
    out = tmp_path / "plain.png"
    run_cli("slice", shared.table_path, "--axis", "z", "--at", "3", "--size", "32,24",
            "--seed", "7", "--scheme", "plain", "-o", out)
    assert np.array_equal(file_pixels(out), png_pixels(png)), "service plain != CLI --scheme plain"
    # the default scheme, dual-grid; the typicality, passes, init, color, subpass, balance, finest scale, init band
    # finest match and finest sources defaults are pinned
    assert shared.volume["params"] == {"typicality": "auto", "passes": 1, "init": "auto", "color": "auto", "finest_subpass_size": 1,
                                       "balance": 1.0, "finest_typicality_scale": 0.7, "init_band": 8,
                                       "finest_match": "auto", "finest_sources": "square"}, shared.volume
    default = c.slice(shared.volume_id, "z", 3, (32, 24))
    assert not np.array_equal(png_pixels(png), default), "plain and dual-grid gave the same slice"
    c.delete_volume(vol["id"])


def test_synthesized_answers_are_immutable_and_revalidate(shared):
    """Slices, regions and cuts carry a content ETag and an immutable Cache-Control (HTTP caches,
    nginx in deploy/, may keep them); a GET naming the ETag gets 304 without a body."""
    base = f"{shared.server.url}/v1/volumes/{shared.volume_id}"
    params = {"axis": "z", "at": 5, "size": "24,16"}
    first = requests.get(f"{base}/slice", params=params, timeout=60)
    again = requests.get(f"{base}/slice", params=params, timeout=60)
    assert first.status_code == again.status_code == 200
    etag = first.headers["ETag"]
    assert etag.startswith('"img-') and etag == again.headers["ETag"]
    assert first.headers["Cache-Control"] == "public, max-age=31536000, immutable"
    other = requests.get(f"{base}/slice", params={**params, "at": 6}, timeout=60)
    assert other.headers["ETag"] != etag
    raw = requests.get(f"{base}/slice", params=params, headers={"Accept": "application/octet-stream"}, timeout=60)
    assert raw.headers["ETag"] != etag  # another representation, another tag
    revalidated = requests.get(f"{base}/slice", params=params, headers={"If-None-Match": etag}, timeout=60)
    assert revalidated.status_code == 304 and revalidated.content == b""
    assert revalidated.headers["ETag"] == etag
    region = requests.get(f"{base}/region", params={"min": "0,0,0", "size": "4,4,4"},
                          headers={"Accept": "application/octet-stream"}, timeout=60)
    assert region.status_code == 200 and region.headers["ETag"].startswith('"img-')
    assert requests.get(f"{base}/region", params={"min": "0,0,0", "size": "4,4,4"},
                        headers={"Accept": "application/octet-stream", "If-None-Match": region.headers["ETag"]},
                        timeout=60).status_code == 304
    cut = requests.post(f"{base}/cut", json={"origin": [0, 0, 5], "u": [1, 0, 0], "v": [0, 1, 0], "size": [24, 16]},
                        timeout=60)
    assert cut.status_code == 200 and cut.headers["Cache-Control"].endswith("immutable")
    assert cut.headers["ETag"] == etag  # the same voxels, the same PNG bytes


def test_cli_reference_is_the_exemplar_as_each_axis_cut_shows_its_plane(tmp_path):
    """`slice --reference` writes the exemplar an axis cut's plane was synthesized from, in the
    cut's pixel orientation (what bench/bench_quality.py scores axis cuts against): with
    `--grain y` plane xy holds E, yz holds E transposed and zx (end grain) E, so the z cut shows
    E, the x cut E transposed, and the y cut (x across, z down: zx transposed) E transposed."""
    from PIL import Image
    rng = np.random.default_rng(3)
    exemplar = rng.integers(0, 256, (16, 24, 3), dtype=np.uint8)  # 24 wide, 16 high: transposes show
    src = tmp_path / "e.png"
    Image.fromarray(exemplar).save(src)
    table = tmp_path / "e.stx"
    run_cli("analyze", src, "--grain", "y", "--levels", "2", "--neighborhood", "5", "--candidates", "4",
            "--pca-dims", "6", "--balance-rounds", "0", "-o", table)
    expected = {"z": exemplar, "x": exemplar.transpose(1, 0, 2), "y": exemplar.transpose(1, 0, 2)}
    for axis, want in expected.items():
        ref = tmp_path / f"ref_{axis}.png"
        run_cli("slice", table, "--axis", axis, "--at", "0", "--size", "4,4", "-o", tmp_path / f"{axis}.png",
                "--reference", ref)
        assert np.array_equal(file_pixels(ref), want), axis


def test_points_resample_like_plane_cuts(shared):
    """/points samples nearest voxels unless `resample` says cubic or auto; points along a plane
    give exactly that plane cut's pixels either way (float32), and X-Resample says which."""
    c, vid = shared.client, shared.volume_id
    plane = dict(origin=(1.25, 2.5, 3), u=(0.5, 0.75, 0), v=(-0.25, 0.5, 0.75), size=(20, 12))  # exact in float32
    o, u, v = (np.array(plane[k], np.float64) for k in ("origin", "u", "v"))
    w, h = plane["size"]
    jj, ii = np.mgrid[0:h, 0:w]
    pts = o + ii.reshape(-1, 1) * u + jj.reshape(-1, 1) * v
    assert np.array_equal(pts.astype(np.float32).astype(np.float64), pts), "positions must survive float32"
    for resample, sampled in ((None, "nearest"), ("nearest", "nearest"), ("cubic", "cubic"), ("auto", "cubic")):
        rgb = c.points(vid, pts, resample=resample)
        assert c.last_response.headers["X-Resample"] == sampled, (resample, c.last_response.headers)
        cut = c.cut(vid, dtype="float32", resample=sampled, **plane)
        assert np.array_equal(rgb.reshape(h, w, 3), cut), resample
    r = requests.post(f"{shared.server.url}/v1/volumes/{vid}/points", params={"resample": "trilinear"},
                      data=pts.astype("<f4").tobytes(), headers={"Content-Type": "application/octet-stream"}, timeout=60)
    assert_error(r, 400, "invalid_argument", "resample")
