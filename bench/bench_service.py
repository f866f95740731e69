#!/usr/bin/env python3
"""Load benchmark of `solidtex serve`: prints one JSON object.

Starts the server on a free port with a fresh data directory, uploads a procedural wood
exemplar (default analysis parameters), makes a volume, then measures:
  analysis_seconds          upload to job succeeded
  cold_slice_seconds        a first 64x64 cut (nothing cached)
  cached_slice_ms           p50/p95 latency of the same cut repeated 50 times
  concurrent                8 client threads x 25 cached cuts: requests/s, p95 ms, status counts
  overload                  16 simultaneous new cuts against --threads 1 --queue 2: status counts
  points_ms                 4096 points on the cached cut plane (raw float32 in and out)
  server_peak_rss_mb        VmHWM of the server process at the end
Usage: bench/bench_service.py [BUILD_DIR]
"""
import json
import os
import struct
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import requests

from http_bench import percentile, run_threads, start_server

build = Path(sys.argv[1] if len(sys.argv) > 1 else "build").resolve()
binary = build / "bin" / "solidtex"
RAW = {"Accept": "application/octet-stream"}


def start(data, *flags):
    return start_server(binary, data, *flags)


def main():
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        subprocess.run([str(binary), "exemplar", "wood", "--size", "96,96", "-o", str(tmp / "wood.png")],
                       check=True, capture_output=True)
        proc, url = start(tmp / "data", "--threads", "2", "--queue", "32")
        try:
            t0 = time.monotonic()
            up = requests.post(url + "/v1/exemplars", params={"grain": "x"}, data=(tmp / "wood.png").read_bytes(),
                               headers={"Content-Type": "image/png"}).json()
            while True:
                job = requests.get(url + "/v1/jobs/" + up["job"]["id"]).json()
                if job["state"] in ("succeeded", "failed"):
                    break
                time.sleep(0.05)
            out["analysis_seconds"] = round(time.monotonic() - t0, 3)
            vol = requests.post(url + "/v1/volumes", json={"exemplar": up["exemplar"]["id"], "seed": 1}).json()["id"]
            slice_url = f"{url}/v1/volumes/{vol}/slice"
            q = {"axis": "z", "at": 0, "size": "64,64", "timeout": 300}
            t0 = time.monotonic()
            r = requests.get(slice_url, params=q, headers=RAW)
            out["cold_slice_seconds"] = round(time.monotonic() - t0, 3)
            out["cold_slice_voxels"] = int(r.headers["X-Voxels-Synthesized"])
            lat = []
            for _ in range(50):
                t0 = time.monotonic()
                requests.get(slice_url, params=q, headers=RAW).raise_for_status()
                lat.append(1000 * (time.monotonic() - t0))
            out["cached_slice_ms"] = {"p50": round(percentile(lat, 50), 2), "p95": round(percentile(lat, 95), 2)}

            lat, statuses, lock = [], {}, threading.Lock()

            def client(_):
                s = requests.Session()
                for _ in range(25):
                    t = time.monotonic()
                    code = s.get(slice_url, params=q, headers=RAW).status_code
                    with lock:
                        lat.append(1000 * (time.monotonic() - t))
                        statuses[code] = statuses.get(code, 0) + 1

            wall = run_threads(8, client)
            out["concurrent"] = {"clients": 8, "requests": len(lat), "requests_per_second": round(len(lat) / wall, 1),
                                 "p95_ms": round(percentile(lat, 95), 2), "statuses": statuses}

            xs = [(float(i), float(j), 0.0) for j in range(64) for i in range(64)]
            body = b"".join(struct.pack("<3f", *p) for p in xs)
            t0 = time.monotonic()
            r = requests.post(f"{url}/v1/volumes/{vol}/points", data=body,
                              headers={"Content-Type": "application/octet-stream"})
            r.raise_for_status()
            out["points_ms"] = {"points": len(xs), "ms": round(1000 * (time.monotonic() - t0), 2),
                                "voxels_synthesized": int(r.headers["X-Voxels-Synthesized"])}
            with open(f"/proc/{proc.pid}/status") as f:
                for line in f:
                    if line.startswith("VmHWM"):
                        out["server_peak_rss_mb"] = round(int(line.split()[1]) / 1024, 1)
        finally:
            proc.terminate()
            proc.wait(30)

        proc, url = start(tmp / "data", "--threads", "1", "--queue", "2")
        try:
            vol = requests.get(url + "/v1/volumes").json()["volumes"][0]["id"]
            statuses, lock = {}, threading.Lock()
            barrier = threading.Barrier(16)

            def new_cut(i):
                barrier.wait()
                code = requests.get(f"{url}/v1/volumes/{vol}/slice", params={"axis": "z", "at": 100 + 7 * i,
                                    "size": "16,16", "timeout": 300}, headers=RAW).status_code
                with lock:
                    statuses[code] = statuses.get(code, 0) + 1

            seconds = run_threads(16, new_cut)
            out["overload"] = {"requests": 16, "threads": 1, "queue": 2, "statuses": statuses,
                               "seconds": round(seconds, 2)}
        finally:
            proc.terminate()
            proc.wait(30)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
