"""Persistence: everything acknowledged survives kill -9 and SIGTERM; leftovers are ignored."""
import json
import os
import signal
import threading
import time

import numpy as np
import pytest
import requests

from support import ANALYSIS, ANALYSIS_CLI, run_cli, upload_ready

pytestmark = pytest.mark.slow

SKETCH = {
    "domain": {"min": [0, 0, 0], "max": [32, 32, 32], "shortest_side_cells": 8},
    "curves": [{"points": [[4, 4, 16], [28, 28, 16]], "plane_normal": [0, 0, 1], "axis": "x"}],
}


def wait_ready(client, exemplar_id, seconds=90):
    end = time.monotonic() + seconds
    while True:
        ex = client.get_exemplar(exemplar_id)
        if ex["state"] != "analyzing" or time.monotonic() > end:
            return ex
        time.sleep(0.1)


def test_kill9_restart_keeps_everything(server, exemplars, tmp_path):
    a = server()
    c = a.client
    ex = upload_ready(c, exemplars["wood"], name="wood")
    fld = c.create_field(SKETCH)
    vol = c.create_volume(exemplar=ex["id"], field={"id": fld["id"]}, seed=3, name="v")
    png = c.slice(vol["id"], "z", 5, (24, 16), dtype="png_bytes")
    raw = c.slice(vol["id"], "y", 2, (24, 16), origin=(-5, 1))
    table = c.get_exemplar_table(ex["id"])
    stf = c.get_field_file(fld["id"])
    volume_before = c.get_volume(vol["id"])
    # acknowledged, then the server dies before (or while) analysing it
    pending = c.upload_exemplar(exemplars["spots"], name="pending", **ANALYSIS)
    assert c.last_response.status_code == 202
    a.kill()

    # leftovers of interrupted writes: junk and half-written copies of real files
    files = [p for p in a.data_dir.rglob("*") if p.is_file()]
    assert files, "the server stored nothing in its data directory"
    for d in {a.data_dir, *(p.parent for p in files)}:
        (d / "leftover.tmp").write_bytes(os.urandom(100))
    for p in files:
        data = p.read_bytes()
        p.with_name(p.name + ".tmp").write_bytes(data[: len(data) // 2])

    b = server(data_dir=a.data_dir)
    c = b.client
    assert {ex["id"], pending["exemplar"]["id"]} <= {e["id"] for e in c.list_exemplars()}
    assert fld["id"] in [f["id"] for f in c.list_fields()]
    assert vol["id"] in [v["id"] for v in c.list_volumes()]
    assert c.get_exemplar(ex["id"])["state"] == "ready"
    assert c.get_exemplar(ex["id"])["name"] == "wood"
    assert c.get_field(fld["id"])["revision"] == 1
    assert c.get_volume(vol["id"]) == volume_before
    assert c.get_exemplar_table(ex["id"]) == table
    assert c.get_field_file(fld["id"]) == stf
    assert c.slice(vol["id"], "z", 5, (24, 16), dtype="png_bytes") == png
    assert np.array_equal(c.slice(vol["id"], "y", 2, (24, 16), origin=(-5, 1)), raw)

    # the acknowledged upload is analysed after the restart
    got = wait_ready(c, pending["exemplar"]["id"])
    assert got["state"] == "ready", got
    assert got["name"] == "pending"
    assert got["job_id"] == pending["job"]["id"], got
    job = c.wait_for_job(got["job_id"], timeout=60, poll=0.1)
    assert job["state"] == "succeeded" and job["percent"] == 100
    cli = tmp_path / "spots.stx"
    run_cli("analyze", exemplars["spots"], *ANALYSIS_CLI, "-o", cli)
    assert c.get_exemplar_table(got["id"]) == cli.read_bytes()


def test_sigterm_exits_cleanly_and_restarts(server, exemplars):
    a = server()
    ex = upload_ready(a.client, exemplars["stripes"])
    vol = a.client.create_volume(exemplar=ex["id"], field="axis:0,0,1,30", seed=2)
    before = a.client.slice(vol["id"], "z", 1, (16, 16))
    t0 = time.monotonic()
    code = a.stop(grace=10)
    assert time.monotonic() - t0 < 10, "SIGTERM did not stop the server within 10 s"
    assert code == 0, f"exit status {code} after SIGTERM\n{a.log()}"
    b = server(data_dir=a.data_dir)
    assert b.client.get_exemplar(ex["id"])["state"] == "ready"
    assert np.array_equal(b.client.slice(vol["id"], "z", 1, (16, 16)), before)


def test_healthz_says_stopping_with_503_during_shutdown(server, exemplars):
    """Once SIGTERM arrives /healthz answers 503 "stopping" (balancers and Kubernetes take the
    replica out) while running requests finish or reach their grace period."""
    a = server()
    ex = upload_ready(a.client, exemplars["stripes"])
    vol = a.client.create_volume(exemplar=ex["id"], seed=3)
    assert requests.get(f"{a.url}/healthz", timeout=10).status_code == 200
    slow = threading.Thread(target=lambda: requests.get(
        f"{a.url}/v1/volumes/{vol['id']}/slice", params={"axis": "z", "at": 0, "size": "2048,2048"}, timeout=60))
    slow.start()
    deadline = time.monotonic() + 20
    while requests.get(f"{a.url}/healthz", timeout=10).json()["workers_busy"] == 0:
        assert time.monotonic() < deadline, "the slow slice never started"
        time.sleep(0.02)
    a.proc.send_signal(signal.SIGTERM)
    seen = None
    while time.monotonic() < deadline:
        try:
            r = requests.get(f"{a.url}/healthz", timeout=10)
        except requests.ConnectionError:
            break
        if r.status_code == 503:
            seen = r.json()
            break
        time.sleep(0.02)
    slow.join()
    assert seen is not None and seen["status"] == "stopping", a.log()
    assert a.proc.wait(15) == 0, a.log()


def test_volumes_stored_before_a_default_changed_keep_their_voxels(server, exemplars):
    """New volumes pin the appearance-changing defaults they were made with (typicality, fine
    passes, init, color, finest_subpass_size, balance, finest_typicality_scale, init_band, finest_match,
    finest_sources); a volume.json
    written before those were pinned (none anywhere) comes back with the values its voxels were
    synthesized with (typicality 0, two passes, slab init, mean colors, 8 finest subpasses, no
    usage balance, the same typicality at the finest level, cubic slab subparts, whole triples at
    the finest level, the 3x3 sources where it matches plane-wise), and one written at each later
    era (typicality, 0.5 until auto, and passes pinned; then init; then color; then
    finest_subpass_size; then balance; then finest_typicality_scale; then init_band; then
    finest_match) with the older values of the
    keys it lacks: no release changes a stored volume's look."""
    a = server()
    c = a.client
    ex = upload_ready(c, exemplars["spots"])
    vol = c.create_volume(exemplar=ex["id"], seed=4)
    assert vol["params"] == {"typicality": "auto", "passes": 1, "init": "auto", "color": "auto", "finest_subpass_size": 1,
                             "balance": 1.0, "finest_typicality_scale": 0.7, "init_band": 8,
                             "finest_match": "auto", "finest_sources": "square"}, vol
    # typicality auto is 0.5 on one image (on three planes 0.35: test_robustness.py)
    half = c.create_volume(exemplar=ex["id"], seed=4, params={"typicality": 0.5})
    assert np.array_equal(c.slice(vol["id"], "z", 2, (24, 24)), c.slice(half["id"], "z", 2, (24, 24)))
    # what volumes stored before any of these keys was pinned were made with
    made_with = {"typicality": 0, "passes": 2, "init": "slab", "color": "mean", "finest_subpass_size": 2, "balance": 0,
                 "finest_typicality_scale": 1, "init_band": 0, "finest_match": "triple", "finest_sources": "square"}
    legacy = c.create_volume(exemplar=ex["id"], seed=4, params=made_with)
    want = c.slice(legacy["id"], "z", 2, (24, 24))
    assert not np.array_equal(c.slice(vol["id"], "z", 2, (24, 24)), want), "the defaults changed nothing"
    # made when typicality (0.5, before auto) and passes were pinned but init was not
    middle = c.create_volume(exemplar=ex["id"], seed=5, params={"typicality": 0.5})
    slab = c.create_volume(exemplar=ex["id"], seed=5, params={"init": "slab", "color": "mean", "finest_subpass_size": 2,
                                                                "balance": 0, "finest_typicality_scale": 1, "init_band": 0, "finest_match": "triple"})
    want_middle = c.slice(slab["id"], "z", 2, (24, 24))
    assert not np.array_equal(c.slice(middle["id"], "z", 2, (24, 24)), want_middle), "init changed nothing"
    # made when init was pinned but color was not
    late = c.create_volume(exemplar=ex["id"], seed=6, params={"typicality": 0.5})
    mean = c.create_volume(exemplar=ex["id"], seed=6, params={"color": "mean", "finest_subpass_size": 2, "balance": 0,
                                                              "finest_typicality_scale": 1, "init_band": 0, "finest_match": "triple"})
    want_late = c.slice(mean["id"], "z", 2, (24, 24))
    assert not np.array_equal(c.slice(late["id"], "z", 2, (24, 24)), want_late), "color changed nothing"
    # made when color was pinned but finest_subpass_size was not
    # (color was medoid by default then; it is pinned, so a later default changes nothing stored)
    recent = c.create_volume(exemplar=ex["id"], seed=7, params={"typicality": 0.5, "color": "medoid"})
    eight = c.create_volume(exemplar=ex["id"], seed=7, params={"color": "medoid", "finest_subpass_size": 2, "balance": 0,
                                                               "finest_typicality_scale": 1, "init_band": 0, "finest_match": "triple"})
    want_recent = c.slice(eight["id"], "z", 2, (24, 24))
    assert not np.array_equal(c.slice(recent["id"], "z", 2, (24, 24)), want_recent), "subpasses changed nothing"
    # made when finest_subpass_size was pinned but balance was not
    newest = c.create_volume(exemplar=ex["id"], seed=8, params={"typicality": 0.5, "color": "medoid"})
    unbalanced = c.create_volume(exemplar=ex["id"], seed=8, params={"color": "medoid", "balance": 0,
                                                                     "finest_typicality_scale": 1, "init_band": 0, "finest_match": "triple"})
    want_newest = c.slice(unbalanced["id"], "z", 2, (24, 24))
    assert not np.array_equal(c.slice(newest["id"], "z", 2, (24, 24)), want_newest), "balance changed nothing"
    # made when balance was pinned but finest_typicality_scale was not
    balanced = c.create_volume(exemplar=ex["id"], seed=9)
    same = c.create_volume(exemplar=ex["id"], seed=9, params={"finest_typicality_scale": 1, "init_band": 0, "finest_match": "triple"})
    want_balanced = c.slice(same["id"], "z", 2, (24, 24))
    assert not np.array_equal(c.slice(balanced["id"], "z", 2, (24, 24)), want_balanced), "the finest scale changed nothing"
    # made when finest_typicality_scale was pinned but init_band was not (slab init: bands change its
    # subparts; the 48^2 cut crosses a band seam, 8 coarsest voxels of spacing 4 from the origin)
    scaled = c.create_volume(exemplar=ex["id"], seed=10, params={"init": "slab"})
    cubic = c.create_volume(exemplar=ex["id"], seed=10, params={"init": "slab", "init_band": 0, "finest_match": "triple"})
    want_scaled = c.slice(cubic["id"], "z", 2, (48, 48))
    assert not np.array_equal(c.slice(scaled["id"], "z", 2, (48, 48)), want_scaled), "the init band changed nothing"
    # made when init_band was pinned but finest_match was not (auto is plane-wise on this
    # three-level table; before, the finest level matched whole triples)
    banded = c.create_volume(exemplar=ex["id"], seed=11)
    tripled = c.create_volume(exemplar=ex["id"], seed=11, params={"finest_match": "triple"})
    want_banded = c.slice(tripled["id"], "z", 2, (24, 24))
    assert not np.array_equal(c.slice(banded["id"], "z", 2, (24, 24)), want_banded), "the finest match changed nothing"
    # made when finest_match was pinned but finest_sources was not (plane-wise matching
    # continued the 3x3 neighbours, still the default)
    matched = c.create_volume(exemplar=ex["id"], seed=12)
    want_matched = c.slice(matched["id"], "z", 2, (24, 24))
    crossed = c.create_volume(exemplar=ex["id"], seed=12, params={"finest_sources": "cross"})
    assert not np.array_equal(c.slice(crossed["id"], "z", 2, (24, 24)), want_matched), "the sources changed nothing"
    assert a.stop(grace=10) == 0
    def forget(volume_id, *keys):
        """Rewrites the stored volume.json as a release that did not pin `keys` wrote it (no
        keys: one that stored no params at all)."""
        path = next(p for p in a.data_dir.rglob("volume.json") if volume_id in str(p))
        info = json.loads(path.read_text())
        if not keys:
            del info["params"], info["spec"]["params"]
        for params in (info["params"], info["spec"]["params"]) if keys else ():
            for key in keys:
                del params[key]
        path.write_text(json.dumps(info))

    forget(vol["id"])
    forget(middle["id"], "init", "color", "finest_subpass_size", "balance", "finest_typicality_scale", "init_band", "finest_match", "finest_sources")
    forget(late["id"], "color", "finest_subpass_size", "balance", "finest_typicality_scale", "init_band", "finest_match", "finest_sources")
    forget(recent["id"], "finest_subpass_size", "balance", "finest_typicality_scale", "init_band", "finest_match", "finest_sources")
    forget(newest["id"], "balance", "finest_typicality_scale", "init_band", "finest_match", "finest_sources")
    forget(balanced["id"], "finest_typicality_scale", "init_band", "finest_match", "finest_sources")
    forget(scaled["id"], "init_band", "finest_match", "finest_sources")
    forget(banded["id"], "finest_match", "finest_sources")
    forget(matched["id"], "finest_sources")
    b = server(data_dir=a.data_dir)
    # each era's volume comes back with the values it pinned, and for every key it lacks the
    # value its voxels were made with
    eras = [(vol, {}, want, 24),
            (middle, {"typicality": 0.5, "passes": 1}, want_middle, 24),
            (late, {"typicality": 0.5, "passes": 1, "init": "auto"}, want_late, 24),
            (recent, {"typicality": 0.5, "passes": 1, "init": "auto", "color": "medoid"}, want_recent, 24),
            (newest, {"typicality": 0.5, "passes": 1, "init": "auto", "color": "medoid", "finest_subpass_size": 1},
             want_newest, 24),
            (balanced, {"typicality": "auto", "passes": 1, "init": "auto", "color": "auto", "finest_subpass_size": 1,
                        "balance": 1.0}, want_balanced, 24),
            (scaled, {"typicality": "auto", "passes": 1, "color": "auto", "finest_subpass_size": 1, "balance": 1.0,
                      "finest_typicality_scale": 0.7}, want_scaled, 48),
            (banded, {"typicality": "auto", "passes": 1, "init": "auto", "color": "auto", "finest_subpass_size": 1,
                      "balance": 1.0, "finest_typicality_scale": 0.7, "init_band": 8}, want_banded, 24),
            (matched, {"typicality": "auto", "passes": 1, "init": "auto", "color": "auto", "finest_subpass_size": 1,
                       "balance": 1.0, "finest_typicality_scale": 0.7, "init_band": 8, "finest_match": "auto"},
             want_matched, 24)]
    for volume, pinned, pixels, side in eras:
        got = b.client.get_volume(volume["id"])
        assert got["params"] == {**made_with, **pinned}, got
        assert np.array_equal(b.client.slice(volume["id"], "z", 2, (side, side)), pixels), volume["id"]
