"""`solidtex serve --storage s3://...` against a real S3-compatible server (versitygw, built once
by scripts/versitygw.sh and cached): the storage contract tests of the C++ backend, two
replicas sharing one bucket prefix (an upload acknowledged by one is visible to all and
analysed once; a killed replica's analysis is taken over once its lease expires), and clear
start-up errors for wrong credentials, an unknown bucket and an unreachable endpoint.

Skipped, with a message, when the versitygw binary is not built: building it takes about
4 CPU-minutes, so this test never builds it (run `scripts/versitygw.sh build` once)."""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import subprocess
import time
import uuid
from pathlib import Path

import numpy as np
import pytest
import requests

from support import ANALYSIS, CUBE_OFF, REPO, free_port, http_status, small_exemplar, solidtex_bin, wait_job, wait_job_running
from solidtex_client import Client

SCRIPT = REPO / "scripts" / "versitygw.sh"
ACCESS, SECRET, BUCKET = "solidtex", "solidtex-secret", "solidtex"
SKETCH = {
    "domain": {"min": [0, 0, 0], "max": [32, 32, 32], "shortest_side_cells": 8},
    "curves": [{"points": [[4, 4, 16], [28, 28, 16]], "plane_normal": [0, 0, 1], "axis": "x"}],
}


def versitygw_binary() -> Path | None:
    proc = subprocess.run([str(SCRIPT), "path"], capture_output=True, text=True)
    return Path(proc.stdout.strip()) if proc.returncode == 0 else None


@pytest.fixture(scope="module")
def gateway(tmp_path_factory):
    """A versitygw on a free port serving a fresh directory (bucket `solidtex`)."""
    if versitygw_binary() is None:
        pytest.skip("versitygw is not built (cached): run `scripts/versitygw.sh build` once "
                    "(about 4 CPU-minutes) to run the S3 storage tests")
    root = tmp_path_factory.mktemp("s3")
    port = free_port()
    log = open(root / "versitygw.log", "wb")
    env = {**os.environ, "ROOT_ACCESS_KEY": ACCESS, "ROOT_SECRET_KEY": SECRET}
    proc = subprocess.Popen([str(SCRIPT), "run", str(port), str(root / "data")], stdout=log,
                            stderr=subprocess.STDOUT, env=env)
    url = f"http://127.0.0.1:{port}"
    end = time.monotonic() + 30
    while True:
        try:
            requests.get(url, timeout=1)  # any answer (403 unsigned) means it listens
            break
        except requests.RequestException:
            assert proc.poll() is None, (root / "versitygw.log").read_text()
            assert time.monotonic() < end, "versitygw did not start"
            time.sleep(0.1)
    yield {"url": url, "root": root / "data", "port": port}
    proc.terminate()
    proc.wait(10)
    log.close()


def s3_env(**override):
    env = {k: v for k, v in os.environ.items() if not k.startswith("AWS_")}
    env.update(AWS_ACCESS_KEY_ID=ACCESS, AWS_SECRET_ACCESS_KEY=SECRET)
    env.update(override)
    return env


class Replica:
    """One `solidtex serve --storage s3://...` process."""

    def __init__(self, log_path: Path, storage: str, endpoint: str, *flags, env=None):
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.log_path = log_path
        self.cmd = [str(solidtex_bin()), "serve", "--host", "127.0.0.1", "--port", str(self.port),
                    "--storage", storage, "--s3-endpoint", endpoint, *[str(f) for f in flags]]
        self._log = open(log_path, "wb")
        self.proc = subprocess.Popen(self.cmd, stdout=self._log, stderr=subprocess.STDOUT,
                                     env=env or s3_env())
        self.client = Client(self.url, timeout=120)
        end = time.monotonic() + 30
        while True:
            assert self.proc.poll() is None, f"exited {self.proc.returncode}: {self.log()}"
            try:
                if requests.get(self.url + "/healthz", timeout=2).status_code == 200:
                    return
            except requests.RequestException:
                pass
            assert time.monotonic() < end, f"not healthy: {self.log()}"
            time.sleep(0.05)

    def log(self) -> str:
        self._log.flush()
        return self.log_path.read_text(errors="replace")

    def kill(self):
        self.proc.send_signal(signal.SIGKILL)
        self.proc.wait(10)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.kill()
        self._log.close()


@pytest.fixture
def replicas(gateway, tmp_path):
    """Factory: ``replicas(*flags, prefix=None)`` starts a replica on the bucket prefix of this
    test (a fresh one per test unless given); all are stopped at teardown."""
    started = []
    default_prefix = f"{BUCKET}/{uuid.uuid4().hex[:12]}"

    def start(*flags, prefix=None, env=None):
        r = Replica(tmp_path / f"replica{len(started)}.log", f"s3://{prefix or default_prefix}",
                    gateway["url"], *flags, env=env)
        started.append(r)
        return r

    start.prefix = default_prefix
    yield start
    for r in reversed(started):
        r.stop()


def s3_object(gateway, key, body: bytes | None = None):
    """GET (body None) or PUT of one object with curl's own SigV4 signing: the test's view of
    the bucket, independent of the code under test."""
    url = f"{gateway['url']}/{BUCKET}/{key}"
    cmd = ["curl", "-sS", "--fail-with-body", "--aws-sigv4", "aws:amz:us-east-1:s3",
           "--user", f"{ACCESS}:{SECRET}"]
    if body is None:
        cmd += ["-H", "x-amz-content-sha256: " + hashlib.sha256(b"").hexdigest(), url]
        return subprocess.run(cmd, capture_output=True, check=True, timeout=30).stdout
    cmd += ["-H", "x-amz-content-sha256: " + hashlib.sha256(body).hexdigest(), "-X", "PUT",
            "--data-binary", "@-", url]
    subprocess.run(cmd, input=body, capture_output=True, check=True, timeout=30)
    return None


def test_the_storage_contract_holds_on_s3(gateway):
    tests = solidtex_bin().parent / "solidtex_server_tests"
    if not tests.is_file():
        pytest.skip(f"{tests} is not built")
    env = s3_env(SOLIDTEX_TEST_S3_STORAGE=f"s3://{BUCKET}/contract",
                 SOLIDTEX_TEST_S3_ENDPOINT=gateway["url"])
    proc = subprocess.run([str(tests), "--gtest_filter=Backends/StorageContract.*/s3"],
                          capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stdout[-6000:] + proc.stderr[-2000:]
    assert "[  SKIPPED ]" not in proc.stdout, proc.stdout
    assert "[  PASSED  ] 7 tests" in proc.stdout, proc.stdout[-3000:]


def test_two_replicas_on_one_bucket_behave_as_one_service(replicas, gateway, tmp_path):
    a = replicas()
    b = replicas()
    up = a.client.upload_exemplar(small_exemplar(tmp_path, "noise", 32), name="shared", **ANALYSIS)
    ex_id, job_id = up["exemplar"]["id"], up["job"]["id"]
    # acknowledged by A: visible through B at once, analysed once (by A, whose lease B respects)
    assert b.client.get_exemplar(ex_id)["state"] == "analyzing"
    assert wait_job(b.client, job_id, seconds=90)["state"] == "succeeded"
    assert "took over" not in b.log(), b.log()
    ex_a, ex_b = a.client.get_exemplar(ex_id), b.client.get_exemplar(ex_id)
    assert ex_b["state"] == "ready" and ex_b["name"] == "shared", ex_b
    assert ex_b["table_bytes"] == ex_a["table_bytes"] and ex_b["levels"] == ex_a["levels"]
    assert b.client.get_exemplar_table(ex_id) == a.client.get_exemplar_table(ex_id)
    assert ex_id in [e["id"] for e in b.client.list_exemplars()]
    # The objects are where the layout says, the lease gone once the job ended.
    prefix = replicas.prefix.split("/", 1)[1]
    assert json.loads(s3_object(gateway, f"{prefix}/exemplars/{ex_id}/meta.json"))["name"] == "shared"
    with pytest.raises(subprocess.CalledProcessError):
        s3_object(gateway, f"{prefix}/exemplars/{ex_id}/lease")

    fld = a.client.create_field(SKETCH)
    mesh = a.client.upload_mesh(CUBE_OFF, name="cube")
    vol = a.client.create_volume(exemplar=ex_id, field={"id": fld["id"]}, seed=3)
    assert b.client.get_field_file(fld["id"]) == a.client.get_field_file(fld["id"])
    assert b.client.get_mesh(mesh["id"]) == a.client.get_mesh(mesh["id"])
    assert b.client.get_volume(vol["id"]) == a.client.get_volume(vol["id"])
    assert vol["id"] in [v["id"] for v in b.client.list_volumes()]
    # B builds the volume from the bucket: its cut equals A's bit for bit
    assert np.array_equal(b.client.slice(vol["id"], "x", 1, (12, 8), origin=(-3, 2)),
                          a.client.slice(vol["id"], "x", 1, (12, 8), origin=(-3, 2)))
    curve = {"points": [[4, 28, 16], [28, 4, 16]], "plane_normal": [0, 0, 1], "axis": "y"}
    assert b.client.add_curve(fld["id"], curve)["revision"] == 2
    assert a.client.get_field(fld["id"])["revision"] == 2

    # a restarted replica finds everything in the bucket
    c = replicas()
    assert c.client.get_exemplar(ex_id)["state"] == "ready"
    assert c.client.get_field(fld["id"])["revision"] == 2

    # deleted through A: 404 through B and C
    a.client.delete_volume(vol["id"])
    a.client.delete_field(fld["id"])
    a.client.delete_mesh(mesh["id"])
    a.client.delete_exemplar(ex_id)
    for r in (b, c):
        assert http_status(f"{r.url}/v1/volumes/{vol['id']}") == 404
        assert http_status(f"{r.url}/v1/fields/{fld['id']}") == 404
        assert http_status(f"{r.url}/v1/meshes/{mesh['id']}") == 404
        assert http_status(f"{r.url}/v1/exemplars/{ex_id}") == 404
    with pytest.raises(subprocess.CalledProcessError):
        s3_object(gateway, f"{prefix}/exemplars/{ex_id}/meta.json")


def test_a_killed_replicas_analysis_is_taken_over_once_its_lease_expires(replicas, gateway, tmp_path):
    lease = 3.0
    a = replicas("--job-lease-seconds", lease)
    b = replicas("--job-lease-seconds", lease)
    up = a.client.upload_exemplar(small_exemplar(tmp_path, "spots", 48), name="orphan", **ANALYSIS)
    ex_id, job_id = up["exemplar"]["id"], up["job"]["id"]
    wait_job_running(a.client, job_id, "the analysis never started on A")
    a.kill()  # mid-analysis: no result.json, A's lease left in the bucket
    key = f"{replicas.prefix.split('/', 1)[1]}/exemplars/{ex_id}/lease"
    held = json.loads(s3_object(gateway, key))
    assert held["pid"] == a.proc.pid, held
    # As if A ran on another host (B cannot see that the process is gone): B must wait until
    # the lease is older than its length, by the server's clock.
    held.update(host="another-host.invalid")
    s3_object(gateway, key, json.dumps(held).encode())
    t_written = time.monotonic()
    assert b.client.get_job(job_id)["state"] == "running"
    while time.monotonic() < t_written + lease - 1.2:  # Last-Modified has 1 s resolution
        assert b.client.get_exemplar(ex_id)["state"] == "analyzing"
        time.sleep(0.2)
    assert "took over" not in b.log(), b.log()
    job = wait_job(b.client, job_id, seconds=90)
    assert job["state"] == "succeeded", job
    assert f"took over the analysis of exemplar {ex_id}" in b.log(), b.log()
    with pytest.raises(subprocess.CalledProcessError):
        s3_object(gateway, key)  # released after the result
    vol = b.client.create_volume(exemplar=ex_id, seed=1)
    assert b.client.slice(vol["id"], "z", 0, (8, 8)).shape == (8, 8, 3)


def test_a_killed_replicas_analysis_on_this_host_is_taken_over_at_once(replicas, tmp_path):
    a = replicas("--job-lease-seconds", 600)
    b = replicas("--job-lease-seconds", 600)
    up = a.client.upload_exemplar(small_exemplar(tmp_path, "spots", 48), name="orphan", **ANALYSIS)
    job_id = up["job"]["id"]
    wait_job_running(a.client, job_id, "the analysis never started on A")
    a.kill()
    t0 = time.monotonic()
    assert wait_job(b.client, job_id, seconds=90)["state"] == "succeeded"
    assert time.monotonic() - t0 < 60  # not the 600 s lease
    assert "took over" in b.log(), b.log()


def startup_error(gateway, tmp_path, storage, endpoint, env):
    cmd = [str(solidtex_bin()), "serve", "--port", str(free_port()), "--storage", storage,
           "--s3-endpoint", endpoint]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=env)
    assert proc.returncode != 0, proc.stderr
    return proc.stderr


def test_bad_credentials_bucket_or_endpoint_stop_start_up_with_a_clear_error(gateway, tmp_path):
    ok = f"s3://{BUCKET}/errors"
    err = startup_error(gateway, tmp_path, ok, gateway["url"], s3_env(AWS_SECRET_ACCESS_KEY="wrong"))
    assert "refused the credentials" in err and "AWS_SECRET_ACCESS_KEY" in err, err
    err = startup_error(gateway, tmp_path, ok, gateway["url"], s3_env(AWS_ACCESS_KEY_ID="nobody"))
    assert "refused the credentials" in err and "AWS_ACCESS_KEY_ID" in err, err
    err = startup_error(gateway, tmp_path, "s3://no-such-bucket/x", gateway["url"], s3_env())
    assert "no-such-bucket" in err and "does not exist" in err, err
    closed = f"http://127.0.0.1:{free_port()}"
    err = startup_error(gateway, tmp_path, ok, closed, s3_env())
    assert "cannot reach the S3 endpoint " + closed in err, err
    env = s3_env()
    del env["AWS_ACCESS_KEY_ID"]
    err = startup_error(gateway, tmp_path, ok, gateway["url"], env)
    assert "AWS_ACCESS_KEY_ID" in err, err
    err = startup_error(gateway, tmp_path, ok, "", s3_env())
    assert "--s3-endpoint" in err, err
    err = startup_error(gateway, tmp_path, "s3://Bad_Bucket", gateway["url"], s3_env())
    assert "--storage" in err, err


def test_the_store_going_away_answers_502_and_coming_back_heals(replicas, gateway, tmp_path):
    a = replicas()
    fld = a.client.create_field(SKETCH)
    mesh = a.client.upload_mesh(CUBE_OFF, name="cube")
    # Make the bucket unreachable for this replica's requests: stop the gateway's bucket by
    # renaming its directory (versitygw then answers NoSuchBucket), then put it back.
    bucket_dir = gateway["root"] / BUCKET
    moved = gateway["root"] / "moved-away"
    bucket_dir.rename(moved)
    try:
        # What the store must confirm answers 502, not 503: the store failed, not this replica
        # (a balancer must not mark it down): a field this replica has never seen, a write.
        unknown = "fld_" + "0" * 16 if fld["id"] != "fld_" + "0" * 16 else "fld_" + "1" * 16
        for r in (requests.get(f"{a.url}/v1/fields/{unknown}", timeout=30),
                  requests.post(f"{a.url}/v1/fields", json=SKETCH, timeout=30)):
            assert r.status_code == 502, (r.status_code, r.text)
            assert r.json()["error"]["code"] == "unavailable" and r.headers.get("Retry-After") == "1", r.text
            assert "does not exist" in r.json()["error"]["message"], r.text
        # What this replica knows it answers from memory: the field (and its frames) and the
        # mesh (and its cleaned triangles); lists too.
        assert a.client.get_field(fld["id"])["revision"] == 1
        assert len(a.client.sample_frames(fld["id"], [0, 0, 0], [2, 2, 2], 1.0)["points"]) == 8
        assert a.client.get_mesh(mesh["id"])["id"] == mesh["id"]
        assert len(a.client.get_mesh_file(mesh["id"])) > 0
        assert fld["id"] in [f["id"] for f in a.client.list_fields()]
        assert mesh["id"] in [m["id"] for m in a.client.list_meshes()]
    finally:
        moved.rename(bucket_dir)
    assert a.client.get_field(fld["id"])["revision"] == 1
    assert a.client.create_field(SKETCH)["revision"] == 1
