"""The Python client's command line against a running server."""
import json

import numpy as np
from PIL import Image

from support import client_cli, file_pixels


def test_cli_slice_writes_png(shared, tmp_path):
    out = tmp_path / "out.png"
    client_cli(shared.server.url, "slice", shared.volume_id, "--axis", "z", "--at", "0",
               "--size", "16,16", "-o", out)
    img = Image.open(out)
    assert img.format == "PNG" and img.size == (16, 16)
    assert np.array_equal(file_pixels(out), shared.client.slice(shared.volume_id, "z", 0, (16, 16)))


def test_cli_error_message_and_status(shared, tmp_path):
    proc = client_cli(shared.server.url, "slice", "no-such-volume", "--axis", "z", "--at", "0",
                      "--size", "16,16", "-o", tmp_path / "x.png", check=False)
    assert proc.returncode == 1
    assert proc.stderr.startswith("error: not_found: "), proc.stderr
    assert not (tmp_path / "x.png").exists()


def test_cli_upload_field_volume_region_points(shared, exemplars, tmp_path):
    url = shared.server.url
    up = json.loads(client_cli(url, "upload", exemplars["bricks"], "--levels", "3",
                               "--neighborhood", "5", "--candidates", "4", "--pca-dims", "8",
                               "--name", "bricks", "--wait").stdout)
    assert up["exemplar"]["state"] == "ready" and up["job"]["state"] == "succeeded"
    sketch = tmp_path / "s.json"
    sketch.write_text(json.dumps({
        "domain": {"min": [0, 0, 0], "max": [16, 16, 16], "shortest_side_cells": 4},
        "curves": [{"points": [[2, 8, 8], [14, 8, 8]], "plane_normal": [0, 0, 1]}]}))
    fld = json.loads(client_cli(url, "field", sketch).stdout)
    assert fld["revision"] == 1
    vol = json.loads(client_cli(url, "volume", "--exemplar", up["exemplar"]["id"],
                                "--field-id", fld["id"], "--seed", "4").stdout)
    assert vol["seed"] == 4

    npy = tmp_path / "box.npy"
    client_cli(url, "region", vol["id"], "--min", "0,0,0", "--size", "6,5,4", "-o", npy)
    box = np.load(npy)
    assert box.shape == (4, 5, 6, 3) and box.dtype == np.float32
    vdb = tmp_path / "box.vdb"
    client_cli(url, "region", vol["id"], "--min", "0,0,0", "--size", "6,5,4", "-o", vdb)
    assert vdb.read_bytes()[:4] == b" BDV"

    pts = tmp_path / "pts.txt"
    pts.write_text("0 0 0\n5,4,3\n2 1 0\n")
    out = tmp_path / "rgb.npy"
    client_cli(url, "points", vol["id"], pts, "-o", out)
    rgb = np.load(out)
    assert rgb.shape == (3, 3)
    assert np.array_equal(rgb[0], box[0, 0, 0])
    assert np.array_equal(rgb[1], box[3, 4, 5])
    assert np.array_equal(rgb[2], box[0, 1, 2])
    # on voxel centres cubic resampling is the voxel; between them it blends its neighbours
    out_cubic = tmp_path / "rgb_cubic.npy"
    client_cli(url, "points", vol["id"], pts, "--resample", "cubic", "-o", out_cubic)
    assert np.array_equal(np.load(out_cubic), rgb)
    half = tmp_path / "half.txt"
    half.write_text("2.5 1 0\n")
    client_cli(url, "points", vol["id"], half, "--resample", "cubic", "-o", out_cubic)
    blended = np.load(out_cubic)[0]
    assert not np.array_equal(blended, box[0, 1, 2]) or np.array_equal(box[0, 1, 2], box[0, 1, 3])


def test_cli_slice_scale_is_the_clients(shared, tmp_path):
    levels = shared.exemplar["params"]["levels"]
    out = tmp_path / "coarse.png"
    client_cli(shared.server.url, "slice", shared.volume_id, "--axis", "x", "--at", "-40",
               "--origin=-60,-60", "--size", "12,8", "--scale", levels - 1, "-o", out)
    assert Image.open(out).size == (12, 8)
    want = shared.client.slice(shared.volume_id, "x", -40, (12, 8), origin=(-60, -60), scale=levels - 1)
    assert np.array_equal(file_pixels(out), want)
    proc = client_cli(shared.server.url, "slice", shared.volume_id, "--axis", "x", "--at", "0",
                      "--size", "4,4", "--scale", levels, "-o", tmp_path / "x.png", check=False)
    assert proc.returncode == 1 and proc.stderr.startswith("error: not_found: "), proc.stderr
    assert "(scale)" in proc.stderr and not (tmp_path / "x.png").exists()


def test_cli_upload_levels_auto_or_an_integer(shared, exemplars):
    """--levels auto leaves the count to the server (64^2 with N = 5: 3 levels); a word that is
    neither auto nor an integer is refused by the command line before anything is sent."""
    url = shared.server.url
    small = ["--neighborhood", "5", "--candidates", "4", "--pca-dims", "8", "--wait"]
    up = json.loads(client_cli(url, "upload", exemplars["noise"], "--levels", "auto", *small).stdout)
    got = shared.client.get_exemplar(up["exemplar"]["id"])
    assert got["params"]["levels"] == 3 and len(got["levels"]) == 3, got
    proc = client_cli(url, "upload", exemplars["noise"], "--levels", "many", *small, check=False)
    assert proc.returncode == 2 and "neither auto nor an integer" in proc.stderr, proc.stderr
    proc = client_cli(url, "upload", exemplars["noise"], "--levels", "9", *small, check=False)
    assert proc.returncode == 1 and "levels" in proc.stderr, proc.stderr
