"""Exemplar upload, background analysis, table download and bit identity with the CLI."""
import numpy as np

from support import ANALYSIS, ANALYSIS_CLI, assert_error, file_pixels, post_bytes, run_cli, upload_ready
from solidtex_client import encode_png


def test_upload_analyse_download_matches_cli(shared, exemplars, cli_table):
    c = shared.client
    r = post_bytes(shared.server.url + "/v1/exemplars", exemplars["wood"].read_bytes(),
                   params={**ANALYSIS, "name": "wood2"})
    assert r.status_code == 202, r.text
    assert r.headers.get("Location"), r.headers
    body = r.json()
    ex, job = body["exemplar"], body["job"]
    assert ex["id"] and job["id"]
    assert job["kind"] == "analysis"
    assert job["state"] in ("queued", "running", "succeeded")
    assert 0 <= job["percent"] <= 100
    assert ex["state"] in ("analyzing", "ready")

    final = c.wait_for_job(job["id"], timeout=120, poll=0.1)
    assert final["state"] == "succeeded"
    assert final["percent"] == 100
    assert final.get("error") is None
    assert final["exemplar_id"] == ex["id"]

    got = c.get_exemplar(ex["id"])
    assert got["id"] == ex["id"]
    assert got["state"] == "ready"
    assert got["name"] == "wood2"
    # the procedural wood is strongly striped along x: grain=auto (the default) lays it out as grain x
    assert got["grain"] == "x"
    assert got["planes"] == 3
    assert (got["width"], got["height"]) == (64, 64)
    assert got["has_mask"] is False
    assert got["job_id"] == job["id"]
    levels = got["levels"]
    assert len(levels) == 3
    for lv in levels:
        assert lv["mean_crossbar_error"] < lv["random_crossbar_error"], lv

    assert ex["id"] in [e["id"] for e in c.list_exemplars()]

    table = c.get_exemplar_table(ex["id"])
    assert table[:8] == b"STXTABLE"
    assert got["table_bytes"] == len(table)
    assert table == cli_table.read_bytes(), "service table differs from `solidtex analyze`"
    # the shared fixture's upload of the same image gives the same table too
    assert shared.table == table


def test_grain_auto_none_and_y_layouts(shared, exemplars):
    """grain=auto gives striped exemplars a grain layout and leaves isotropic ones alone; none
    keeps a striped one isotropic; y takes stripes along the image's y axis; the stored grain is
    the layout applied. Unknown layouts are a 400 naming grain."""
    c = shared.client
    noise = upload_ready(c, exemplars["noise"])
    assert (noise["grain"], noise["planes"]) == ("", 1), noise
    none = upload_ready(c, exemplars["wood"], grain="none")
    assert (none["grain"], none["planes"]) == ("", 1), none
    upright = np.ascontiguousarray(file_pixels(exemplars["wood"]).transpose(1, 0, 2))
    auto_y = upload_ready(c, upright)
    assert (auto_y["grain"], auto_y["planes"]) == ("y", 3), auto_y
    r = post_bytes(shared.server.url + "/v1/exemplars", exemplars["wood"].read_bytes(), params={**ANALYSIS, "grain": "z"})
    assert r.status_code == 400, r.text
    assert r.json()["error"]["field"] == "grain", r.text


def test_grain_crossed_matches_the_cli_and_stays_crossed(shared, exemplars, tmp_path):
    """grain=crossed (yz = zx = the exemplar transposed) is stored as applied, analysed into
    the CLI's table bit for bit, and a volume of it cuts like the CLI's (init auto: scatter)."""
    c = shared.client
    got = upload_ready(c, exemplars["bricks"], grain="crossed")
    assert (got["grain"], got["planes"]) == ("crossed", 3), got
    cli = tmp_path / "crossed.stx"
    run_cli("analyze", exemplars["bricks"], *ANALYSIS_CLI, "--grain", "crossed", "-o", cli)
    assert c.get_exemplar_table(got["id"]) == cli.read_bytes()
    vol = c.create_volume(exemplar=got["id"], seed=4)
    png = tmp_path / "z.png"
    run_cli("slice", cli, "--axis", "z", "--at", 2, "--size", "24,16", "--seed", 4, "-o", png)
    assert np.array_equal(c.slice(vol["id"], "z", 2, (24, 16)), file_pixels(png))


def test_three_planes_multipart_matches_cli(shared, exemplars, tmp_path):
    c = shared.client
    up = c.upload_exemplar(exemplars["wood"], yz=exemplars["stripes"], zx=exemplars["bricks"],
                           **ANALYSIS)
    assert c.last_response.status_code == 202
    c.wait_for_job(up["job"]["id"], timeout=120, poll=0.1)
    got = c.get_exemplar(up["exemplar"]["id"])
    assert got["state"] == "ready"
    assert got["planes"] == 3
    cli = tmp_path / "three.stx"
    run_cli("analyze", exemplars["wood"], "--yz", exemplars["stripes"], "--zx", exemplars["bricks"],
            *ANALYSIS_CLI, "-o", cli)
    assert c.get_exemplar_table(got["id"]) == cli.read_bytes()


def test_numpy_upload_is_sent_as_png(shared, exemplars, tmp_path):
    c = shared.client
    pixels = file_pixels(exemplars["noise"])
    assert pixels.dtype == np.uint8 and pixels.shape == (64, 64, 3)
    up = c.upload_exemplar(pixels, name="noise-array", **ANALYSIS)
    c.wait_for_job(up["job"]["id"], timeout=120, poll=0.1)
    got = c.get_exemplar(up["exemplar"]["id"])
    assert got["state"] == "ready" and (got["width"], got["height"]) == (64, 64)
    # the CLI analysing the same PNG bytes the client sent gives the same table
    png = tmp_path / "noise-array.png"
    png.write_bytes(encode_png(pixels))
    cli = tmp_path / "noise.stx"
    run_cli("analyze", png, *ANALYSIS_CLI, "-o", cli)
    assert c.get_exemplar_table(got["id"]) == cli.read_bytes()


def test_levels_default_to_the_exemplars_size(shared, tmp_path):
    """Without `levels` (or with levels=auto) the pyramid gets the most levels whose coarsest
    template spans at most half the exemplar's shorter side (auto_levels); the stored record and
    the table hold the count used, and it equals asking for that count. Anything else is a 400
    naming levels."""
    c = shared.client
    rng = np.random.default_rng(3)
    img = tmp_path / "e.png"
    img.write_bytes(encode_png((rng.random((48, 80, 3)) * 255).astype(np.uint8)))
    small = {k: v for k, v in ANALYSIS.items() if k != "levels"}  # N = 5: 5*2^(L-1) <= 24 -> L = 3

    def ready(**params):
        up = c.upload_exemplar(img, grain="none", **params)
        c.wait_for_job(up["job"]["id"], timeout=120, poll=0.1)
        return c.get_exemplar(up["exemplar"]["id"])

    default = ready(**small)
    auto = ready(**small, levels="auto")
    three = ready(**small, levels=3)
    for ex in (default, auto):
        assert len(ex["levels"]) == 3 and ex["params"]["levels"] == 3, ex
    tables = [c.get_exemplar_table(ex["id"]) for ex in (default, auto, three)]
    assert tables[0] == tables[1] == tables[2]
    two = ready(**small, levels=2)
    assert len(two["levels"]) == 2 and c.get_exemplar_table(two["id"]) != tables[0]
    for bad in ("autos", "0", "9", "3.5", ""):
        r = post_bytes(shared.server.url + "/v1/exemplars", img.read_bytes(), params={**small, "levels": bad})
        assert_error(r, 400, "invalid_argument", "levels")
