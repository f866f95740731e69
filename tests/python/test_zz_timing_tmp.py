"""Persistence: everything acknowledged survives kill -9 and SIGTERM; leftovers are ignored."""
import os
import time

import numpy as np
import pytest

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
    import time as _t; _T=[_t.monotonic()]
    a = server()
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'a = server()', flush=True); _T[0]=_t.monotonic()
    c = a.client
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'c = a.client', flush=True); _T[0]=_t.monotonic()
    ex = upload_ready(c, exemplars["wood"], name="wood")
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'ex = upload_ready(c, exemplars["wood"], ', flush=True); _T[0]=_t.monotonic()
    fld = c.create_field(SKETCH)
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'fld = c.create_field(SKETCH)', flush=True); _T[0]=_t.monotonic()
    vol = c.create_volume(exemplar=ex["id"], field={"id": fld["id"]}, seed=3, name="v")
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'vol = c.create_volume(exemplar=ex["id"],', flush=True); _T[0]=_t.monotonic()
    png = c.slice(vol["id"], "z", 5, (24, 16), dtype="png_bytes")
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'png = c.slice(vol["id"], "z", 5, (24, 16', flush=True); _T[0]=_t.monotonic()
    raw = c.slice(vol["id"], "y", 2, (24, 16), origin=(-5, 1))
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'raw = c.slice(vol["id"], "y", 2, (24, 16', flush=True); _T[0]=_t.monotonic()
    table = c.get_exemplar_table(ex["id"])
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'table = c.get_exemplar_table(ex["id"])', flush=True); _T[0]=_t.monotonic()
    stf = c.get_field_file(fld["id"])
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'stf = c.get_field_file(fld["id"])', flush=True); _T[0]=_t.monotonic()
    volume_before = c.get_volume(vol["id"])
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'volume_before = c.get_volume(vol["id"])', flush=True); _T[0]=_t.monotonic()
    # acknowledged, then the server dies before (or while) analysing it
    pending = c.upload_exemplar(exemplars["spots"], name="pending", **ANALYSIS)
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'pending = c.upload_exemplar(exemplars["s', flush=True); _T[0]=_t.monotonic()
    assert c.last_response.status_code == 202
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert c.last_response.status_code == 20', flush=True); _T[0]=_t.monotonic()
    a.kill()
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'a.kill()', flush=True); _T[0]=_t.monotonic()

    # leftovers of interrupted writes: junk and half-written copies of real files
    files = [p for p in a.data_dir.rglob("*") if p.is_file()]
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'files = [p for p in a.data_dir.rglob("*"', flush=True); _T[0]=_t.monotonic()
    assert files, "the server stored nothing in its data directory"
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert files, "the server stored nothing', flush=True); _T[0]=_t.monotonic()
    for d in {a.data_dir, *(p.parent for p in files)}:
        (d / "leftover.tmp").write_bytes(os.urandom(100))
    for p in files:
        data = p.read_bytes()
        p.with_name(p.name + ".tmp").write_bytes(data[: len(data) // 2])

    b = server(data_dir=a.data_dir)
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'b = server(data_dir=a.data_dir)', flush=True); _T[0]=_t.monotonic()
    c = b.client
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'c = b.client', flush=True); _T[0]=_t.monotonic()
    assert {ex["id"], pending["exemplar"]["id"]} <= {e["id"] for e in c.list_exemplars()}
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert {ex["id"], pending["exemplar"]["i', flush=True); _T[0]=_t.monotonic()
    assert fld["id"] in [f["id"] for f in c.list_fields()]
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert fld["id"] in [f["id"] for f in c.', flush=True); _T[0]=_t.monotonic()
    assert vol["id"] in [v["id"] for v in c.list_volumes()]
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert vol["id"] in [v["id"] for v in c.', flush=True); _T[0]=_t.monotonic()
    assert c.get_exemplar(ex["id"])["state"] == "ready"
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert c.get_exemplar(ex["id"])["state"]', flush=True); _T[0]=_t.monotonic()
    assert c.get_exemplar(ex["id"])["name"] == "wood"
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert c.get_exemplar(ex["id"])["name"] ', flush=True); _T[0]=_t.monotonic()
    assert c.get_field(fld["id"])["revision"] == 1
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert c.get_field(fld["id"])["revision"', flush=True); _T[0]=_t.monotonic()
    assert c.get_volume(vol["id"]) == volume_before
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert c.get_volume(vol["id"]) == volume', flush=True); _T[0]=_t.monotonic()
    assert c.get_exemplar_table(ex["id"]) == table
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert c.get_exemplar_table(ex["id"]) ==', flush=True); _T[0]=_t.monotonic()
    assert c.get_field_file(fld["id"]) == stf
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert c.get_field_file(fld["id"]) == st', flush=True); _T[0]=_t.monotonic()
    assert c.slice(vol["id"], "z", 5, (24, 16), dtype="png_bytes") == png
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert c.slice(vol["id"], "z", 5, (24, 1', flush=True); _T[0]=_t.monotonic()
    assert np.array_equal(c.slice(vol["id"], "y", 2, (24, 16), origin=(-5, 1)), raw)
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert np.array_equal(c.slice(vol["id"],', flush=True); _T[0]=_t.monotonic()

    # the acknowledged upload is analysed after the restart
    got = wait_ready(c, pending["exemplar"]["id"])
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'got = wait_ready(c, pending["exemplar"][', flush=True); _T[0]=_t.monotonic()
    assert got["state"] == "ready", got
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert got["state"] == "ready", got', flush=True); _T[0]=_t.monotonic()
    assert got["name"] == "pending"
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert got["name"] == "pending"', flush=True); _T[0]=_t.monotonic()
    job_id = got.get("job_id") or pending["job"]["id"]
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'job_id = got.get("job_id") or pending["j', flush=True); _T[0]=_t.monotonic()
    job = c.wait_for_job(job_id, timeout=60, poll=0.1)
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'job = c.wait_for_job(job_id, timeout=60,', flush=True); _T[0]=_t.monotonic()
    assert job["state"] == "succeeded" and job["percent"] == 100
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert job["state"] == "succeeded" and j', flush=True); _T[0]=_t.monotonic()
    cli = tmp_path / "spots.stx"
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'cli = tmp_path / "spots.stx"', flush=True); _T[0]=_t.monotonic()
    run_cli("analyze", exemplars["spots"], *ANALYSIS_CLI, "-o", cli)
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'run_cli("analyze", exemplars["spots"], *', flush=True); _T[0]=_t.monotonic()
    assert c.get_exemplar_table(got["id"]) == cli.read_bytes()
    print(f"{_t.monotonic()-_T[0]:6.2f}", 'assert c.get_exemplar_table(got["id"]) =', flush=True); _T[0]=_t.monotonic()


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
