"""Load benchmark of the local reference deployment (issue #16; deploy/README.md): 1, 2 and 3
`solidtex serve` replicas behind nginx (scripts/cluster.sh), all on this machine. JSON on stdout.

  build/venv/bin/python bench/bench_cluster.py [--build build] [--seconds 10] [--rate 200]
         [--replicas 1,2,3] [--walk-steps 150] [--storage dir|s3]

1. Cached answers through nginx, for N = 1, 2, 3 replicas (consistent hashing):
   - `nginx_cache`: the same set of 64² slices and 32³ zarr chunks, once asked, answered from
     nginx's cache (X-Cache-Status HIT);
   - `replica_cache`: nginx's cache off, so the replicas answer them from their voxel and chunk
     caches (every answer was synthesized once before the measurement).
   Each: closed loop (C threads back to back: answers per second) and open loop (a request
   every 1/RATE s whatever the answers; latency counted from when it was due, so queueing
   shows): p50/p99/max ms.
2. A random walk of neighbouring cuts (--cut-size, 64² slices by default; 256² is what the
   browser app asks for: `at` +-1, panning +-16 voxels, one in
   five steps back to a cut seen before) through 3 replicas, with consistent hashing and with
   round-robin, on cold replicas: nginx's hit rate (X-Cache-Status) and the replicas' voxel-
   cache hit rate (voxel lookups found / made, summed from each replica's
   /v1/volumes/{id}/stats).
The machine's load average is recorded before and after each measurement.
"""
from __future__ import annotations

import argparse
import http.client
import json
import os
import platform
import random
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, Dict, List, Tuple
from urllib.parse import urlsplit

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "cluster"))
sys.path.insert(0, str(REPO / "bench"))
from harness import Cluster  # noqa: E402
from http_bench import percentile, run_threads  # noqa: E402

import requests  # noqa: E402

ANALYSIS = {"levels": 3, "neighborhood": 5, "candidates": 4, "pca_dims": 8}


def load() -> List[float]:
    return [round(x, 2) for x in os.getloadavg()]


def pct(values: List[float], p: float) -> float:
    """The p-th percentile of `values` (seconds) in milliseconds; NaN when there are none."""
    return round(percentile(values, p) * 1000, 2) if values else float("nan")


class Conn(threading.local):
    """One keep-alive HTTP/1.1 connection per thread."""

    def __init__(self, url: str) -> None:
        parts = urlsplit(url)
        self.host, self.port = parts.hostname, parts.port
        self.c = http.client.HTTPConnection(self.host, self.port, timeout=60)

    def get(self, path: str) -> Tuple[int, str]:
        try:
            self.c.request("GET", path)
            r = self.c.getresponse()
            r.read()
            return r.status, r.getheader("X-Cache-Status") or ""
        except (OSError, http.client.HTTPException):
            self.c.close()
            self.c = http.client.HTTPConnection(self.host, self.port, timeout=60)
            return 599, ""


def closed_loop(url: str, paths: List[str], threads: int, seconds: float) -> Dict[str, Any]:
    conn = Conn(url)
    lat: List[float] = []
    errors = [0]
    lock = threading.Lock()
    stop = time.monotonic() + seconds

    def worker(k: int) -> None:
        rng = random.Random(k)
        mine, bad = [], 0
        while time.monotonic() < stop:
            t0 = time.monotonic()
            status, _ = conn.get(rng.choice(paths))
            mine.append(time.monotonic() - t0)
            bad += status != 200
        with lock:
            lat.extend(mine)
            errors[0] += bad

    wall = run_threads(threads, worker)
    return {"threads": threads, "requests": len(lat), "per_second": round(len(lat) / wall, 1),
            "p50_ms": pct(lat, 50), "p99_ms": pct(lat, 99), "errors": errors[0]}


def open_loop(url: str, paths: List[str], rate: float, seconds: float) -> Dict[str, Any]:
    """A request every 1/rate s; latency from when it was due to its answer's end."""
    conn = Conn(url)
    n = int(rate * seconds)
    rng = random.Random(1)
    chosen = [rng.choice(paths) for _ in range(n)]
    lat: List[float] = [0.0] * n   # from when the request was due
    service: List[float] = [0.0] * n  # from when it was sent
    lag: List[float] = [0.0] * n   # how late this process sent it (its own CPU starvation)
    status: List[int] = [0] * n
    hits = [0]

    def one(i: int, due: float) -> None:
        sent = time.monotonic()
        s, cache = conn.get(chosen[i])
        end = time.monotonic()
        lat[i], service[i], lag[i] = end - due, end - sent, sent - due
        status[i] = s
        if cache == "HIT":
            hits[0] += 1

    t0 = time.monotonic() + 0.05
    with ThreadPoolExecutor(max_workers=32) as pool:
        for i in range(n):
            due = t0 + i / rate
            delay = due - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            pool.submit(one, i, due)
    wall = time.monotonic() - t0
    return {"rate": rate, "requests": n, "achieved_per_second": round(n / wall, 1),
            "p50_ms": pct(lat, 50), "p99_ms": pct(lat, 99), "max_ms": pct(lat, 100),
            "service_p50_ms": pct(service, 50), "service_p99_ms": pct(service, 99),
            "sender_lag_p99_ms": pct(lag, 99),
            "errors": sum(s != 200 for s in status), "error_statuses": sorted(set(s for s in status if s != 200)),
            "nginx_hits": hits[0]}


def cached_set(volume: str) -> List[str]:
    v = f"/v1/volumes/{volume}"
    slices = [f"{v}/slice?axis=z&at={k}&origin={64 * (k % 4)},{64 * (k // 4 % 4)}&size=64,64" for k in range(16)]
    chunks = [f"{v}/zarr/1/c/0/{k // 8}/{k // 4 % 2}/{k % 4}" for k in range(16)]
    return slices + chunks


def measure_cached(args, data_dir: Path, volume: str, replicas: int, nginx_cache: str) -> Dict[str, Any]:
    with Cluster(data_dir, replicas=replicas, storage=args.storage,
                 serve_flags="", nginx_cache=nginx_cache) as c:
        paths = cached_set(volume)
        for p in paths:  # synthesized once (and cached by nginx when its cache is on)
            r = requests.get(c.url + p, timeout=300)
            assert r.status_code == 200, (p, r.status_code, r.text[:200])
        for p in paths:
            requests.get(c.url + p, timeout=300)
        out: Dict[str, Any] = {"replicas": replicas, "nginx_cache": nginx_cache, "load_before": load()}
        out["closed_loop"] = closed_loop(c.url, paths, args.threads, args.seconds)
        out["open_loop"] = open_loop(c.url, paths, args.rate, args.seconds)
        out["load_after"] = load()
        return out


def walk(args, data_dir: Path, volume: str, balance: str, replicas: int = 3) -> Dict[str, Any]:
    """The random walk of neighbouring z cuts (args.cut_size square) on cold replicas; hit rates per move kind."""
    rng = random.Random(args.seed)
    with Cluster(data_dir, replicas=replicas, balance=balance, storage=args.storage) as c:
        def counters() -> Tuple[int, int]:
            caches = [requests.get(f"{u}/v1/volumes/{volume}/stats", timeout=60).json()["cache"] for u in c.replica_urls]
            return sum(x["hits"] for x in caches), sum(x["misses"] for x in caches)

        load_before = load()
        # The cut's corner; it starts centred in a 100^3 affinity block (deploy/nginx).
        at, ou, ov = 50, 18, 18
        seen: List[Tuple[int, int, int]] = []
        kinds: Dict[str, Dict[str, int]] = {}
        nginx_hits = 0
        upstreams: Dict[str, int] = {}
        lat = []
        hits0, misses0 = counters()
        last = (hits0, misses0)
        t0 = time.monotonic()
        for _ in range(args.walk_steps):
            move = rng.random()
            if seen and move < args.revisit:
                kind, cut = "revisit", rng.choice(seen)
            else:
                if move < args.revisit + (1 - args.revisit) * 0.6:
                    kind = "pan"
                    if rng.random() < 0.5:
                        ou += rng.choice([-16, 16])
                    else:
                        ov += rng.choice([-16, 16])
                else:
                    kind = "depth"
                    at += rng.choice([-1, 1])
                cut = (at, ou, ov)
                seen.append(cut)
            t = time.monotonic()
            n = args.cut_size
            r = requests.get(f"{c.url}/v1/volumes/{volume}/slice?axis=z&at={cut[0]}&origin={cut[1]},{cut[2]}&size={n},{n}",
                             timeout=300)
            lat.append(time.monotonic() - t)
            assert r.status_code == 200, r.text[:200]
            nginx_hits += r.headers.get("X-Cache-Status") == "HIT"
            if "X-Upstream" in r.headers:
                upstreams[r.headers["X-Upstream"]] = upstreams.get(r.headers["X-Upstream"], 0) + 1
            now = counters()
            k = kinds.setdefault(kind, {"steps": 0, "hits": 0, "lookups": 0})
            k["steps"] += 1
            k["hits"] += now[0] - last[0]
            k["lookups"] += now[0] - last[0] + now[1] - last[1]
            last = now
        wall = time.monotonic() - t0
        hits, lookups = last[0] - hits0, last[0] - hits0 + last[1] - misses0
        return {"balance": balance, "replicas": replicas, "cut_size": args.cut_size, "steps": args.walk_steps,
                "distinct_cuts": len(set(seen)),
                "nginx_hit_rate": round(nginx_hits / args.walk_steps, 3),
                "replica_voxel_cache_hit_rate": round(hits / max(1, lookups), 3),
                "replica_voxel_lookups": lookups,
                "by_move": {k: {"steps": v["steps"], "voxel_cache_hit_rate": round(v["hits"] / max(1, v["lookups"]), 3),
                                "lookups": v["lookups"]} for k, v in sorted(kinds.items())},
                "requests_per_replica": sorted(upstreams.values(), reverse=True),
                "seconds": round(wall, 1), "p50_ms": pct(lat, 50), "p99_ms": pct(lat, 99),
                "load_before": load_before, "load_after": load()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=str(REPO / "build"))
    ap.add_argument("--dir", default=None, help="cluster directory (default BUILD/bench-cluster)")
    ap.add_argument("--seconds", type=float, default=10)
    ap.add_argument("--rate", type=float, default=200)
    ap.add_argument("--threads", type=int, default=4)
    ap.add_argument("--replicas", default="1,2,3")
    ap.add_argument("--walk-steps", type=int, default=150)
    ap.add_argument("--cut-size", type=int, default=64, help="side of the walk's square z cuts, voxels")
    ap.add_argument("--walks", default="hash:3,round-robin:3,hash:1",
                    help="BALANCE:REPLICAS of each random walk (empty: none)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--revisit", type=float, default=0.2, help="share of walk steps back to a cut seen before")
    ap.add_argument("--storage", default=None, help="dir or s3 (default: scripts/cluster.sh's)")
    args = ap.parse_args()
    build = Path(args.build).resolve()
    os.environ.setdefault("SOLIDTEX_BIN", str(build / "bin" / "solidtex"))
    data_dir = Path(args.dir or build / "bench-cluster").resolve()
    started = time.time()

    # One exemplar and one volume for everything (the store outlives each cluster).
    png = data_dir / "noise96.png"
    data_dir.mkdir(parents=True, exist_ok=True)
    subprocess.run([os.environ["SOLIDTEX_BIN"], "exemplar", "noise", "--size", "96,96", "-o", str(png)],
                   check=True, capture_output=True)
    with Cluster(data_dir, replicas=1, storage=args.storage) as c:
        storage = c.state["storage"]["kind"]
        up = requests.post(f"{c.url}/v1/exemplars", data=png.read_bytes(), params=ANALYSIS,
                           headers={"Content-Type": "image/png"}, timeout=60).json()
        job = up["job"]["id"]
        while (state := requests.get(f"{c.url}/v1/jobs/{job}", timeout=60).json()["state"]) not in ("succeeded", "failed"):
            time.sleep(0.2)
        assert state == "succeeded"
        volume = requests.post(f"{c.url}/v1/volumes", json={"exemplar": up["exemplar"]["id"], "seed": 1},
                               timeout=60).json()["id"]

    result: Dict[str, Any] = {
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(),
                    "nginx": subprocess.run(["nginx", "-v"], capture_output=True, text=True).stderr.strip()
                    if subprocess.run(["which", "nginx"], capture_output=True).returncode == 0
                    else subprocess.run(["/usr/sbin/nginx", "-v"], capture_output=True, text=True).stderr.strip(),
                    "load_at_start": load()},
        "storage": storage, "volume": volume, "cached_set": "16 slices 64x64 (PNG) + 16 zarr chunks 32^3 (scale 1)",
        "replica_flags": "--threads 1 --queue 64 --cache-mb 256 (scripts/cluster.sh)",
        "cached": [], "walk": [],
    }
    for n in [int(x) for x in filter(None, args.replicas.split(","))]:
        for nginx_cache in ("on", "off"):
            result["cached"].append(measure_cached(args, data_dir, volume, n, nginx_cache))
            print(json.dumps(result["cached"][-1]), file=sys.stderr)
    for spec in filter(None, args.walks.split(",")):
        balance, replicas = spec.split(":")
        result["walk"].append(walk(args, data_dir, volume, balance, int(replicas)))
        print(json.dumps(result["walk"][-1]), file=sys.stderr)
    result["seconds"] = round(time.time() - started, 1)
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
