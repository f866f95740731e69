"""The local reference deployment (issue #16; deploy/README.md): three `solidtex serve` replicas
on one store behind nginx (deploy/nginx/nginx.conf.template), started by scripts/cluster.sh.

Run by `make cluster-test` (not part of `make test`). SOLIDTEX_BIN names the executable
(default build/bin/solidtex); CLUSTER_STORAGE=dir|s3 chooses the store (scripts/cluster.sh's
default otherwise)."""
from __future__ import annotations

import json
import random
import shutil
import subprocess
import threading
import time
from pathlib import Path
from typing import Dict, List

import pytest
import requests

from harness import REPO, Cluster

BIN = Path(__import__("os").environ.get("SOLIDTEX_BIN", str(REPO / "build" / "bin" / "solidtex")))
# Small analyses keep the test fast on 2 cores (the values of tests/python/support.py).
ANALYSIS = {"levels": 3, "neighborhood": 5, "candidates": 4, "pca_dims": 8}
RAW = {"Accept": "application/octet-stream"}
RAW_F32 = {"Accept": "application/octet-stream; dtype=float32"}
CUBE_OFF = ("OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
            "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n")
T = 120  # seconds for any one request


def exemplar_png(tmp: Path, kind: str, side: int) -> bytes:
    path = tmp / f"{kind}{side}.png"
    subprocess.run([str(BIN), "exemplar", kind, "-o", str(path), "--size", f"{side},{side}"],
                   check=True, capture_output=True, timeout=120)
    return path.read_bytes()


def upload(url: str, png: bytes, **params) -> requests.Response:
    r = requests.post(f"{url}/v1/exemplars", data=png, headers={"Content-Type": "image/png"},
                      params={**ANALYSIS, **params}, timeout=T)
    assert r.status_code == 202, r.text
    return r


def wait_job(url: str, job_id: str, seconds: float = 180) -> dict:
    end = time.monotonic() + seconds
    while True:
        job = requests.get(f"{url}/v1/jobs/{job_id}", timeout=T).json()
        if job["state"] in ("succeeded", "failed"):
            return job
        assert time.monotonic() < end, f"job {job_id} still {job['state']} after {seconds} s"
        time.sleep(0.1)


def wait_started(url: str, job_id: str, seconds: float = 60) -> None:
    """Polls the replica running a job (its own URL) until the job has left the queue."""
    end = time.monotonic() + seconds
    while requests.get(f"{url}/v1/jobs/{job_id}", timeout=T).json()["state"] == "queued":
        assert time.monotonic() < end, "the analysis never started"
        time.sleep(0.01)


def create_volume(url: str, exemplar_id: str, seed: int) -> str:
    r = requests.post(f"{url}/v1/volumes", json={"exemplar": exemplar_id, "seed": seed}, timeout=T)
    assert r.status_code == 201, r.text
    return r.json()["id"]


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    assert BIN.is_file(), f"{BIN} not found: build it (make build) or set SOLIDTEX_BIN"
    assert shutil.which("nginx") or Path("/usr/sbin/nginx").exists(), \
        "nginx is not installed: scripts/cluster.sh deps (make cluster-test runs it)"
    # nginx or the S3 server, killed, stays down 4 s before its supervisor restarts it: long
    # enough for a balancer that counted the store's failures against replicas to drop them all.
    c = Cluster(tmp_path_factory.mktemp("cluster"), replicas=3, restart_delay=4)
    yield c
    c.stop()


@pytest.fixture(scope="module")
def volume(cluster, tmp_path_factory):
    """A noise exemplar uploaded and analysed through nginx, and a volume of it (seed 5)."""
    r = upload(cluster.url, exemplar_png(tmp_path_factory.mktemp("ex"), "noise", 64), name="noise")
    up = r.json()
    assert wait_job(cluster.url, up["job"]["id"])["state"] == "succeeded"
    return {"exemplar": up["exemplar"]["id"], "id": create_volume(cluster.url, up["exemplar"]["id"], 5)}


def test_answers_are_byte_identical_whichever_replica_serves_them(cluster, volume):
    v = f"/v1/volumes/{volume['id']}"
    asks = [
        ("GET", f"{v}/slice?axis=z&at=3&origin=-5,7&size=48,40", {}, None),
        ("GET", f"{v}/slice?axis=x&at=-2&size=32,24", RAW_F32, None),
        ("GET", f"{v}/slice?axis=y&at=1&size=16,16&scale=1", RAW, None),
        ("POST", f"{v}/cut", {}, {"origin": [1.5, -3, 2], "u": [0.6, 0.8, 0], "v": [-0.48, 0.36, 0.8], "size": [40, 32]}),
        ("GET", f"{v}/region?min=-4,2,9&size=8,8,8", RAW, None),
        ("POST", f"{v}/points", {"Accept": "application/json"}, {"points": [[0, 0, 0], [3.5, -2, 7], [100, 200, -300]]}),
        ("GET", f"{v}/zarr/0/c/0/0/0/0", {}, None),
        ("GET", f"{v}/zarr2/1/0/0/0/1", {}, None),
        ("GET", f"{v}/precomputed/0/0-32_0-32_0-32", {}, None),
        ("GET", f"/v1/exemplars/{volume['exemplar']}/table", {}, None),
    ]
    for method, path, headers, body in asks:
        answers: Dict[str, bytes] = {}
        # Each replica computes its own answer (nothing cached yet), then nginx twice.
        for name, base in [*[(f"replica {i}", u) for i, u in enumerate(cluster.replica_urls)],
                           ("nginx", cluster.url), ("nginx again", cluster.url)]:
            r = requests.request(method, base + path, headers=headers, json=body, timeout=T)
            assert r.status_code == 200, (name, path, r.status_code, r.text[:300])
            answers[name] = r.content
        first = answers["replica 0"]
        assert len(first) > 0
        assert all(a == first for a in answers.values()), \
            (path, {k: (len(a), a == first) for k, a in answers.items()})


def test_an_upload_through_the_balancer_is_analysed_once_and_usable_from_every_replica(cluster, tmp_path):
    r = upload(cluster.url, exemplar_png(tmp_path, "spots", 64), name="spots")
    uploader = cluster.replica_of(r.headers["X-Upstream"])
    ex_id, job_id = r.json()["exemplar"]["id"], r.json()["job"]["id"]
    lease = cluster.store_file("exemplars", ex_id, "lease")
    holders = set()
    states: Dict[int, set] = {i: set() for i in range(len(cluster.replica_urls))}
    end = time.monotonic() + 180
    while True:  # every replica reports the job; the lease, while it exists, is the uploader's
        try:
            holders.add(json.loads(lease.read_text())["pid"])
        except (OSError, ValueError, KeyError):
            pass
        for i, url in enumerate(cluster.replica_urls):
            job = requests.get(f"{url}/v1/jobs/{job_id}", timeout=T).json()
            assert job["id"] == job_id and job["exemplar_id"] == ex_id, job
            states[i].add(job["state"])
        if all("succeeded" in s for s in states.values()):
            break
        assert not any("failed" in s for s in states.values()), states
        assert time.monotonic() < end, states
        time.sleep(0.05)
    assert holders <= {cluster.pid(uploader)}, (holders, cluster.pid(uploader))
    assert cluster.store_file("exemplars", ex_id, "attempts").read_text().strip() == "1"
    assert not lease.exists(), "the lease outlived its job"
    for i in range(len(cluster.replica_urls)):
        log = cluster.replica_log(i)
        assert f"took over the analysis of exemplar {ex_id}" not in log, log[-2000:]
        assert f"re-queued the analysis of exemplar {ex_id}" not in log, log[-2000:]
    tables = {requests.get(f"{u}/v1/exemplars/{ex_id}/table", timeout=T).content for u in cluster.replica_urls}
    assert len(tables) == 1 and len(next(iter(tables))) > 0
    # Usable from every replica: each makes a volume of it; every replica draws each the same.
    for i, url in enumerate(cluster.replica_urls):
        ex = requests.get(f"{url}/v1/exemplars/{ex_id}", timeout=T).json()
        assert ex["state"] == "ready" and ex["name"] == "spots", (i, ex)
        vol = create_volume(url, ex_id, seed=10 + i)
        cuts = {requests.get(f"{u}/v1/volumes/{vol}/slice?axis=z&at={i}&size=16,16", timeout=T).content
                for u in [*cluster.replica_urls, cluster.url]}
        assert len(cuts) == 1, (i, vol)


def slice_once(url: str, path: str, headers=None, method="GET", body=None) -> requests.Response:
    r = requests.request(method, url + path, headers=headers or {}, json=body, timeout=T)
    return r


def test_a_repeated_cut_is_a_cache_hit_at_nginx_and_nothing_mutable_is_cached(cluster, volume):
    v = f"/v1/volumes/{volume['id']}"
    u = cluster.url
    for method, path, body in [("GET", f"{v}/slice?axis=z&at=11&origin=3,4&size=40,40", None),
                               ("POST", f"{v}/cut", {"origin": [2, 0.5, 9], "u": [0, 1, 0], "v": [0.6, 0, 0.8], "size": [32, 32]})]:
        first = slice_once(u, path, method=method, body=body)
        again = slice_once(u, path, method=method, body=body)
        assert first.status_code == again.status_code == 200, first.text
        assert first.headers["X-Cache-Status"] == "MISS" and "X-Upstream" in first.headers, first.headers
        assert again.headers["X-Cache-Status"] == "HIT", again.headers
        assert "X-Upstream" not in again.headers, again.headers  # no replica was asked
        assert again.content == first.content
        # Another representation of the same cut is another entry.
        raw = slice_once(u, path, RAW, method=method, body=body)
        assert raw.headers["X-Cache-Status"] == "MISS" and raw.content != first.content
        assert slice_once(u, path, RAW, method=method, body=body).headers["X-Cache-Status"] == "HIT"
    other = slice_once(u, f"{v}/cut", method="POST", body={"origin": [2, 0.5, 10], "u": [0, 1, 0], "v": [0.6, 0, 0.8], "size": [32, 32]})
    assert other.headers["X-Cache-Status"] == "MISS", "a different cut body must not hit the cached one"

    # Chunks: nginx keeps the app's immutable headers and answers revalidations itself.
    chunk = f"{v}/zarr/0/c/0/0/1/0"
    a, b = slice_once(u, chunk), slice_once(u, chunk)
    assert (a.headers["X-Cache-Status"], b.headers["X-Cache-Status"]) == ("MISS", "HIT")
    assert b.headers["Cache-Control"] == "public, max-age=31536000, immutable" and b.headers["ETag"] == a.headers["ETag"]
    assert b.content == a.content
    nm = slice_once(u, chunk, {"If-None-Match": a.headers["ETag"]})
    assert nm.status_code == 304 and nm.headers["X-Cache-Status"] == "HIT"

    # Never cached: 404s, job status, resources, lists.
    for path in ["/v1/volumes/vol_0000000000000000/slice?axis=z&at=0&size=8,8",
                 f"{v}/zarr/0/c/0/999/0/0",
                 f"/v1/jobs/job_{volume['exemplar'][3:]}", v, "/v1/volumes", "/healthz"]:
        seen = [slice_once(u, path) for _ in range(3)]
        assert all(r.headers.get("X-Cache-Status") != "HIT" for r in seen), (path, [r.headers for r in seen])
        assert all("X-Upstream" in r.headers for r in seen), path
    assert seen[0].status_code == 200
    missing = slice_once(u, "/v1/volumes/vol_0000000000000000/slice?axis=z&at=0&size=8,8")
    assert missing.status_code == 404


def test_neighbouring_cuts_share_a_replica_and_regions_spread_over_all(cluster, volume):
    v = f"/v1/volumes/{volume['id']}"
    # One 100^3 block: slices along z at 40..49 panned within it, and the cut of one of them.
    upstreams = set()
    for k in range(10):
        r = slice_once(cluster.url, f"{v}/slice?axis=z&at={40 + k}&origin={10 + 7 * k},{5 + 3 * k}&size=8,8")
        assert r.headers["X-Cache-Status"] == "MISS", r.headers
        upstreams.add(r.headers["X-Upstream"])
    r = slice_once(cluster.url, f"{v}/cut", method="POST",
                   body={"origin": [12, 30, 45.5], "u": [1, 0, 0], "v": [0, 1, 0], "size": [8, 8]})
    upstreams.add(r.headers["X-Upstream"])
    assert len(upstreams) == 1, upstreams
    # Different blocks are spread: 60 blocks along x land on every replica. (The ring hashes the
    # replicas' ports, which change from run to run; with 18 blocks a replica owning a quarter
    # of it got none about 1 % of the time: 0.75^18 = 0.6 %, per replica.)
    spread = {slice_once(cluster.url, f"{v}/slice?axis=x&at={100 * k + 50}&size=8,8").headers["X-Upstream"]
              for k in range(-30, 30)}
    assert spread == {u.split("//")[1] for u in cluster.replica_urls}, spread


def test_the_k8s_configmap_is_the_rendered_template():
    out = subprocess.run([str(REPO / "scripts" / "cluster.sh"), "k8s-configmap"], capture_output=True,
                         text=True, check=True, timeout=60).stdout
    assert (REPO / "deploy" / "k8s" / "nginx-configmap.yaml").read_text() == out, \
        "deploy/k8s/nginx-configmap.yaml is stale: scripts/cluster.sh k8s-configmap > deploy/k8s/nginx-configmap.yaml"


class Load:
    """Threads sending a mix of cached and new cuts and writes through nginx, recording each
    request's (start, end, what, status, X-Upstream) and the ids of acknowledged objects."""

    def __init__(self, url: str, volume: dict, threads: int = 3, new_cut_threads: int = 4) -> None:
        # The mixed threads spend a store outage mostly in writes, each about a second before
        # its 502 (the S3 client's retries); the new-cut threads keep measuring that cuts of a
        # loaded volume go on meanwhile.
        self.url, self.volume = url, volume
        self.mixed = threads
        self.records: List[tuple] = []
        self.acked: Dict[str, List[str]] = {"volumes": [], "meshes": []}
        self.stop = threading.Event()
        self.lock = threading.Lock()
        self.threads = [threading.Thread(target=self.run, args=(k,), daemon=True)
                        for k in range(threads + new_cut_threads)]
        for t in self.threads:
            t.start()

    def one(self, session: requests.Session, rng: random.Random, mixed: bool = True) -> None:
        v = f"{self.url}/v1/volumes/{self.volume['id']}"
        kind = rng.choice(["cached", "cached", "new", "new", "volume", "mesh"]) if mixed else "new"
        t0 = time.monotonic()
        try:
            if kind == "cached":
                r = session.get(f"{v}/slice?axis=z&at={rng.randrange(4)}&size=24,24", timeout=T)
            elif kind == "new":
                r = session.get(f"{v}/slice?axis={rng.choice('xyz')}&at={rng.randrange(-5000, 5000)}&size=24,24", timeout=T)
            elif kind == "volume":
                r = session.post(f"{self.url}/v1/volumes", json={"exemplar": self.volume["exemplar"],
                                                                 "seed": rng.randrange(1 << 30)}, timeout=T)
            else:
                r = session.post(f"{self.url}/v1/meshes", params={"name": "cube"}, data=CUBE_OFF, timeout=T)
            status, upstream = r.status_code, r.headers.get("X-Upstream", "")
            if status == 201:
                with self.lock:
                    self.acked["volumes" if kind == "volume" else "meshes"].append(r.json()["id"])
        except requests.RequestException as e:
            status, upstream = f"exception: {e}", ""
        with self.lock:
            self.records.append((t0, time.monotonic(), kind, status, upstream))

    def run(self, k: int) -> None:
        rng = random.Random(k)
        with requests.Session() as s:
            while not self.stop.is_set():
                self.one(s, rng, k < self.mixed)

    def finish(self) -> None:
        self.stop.set()
        for t in self.threads:
            t.join(T)


def test_kill_9_of_a_replica_under_load_loses_no_acknowledged_object(cluster, volume, tmp_path):
    v = f"{cluster.url}/v1/volumes/{volume['id']}"
    for at in range(4):  # the load's cached cuts
        assert requests.get(f"{v}/slice?axis=z&at={at}&size=24,24", timeout=T).status_code == 200
    png = exemplar_png(tmp_path, "bricks", 96)
    load = Load(cluster.url, volume)
    try:
        time.sleep(2)
        # An acknowledged upload whose analysis runs on the replica that is then killed.
        r = upload(cluster.url, png, name="orphan")
        victim = cluster.replica_of(r.headers["X-Upstream"])
        victim_addr = r.headers["X-Upstream"]
        ex_id, job_id = r.json()["exemplar"]["id"], r.json()["job"]["id"]
        wait_started(cluster.replica_urls[victim], job_id)
        t_kill = time.monotonic()
        cluster.kill_replica(victim)
        time.sleep(6)
    finally:
        load.finish()
    records = load.records
    after = [x for x in records if x[0] > t_kill + 0.5]
    assert len(after) >= 10, f"the balancer answered only {len(after)} requests after the kill"
    bad = [x for x in records if not isinstance(x[3], int) or x[3] >= 500]
    # A 5xx may only be a request the killed replica held when it died (a POST nginx must not
    # send twice): started before the kill (or on a connection nginx had open to it then).
    beyond = [x for x in bad if not (x[0] <= t_kill + 0.05 and x[1] >= t_kill and x[4] == victim_addr)]
    assert not beyond, (f"5xx beyond the killed replica's in-flight requests (kill at {t_kill:.3f}):",
                        beyond[:10], len(records))
    print(f"{len(records)} requests, {len(after)} after the kill, {len(bad)} in-flight failures "
          f"({len(load.acked['volumes'])} volumes and {len(load.acked['meshes'])} meshes acknowledged)")
    assert load.acked["volumes"] and load.acked["meshes"]

    # The orphaned analysis is finished by a survivor (the lease names a dead process).
    job = wait_job(cluster.url, job_id)
    assert job["state"] == "succeeded", job
    survivors = [i for i in range(len(cluster.replica_urls)) if i != victim]
    assert any(f"took over the analysis of exemplar {ex_id}" in cluster.replica_log(i) for i in survivors)

    def everything_there(urls: List[str]) -> None:
        for url in urls:
            for vid in load.acked["volumes"]:
                assert requests.get(f"{url}/v1/volumes/{vid}", timeout=T).status_code == 200, (url, vid)
            for mid in load.acked["meshes"]:
                assert requests.get(f"{url}/v1/meshes/{mid}", timeout=T).status_code == 200, (url, mid)
            assert requests.get(f"{url}/v1/exemplars/{ex_id}", timeout=T).json()["state"] == "ready"

    everything_there([cluster.url] + [cluster.replica_urls[i] for i in survivors])
    cluster.restart_replica(victim)
    everything_there([cluster.replica_urls[victim]])
    vol = create_volume(cluster.url, ex_id, 3)
    cuts = {requests.get(f"{u}/v1/volumes/{vol}/slice?axis=y&at=2&size=16,16", timeout=T).content
            for u in cluster.replica_urls}
    assert len(cuts) == 1


def test_kill_9_of_the_store_or_of_nginx_loses_no_acknowledged_object(cluster, volume):
    """Issue #16's first target for the two other processes: the S3 server, then nginx, killed
    with -9 under load and restarted by scripts/cluster.sh's supervisor. While the store is
    down, what needs it answers 502 and the rest goes on: nginx does not count those 502s
    against the replicas, so cuts of loaded volumes keep being served."""
    v = f"{cluster.url}/v1/volumes/{volume['id']}"
    cached = f"{v}/slice?axis=z&at=1&size=24,24"
    before = requests.get(cached, timeout=T)
    assert before.status_code == 200
    # Every replica loads the volume (a replica restarted by an earlier test has not), so the
    # outage measures cuts of a loaded volume wherever nginx's hash sends them.
    for u in cluster.replica_urls:
        assert requests.get(f"{u}/v1/volumes/{volume['id']}", timeout=T).status_code == 200
    kills: Dict[str, tuple] = {}
    load = Load(cluster.url, volume)
    try:
        time.sleep(2)
        if cluster.state["storage"]["kind"] == "s3":
            t = time.monotonic()
            kills["storage"] = (t, cluster.wait_restarted("storage", cluster.kill_store()))
            time.sleep(5)
        t = time.monotonic()
        kills["nginx"] = (t, cluster.wait_restarted("nginx", cluster.kill_nginx()))
        time.sleep(4)
    finally:
        load.finish()
    records = load.records
    after_all = max(t_back for _, t_back in kills.values())

    def excused(x) -> bool:
        start, end, _, status, _ = x
        if "storage" in kills:  # writes, and reads of volumes a replica had not loaded: 502
            t_kill, t_back = kills["storage"]
            if status == 502 and end >= t_kill and start <= t_back + 0.5:
                return True
        t_kill, t_back = kills["nginx"]  # nothing listens: connections refused or cut
        return isinstance(status, str) and end >= t_kill and start <= t_back + 0.5

    bad = [x for x in records if not isinstance(x[3], int) or x[3] >= 500]
    beyond = [x for x in bad if not excused(x)]
    if "storage" in kills:  # cuts of the loaded volume went on while the store was down
        # Counted by when they were asked for: how many also end before the store is back
        # depends on the machine's speed (a 24x24 cut took 0.5-2.7 s on a slow day, and the
        # outage lasts about 4 s). A few may answer 502 (excused above), most must not.
        t_kill, t_back = kills["storage"]
        asked = [x for x in records if x[2] == "new" and t_kill + 0.5 < x[0] < t_back]
        served = [x for x in asked if x[3] == 200]
        assert len(served) >= 3 and 2 * len(served) >= len(asked), \
            (f"{len(served)} of {len(asked)} new cuts asked for during the store's outage served", asked[:10])
    assert not beyond, ("failures beyond the outages", {k: v for k, v in kills.items()}, beyond[:10])
    later = [x for x in records if x[0] > after_all + 0.5]
    assert len(later) >= 10 and all(isinstance(x[3], int) and x[3] < 500 for x in later)
    print(f"{len(records)} requests; outages (s): "
          + ", ".join(f"{k} {b - a:.2f}" for k, (a, b) in kills.items())
          + f"; {sum(1 for x in bad if x[3] == 502)} answered 502, {sum(1 for x in bad if isinstance(x[3], str))} "
          f"refused or cut; acknowledged: {len(load.acked['volumes'])} volumes, {len(load.acked['meshes'])} meshes"
          + (f"; {len(served)} new cuts asked for and served while the store was down" if "storage" in kills else ""))
    assert load.acked["volumes"] and load.acked["meshes"]
    for url in [cluster.url] + cluster.replica_urls:
        for vid in load.acked["volumes"]:
            assert requests.get(f"{url}/v1/volumes/{vid}", timeout=T).status_code == 200, (url, vid)
        for mid in load.acked["meshes"]:
            assert requests.get(f"{url}/v1/meshes/{mid}", timeout=T).status_code == 200, (url, mid)
    after = requests.get(cached, timeout=T)
    assert after.status_code == 200 and after.content == before.content


def test_an_analysis_ending_while_the_store_is_down_lands_once_it_is_back(cluster, tmp_path):
    """An acknowledged upload whose table is written while the S3 server is down: the replica
    keeps trying, and the job succeeds once the supervisor has restarted the store."""
    if cluster.state["storage"]["kind"] != "s3":
        pytest.skip("the store is a directory here: there is no storage process to kill")
    r = upload(cluster.url, exemplar_png(tmp_path, "spots", 64), name="outage")
    owner = cluster.replica_urls[cluster.replica_of(r.headers["X-Upstream"])]
    ex_id, job_id = r.json()["exemplar"]["id"], r.json()["job"]["id"]
    wait_started(owner, job_id)
    old = cluster.kill_store()
    # The analysis ends during the outage (4 s): its table cannot be written then.
    time.sleep(1.5)
    # The replica running the job answers its state from memory meanwhile: still running.
    during = requests.get(f"{owner}/v1/jobs/{job_id}", timeout=T)
    assert during.status_code == 200 and during.json()["state"] == "running", during.text
    cluster.wait_restarted("storage", old)
    job = wait_job(owner, job_id, 60)
    assert job["state"] == "succeeded", job
    assert f"analysis of exemplar {ex_id}: storage unavailable" in \
        cluster.replica_log(cluster.replica_of(r.headers["X-Upstream"])), "the table was not written during the outage"
    for url in [cluster.url] + cluster.replica_urls:
        assert wait_job(url, job_id, 60)["state"] == "succeeded", url
        assert requests.get(f"{url}/v1/exemplars/{ex_id}", timeout=T).json()["state"] == "ready", url
