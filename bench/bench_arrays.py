#!/usr/bin/env python3
"""Chunked-array benchmark (issue #14): prints one JSON object.

Starts `solidtex serve` on a free port, uploads EXEMPLAR (default: the shared pebbles, else a
procedural one; default analysis), makes a volume, then over HTTP measures for the /zarr view:
  first_chunk            a new finest 32^3 chunk (0,0,0) on a cold volume: seconds, voxels synthesized
  neighbour_chunk        the chunk next to it along x (0,0,1), and along z (1,0,0)
  cached_chunk_ms        8 client threads x 50 requests of cached chunks (keep-alive http.client):
                         p50/p99 ms, requests/s
  datasets               per dataset (synthesis level): the first chunk's seconds and the voxels
                         synthesized per voxel delivered
Usage: bench/bench_arrays.py BUILD [--exemplar PNG]
"""
import argparse
import http.client
import json
import subprocess
import tempfile
import threading
import time
import urllib.parse
from pathlib import Path

import requests

from http_bench import percentile, run_threads, start_server

REPO = Path(__file__).resolve().parents[1]


def timed_get(url):
    t0 = time.monotonic()
    r = requests.get(url, timeout=600)
    r.raise_for_status()
    return time.monotonic() - t0, r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("build", type=Path)
    ap.add_argument("--exemplar", type=Path, default=REPO.parent / "shared" / "data" / "exemplars" / "pebbles.png")
    args = ap.parse_args()
    binary = args.build.resolve() / "bin" / "solidtex"
    out = {"benchmark": "arrays"}
    with tempfile.TemporaryDirectory() as tmp:
        exemplar = args.exemplar
        if not exemplar.exists():
            exemplar = Path(tmp) / "pebbles.png"
            subprocess.run([str(binary), "exemplar", "pebbles", "--size", "128,128", "-o", str(exemplar)], check=True,
                           capture_output=True)
        out["exemplar"] = exemplar.name
        proc, url = start_server(binary, Path(tmp) / "data", "--cache-mb", "1024")
        try:
            up = requests.post(url + "/v1/exemplars", data=exemplar.read_bytes(),
                               headers={"Content-Type": "application/octet-stream"}, timeout=60).json()
            while (job := requests.get(f"{url}/v1/jobs/{up['job']['id']}", timeout=60).json())["state"] not in ("succeeded", "failed"):
                time.sleep(0.2)
            vol = requests.post(url + "/v1/volumes", json={"exemplar": up["exemplar"]["id"], "seed": 1}, timeout=60).json()
            base = f"{url}/v1/volumes/{vol['id']}/zarr"
            group = requests.get(base + "/zarr.json", timeout=60).json()
            scales = len(group["attributes"]["ome"]["multiscales"][0]["datasets"])
            chunk_voxels = 32 ** 3
            for name, key in (("first_chunk", "0/0/0"), ("neighbour_chunk_x", "0/0/1"), ("neighbour_chunk_z", "1/0/0")):
                seconds, r = timed_get(f"{base}/0/c/0/{key}")
                out[name] = {"seconds": round(seconds, 3), "voxels_synthesized": int(r.headers["X-Voxels-Synthesized"])}
            cached = [f"{base}/0/c/0/{k}" for k in ("0/0/0", "0/0/1", "1/0/0")]
            latencies, lock = [], threading.Lock()

            # A keep-alive http.client connection per client thread: requests' own per-call cost
            # (~2.5 ms of Python under the GIL) capped 8 threads at ~380 requests/s and made the
            # load generator, not the server, the measured p99.
            target = urllib.parse.urlsplit(base)

            def client(i):
                conn = http.client.HTTPConnection(target.hostname, target.port, timeout=60)
                for j in range(50):
                    path = urllib.parse.urlsplit(cached[(i + j) % len(cached)]).path
                    t0 = time.monotonic()
                    conn.request("GET", path)
                    r = conn.getresponse()
                    r.read()
                    dt = time.monotonic() - t0
                    with lock:
                        latencies.append((dt, r.status))
                conn.close()

            wall = run_threads(8, client)
            ms = [d * 1000 for d, _ in latencies]
            out["cached_chunk_ms"] = {"clients": 8, "requests": len(ms), "p50": round(percentile(ms, 50), 2),
                                      "p99": round(percentile(ms, 99), 2), "requests_per_second": round(len(ms) / wall, 1),
                                      "statuses": sorted({s for _, s in latencies})}
            datasets = []
            for s in range(scales):
                # a chunk away from the finest chunks above, so each level starts cold there
                seconds, r = timed_get(f"{base}/{s}/c/0/0/3/3" if s else f"{base}/0/c/0/0/6/6")
                synthesized = int(r.headers["X-Voxels-Synthesized"])
                datasets.append({"dataset": s, "seconds": round(seconds, 3), "voxels_synthesized": synthesized,
                                 "synthesized_per_delivered": round(synthesized / chunk_voxels, 2)})
            out["datasets"] = datasets
        finally:
            proc.terminate()
            proc.wait(timeout=30)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
