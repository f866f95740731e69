"""Several `solidtex serve` replicas on one --data directory behave as one service (issue #16,
first step): what one acknowledges the others read through the store, deletions reach them, and
an analysis job is claimed by a lease (exemplars/<id>/lease) that another replica takes over
once it expires."""
import json
import os
import subprocess
import time

import numpy as np
import pytest
import requests

from support import ANALYSIS, CUBE_OFF, http_status, small_exemplar, solidtex_bin, wait_job, wait_job_running

SKETCH = {
    "domain": {"min": [0, 0, 0], "max": [32, 32, 32], "shortest_side_cells": 8},
    "curves": [{"points": [[4, 4, 16], [28, 28, 16]], "plane_normal": [0, 0, 1], "axis": "x"}],
}


def test_two_replicas_share_uploads_fields_meshes_volumes_and_deletions(server, tmp_path):
    a = server()
    b = server(data_dir=a.data_dir)
    up = a.client.upload_exemplar(small_exemplar(tmp_path, "noise", 32), name="shared", **ANALYSIS)
    ex_id, job_id = up["exemplar"]["id"], up["job"]["id"]
    # visible through B at once (read-through), analysed once: by A, whose lease B respects
    assert b.client.get_exemplar(ex_id)["state"] == "analyzing"
    assert wait_job(b.client, job_id)["state"] == "succeeded"
    assert "took over" not in b.log(), b.log()
    ex_a, ex_b = a.client.get_exemplar(ex_id), b.client.get_exemplar(ex_id)
    assert ex_b["state"] == "ready" and ex_b["name"] == "shared", ex_b
    assert ex_b["table_bytes"] == ex_a["table_bytes"] and ex_b["levels"] == ex_a["levels"]
    assert ex_id in [e["id"] for e in b.client.list_exemplars()]
    assert b.client.get_exemplar_table(ex_id) == a.client.get_exemplar_table(ex_id)
    assert not (a.data_dir / "exemplars" / ex_id / "lease").exists(), "the lease outlived its job"

    fld = a.client.create_field(SKETCH)
    mesh = a.client.upload_mesh(CUBE_OFF, name="cube")
    vol = a.client.create_volume(exemplar=ex_id, field={"id": fld["id"]}, seed=3)
    assert b.client.get_field(fld["id"]) == a.client.get_field(fld["id"])
    assert b.client.get_field_file(fld["id"]) == a.client.get_field_file(fld["id"])
    assert fld["id"] in [f["id"] for f in b.client.list_fields()]
    assert b.client.get_mesh(mesh["id"]) == a.client.get_mesh(mesh["id"])
    assert mesh["id"] in [m["id"] for m in b.client.list_meshes()]
    assert b.client.get_volume(vol["id"]) == a.client.get_volume(vol["id"])
    assert vol["id"] in [v["id"] for v in b.client.list_volumes()]
    # a slice from B equals A's, bit for bit (B builds the volume from the store)
    assert (b.client.slice(vol["id"], "z", 3, (16, 16), dtype="png_bytes")
            == a.client.slice(vol["id"], "z", 3, (16, 16), dtype="png_bytes"))
    assert np.array_equal(b.client.slice(vol["id"], "x", 1, (12, 8), origin=(-3, 2)),
                          a.client.slice(vol["id"], "x", 1, (12, 8), origin=(-3, 2)))
    # a curve added through B is A's next revision too
    curve = {"points": [[4, 28, 16], [28, 4, 16]], "plane_normal": [0, 0, 1], "axis": "y"}
    assert b.client.add_curve(fld["id"], curve)["revision"] == 2
    assert a.client.get_field(fld["id"])["revision"] == 2
    assert a.client.get_field_file(fld["id"]) == b.client.get_field_file(fld["id"])

    # deleted through A: 404 through B (which had them loaded), and gone from B's lists
    a.client.delete_volume(vol["id"])
    assert http_status(f"{b.url}/v1/volumes/{vol['id']}") == 404
    assert http_status(f"{b.url}/v1/volumes/{vol['id']}/slice?axis=z&at=0&size=8,8") == 404
    assert vol["id"] not in [v["id"] for v in b.client.list_volumes()]
    a.client.delete_field(fld["id"])
    a.client.delete_mesh(mesh["id"])
    assert http_status(f"{b.url}/v1/fields/{fld['id']}") == 404
    assert http_status(f"{b.url}/v1/meshes/{mesh['id']}") == 404
    a.client.delete_exemplar(ex_id)
    assert http_status(f"{b.url}/v1/exemplars/{ex_id}") == 404
    assert http_status(f"{b.url}/v1/jobs/{job_id}") == 404
    assert ex_id not in [e["id"] for e in b.client.list_exemplars()]


def test_a_killed_replicas_analysis_is_finished_by_another_after_its_lease_expires(server, tmp_path):
    lease = 2.0
    a = server("--job-lease-seconds", lease)
    b = server("--job-lease-seconds", lease, data_dir=a.data_dir)
    up = a.client.upload_exemplar(small_exemplar(tmp_path, "spots", 48), name="orphan", **ANALYSIS)
    ex_id, job_id = up["exemplar"]["id"], up["job"]["id"]
    wait_job_running(a.client, job_id, "the analysis never started on A")
    a.kill()  # mid-analysis: no result.json, A's lease left behind
    lease_path = a.data_dir / "exemplars" / ex_id / "lease"
    held = json.loads(lease_path.read_text())
    assert held["pid"] == a.proc.pid and held["expires"] > time.time(), held
    # As if A ran on another host (so that B cannot see that the process is gone): B must wait
    # for the lease to expire.
    held.update(host="another-host.invalid", expires=time.time() + lease)
    tmp = lease_path.with_name(".lease.test")
    tmp.write_text(json.dumps(held))
    os.replace(tmp, lease_path)
    t_expiry = time.monotonic() + lease
    job = b.client.get_job(job_id)
    assert job["state"] == "running" and job["exemplar_id"] == ex_id, job
    while time.monotonic() < t_expiry - 0.5:  # B reads it but leaves it to its live owner
        assert b.client.get_exemplar(ex_id)["state"] == "analyzing"
        time.sleep(0.2)
    assert "took over" not in b.log(), b.log()
    job = wait_job(b.client, job_id)
    assert job["state"] == "succeeded", job
    assert time.monotonic() >= t_expiry - 0.3
    assert f"took over the analysis of exemplar {ex_id}" in b.log(), b.log()
    ex = b.client.get_exemplar(ex_id)
    assert ex["state"] == "ready" and ex["name"] == "orphan", ex
    assert (a.data_dir / "exemplars" / ex_id / "result.json").exists()
    assert not lease_path.exists(), "the lease outlived its job"
    # the volume of the finished exemplar is usable
    vol = b.client.create_volume(exemplar=ex_id, seed=1)
    assert b.client.slice(vol["id"], "z", 0, (8, 8)).shape == (8, 8, 3)


@pytest.mark.parametrize("value", ["0.1", "3601", "x"])
def test_job_lease_seconds_is_validated(value, tmp_path):
    proc = subprocess.run([str(solidtex_bin()), "serve", "--port", "1", "--data", str(tmp_path / "d"),
                           "--job-lease-seconds", value], capture_output=True, text=True, timeout=30)
    assert proc.returncode != 0
    assert "--job-lease-seconds" in proc.stderr, proc.stderr
