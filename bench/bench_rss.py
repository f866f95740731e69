#!/usr/bin/env python3
"""Peak memory of `solidtex serve` under the robustness probes (issue 11): prints one JSON object.

  bench_rss.py [BUILD] [--cache-mb 256] [--volume-state-mb 512] [--threads 2] [--quick]

Starts the server with the given flags (the other limits at their defaults) on a fresh data
directory, analyses a 96x96 procedural wood exemplar with the default parameters (--grain x, as
the demo does), then runs every probe of tests/python/test_robustness.py that is refused or
bounded, plus the legitimate heavy requests the limits admit, one after another. Before each
probe the kernel's peak-RSS mark is reset (/proc/PID/clear_refs, 5), so VmHWM afterwards is the
probe's own peak; a sampler reads VmRSS every 10 ms as well (the fallback where clear_refs is not
permitted). Reports per probe: HTTP statuses, seconds, peak and final RSS (MB), and the peak
above --cache-mb; overall: the server's VmHWM against --cache-mb + FIXED_BUDGET_MB, the bound
README's limits section documents (measured with this script).

The probes reuse the request builders of tests/python (test_robustness.py, support.py).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from types import SimpleNamespace

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "python"))

import numpy as np  # noqa: E402
import requests  # noqa: E402
from PIL import Image  # noqa: E402

import support  # noqa: E402
from support import HTTP_TIMEOUT, RAW_F32, ServerFactory, post_bytes, raw_post  # noqa: E402
import test_robustness as probes  # noqa: E402  (create_volume, slice_of, big_sketch, slow_exemplar)

# The documented fixed budget above --cache-mb (README, "Memory"): what the process holds beside
# the voxel cache under every probe below with the default limits: code and libraries, allocator
# arenas, the loaded volumes' state (bounded by --volume-state-mb, here tables and one surface
# band, 131 MB), the working memory of the running requests (what the cost model admits: a new
# 256^2 cut adds ~620 MB) and request bodies (--max-upload-mb). Measured at most 953 MB with
# --cache-mb 32 and 740 MB with 256 (2 cores, December 2026).
FIXED_BUDGET_MB = 1024
MB = 1 << 20


def read_status(pid: int) -> dict:
    out = {}
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(("VmRSS:", "VmHWM:")):
                key, value = line.split(":", 1)
                out[key] = int(value.split()[0]) * 1024
    return out


class Sampler:
    """Samples VmRSS of `pid` every 10 ms; `peak()` since the last `reset()`."""

    def __init__(self, pid: int) -> None:
        self.pid = pid
        self.max_rss = 0
        self.lock = threading.Lock()
        self.stop = threading.Event()
        self.can_clear = True
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self.stop.is_set():
            try:
                rss = read_status(self.pid)["VmRSS"]
            except (OSError, KeyError):
                return
            with self.lock:
                self.max_rss = max(self.max_rss, rss)
            time.sleep(0.01)

    def reset(self) -> None:
        try:
            with open(f"/proc/{self.pid}/clear_refs", "w") as f:
                f.write("5")
        except OSError:
            self.can_clear = False
        with self.lock:
            self.max_rss = read_status(self.pid)["VmRSS"]

    def peak(self) -> int:
        status = read_status(self.pid)
        with self.lock:
            sampled = max(self.max_rss, status["VmRSS"])
        return max(sampled, status["VmHWM"]) if self.can_clear else sampled

    def close(self) -> None:
        self.stop.set()
        self.thread.join(2)


def mb(b: float) -> float:
    return round(b / MB, 1)


def statuses(*responses) -> list:
    return [r.status_code if hasattr(r, "status_code") else r for r in responses]


# ---- the probes: each takes the server namespace and returns a list of HTTP statuses --------

def p_line_cut(s):
    # The test gives it 5 s; a loaded machine may need longer for the cost model's first estimate.
    return statuses(probes.slice_of(s, s.new_volume(), size="4194304,1", timeout=30))


def p_points_far_apart(s):
    vid = s.new_volume()
    return statuses(requests.post(f"{s.url}/v1/volumes/{vid}/points", json={"points": [[0, 0, 0], [4000, 0, 0]]},
                                  headers=RAW_F32, timeout=HTTP_TIMEOUT))


def p_points_scattered(s):
    """Points thousands of voxels apart, synthesized piece by piece, each piece's bricks cached
    (a small exemplar's volume: a piece of the default one takes seconds)."""
    vid = requests.post(f"{s.url}/v1/volumes", json={"exemplar": s.small_exemplars[0], "seed": 9},
                        timeout=HTTP_TIMEOUT).json()["id"]
    n = 8 if s.quick else 64
    pts = [[4096.0 * (i % 8) - 16000, 4096.0 * (i // 8) - 9000, 5000.0 * (i % 3)] for i in range(n)]
    return statuses(requests.post(f"{s.url}/v1/volumes/{vid}/points", json={"points": pts}, headers=RAW_F32,
                                  params={"timeout": 300}, timeout=HTTP_TIMEOUT * 3))


def p_cut_huge_u(s):
    return statuses(requests.post(f"{s.url}/v1/volumes/{s.new_volume()}/cut", headers=RAW_F32, timeout=HTTP_TIMEOUT,
                                  json={"origin": [0, 0, 0], "u": [1e8, 0, 0], "v": [0, 1, 0], "size": [2, 1]}))


def p_cut_scattered_until_deadline(s):
    """A 64x64 cut with steps of 1000 voxels: 4096 pieces, cancelled at its 10 s deadline."""
    return statuses(requests.post(f"{s.url}/v1/volumes/{s.new_volume()}/cut", headers=RAW_F32, timeout=HTTP_TIMEOUT,
                                  params={"timeout": 10},
                                  json={"origin": [0, 0, 0], "u": [1000, 0, 0], "v": [0, 1000, 0], "size": [64, 64]}))


def p_surface_huge_scale(s):
    vid = s.new_volume()
    return statuses(requests.post(f"{s.url}/v1/volumes/{vid}/surface", timeout=HTTP_TIMEOUT, params={"timeout": 120},
                                  json={"mesh": s.cube, "format": "json",
                                        "placement": {"scale": 1e6, "translate": [-5e5, 3e5, 0]}}))


def regions(s, resolution: int, label: str):
    return requests.post(f"{s.url}/v1/volumes", timeout=HTTP_TIMEOUT, json={"regions": {
        "exemplars": [s.exemplar_id, s.exemplar_id], "label": label,
        "mesh": {"id": s.cube, "placement": {"resolution": resolution}}}})


def p_surface_band_refused(s):
    return statuses(regions(s, 2048, "surface:64"))


def p_surface_band_built(s):
    """The largest band of this probe set that the limits admit, then a query through it."""
    r = regions(s, 256 if s.quick else 512, "surface:8")
    out = [r.status_code]
    if r.status_code == 201:
        vid = r.json()["id"]
        out.append(requests.post(f"{s.url}/v1/volumes/{vid}/points", headers=RAW_F32, timeout=HTTP_TIMEOUT,
                                 json={"points": [[40, 40, 40], [100, 100, 100], [170, 40, 300]]}).status_code)
    return out


def p_blank_png_4096(s):
    path = s.tmp / "blank.png"
    Image.new("RGB", (4096, 4096)).save(path)
    return statuses(post_bytes(f"{s.url}/v1/exemplars", path.read_bytes()))


def p_multipart_six_blank_4096(s):
    """All six planes and masks as 4096^2 blank PNGs (about 16 KB each on the wire)."""
    path = s.tmp / "blank.png"
    if not path.exists():
        Image.new("RGB", (4096, 4096)).save(path)
    data = path.read_bytes()
    return statuses(multipart(s, [(n, (n + ".png", data)) for n in ("xy", "yz", "zx", "mask", "mask_yz", "mask_zx")]))


def multipart(s, parts):
    return requests.post(f"{s.url}/v1/exemplars", files=parts, timeout=HTTP_TIMEOUT)


def p_multipart_many_parts(s):
    return statuses(multipart(s, [(f"p{i}", (f"p{i}.bin", b"x" * 64)) for i in range(2000)]))


def p_multipart_16_big_parts(s):
    """Sixteen parts filling --max-upload-mb (64 MiB) with bytes that are no image."""
    rng = np.random.default_rng(3)
    names = ["xy", "yz", "zx", "mask", "mask_yz", "mask_zx"] + [f"extra{i}" for i in range(10)]
    parts = [(n, (n + ".bin", rng.bytes(int(3.9 * MB)))) for n in names]
    return statuses(multipart(s, parts))


def p_upload_over_limit(s):
    return [raw_post(s.url, "/v1/exemplars", b"\0" * (65 * MB))]


def p_field_solve_deadline(s):
    return statuses(requests.post(f"{s.url}/v1/fields", params={"timeout": 1}, json=probes.big_sketch(),
                                  timeout=HTTP_TIMEOUT))


def p_field_grid_overflow(s):
    sketch = {"domain": {"min": [0, 0, 0], "max": [1.1e9, 1, 1]},
              "curves": [{"axis": "x", "plane_normal": [0, 0, 1], "points": [[0, 0, 0], [10, 0.5, 0.5]]}]}
    return statuses(requests.post(f"{s.url}/v1/fields", json=sketch, timeout=HTTP_TIMEOUT))


def p_synthesis_deadline(s):
    return statuses(probes.slice_of(s, s.new_volume(seed=11), size="160,160", timeout=1))


def p_stretched_field(s):
    r = probes.create_volume(s, field={"spec": "axis:0,0,1,30;scale:3,1,1"})
    return statuses(r, probes.slice_of(s, r.json()["id"], size="16,16"))


def p_region_max_voxels(s):
    """A box of --max-voxels voxels (256x256x64): refused by the cost model, or cancelled at 10 s."""
    r = requests.get(f"{s.url}/v1/volumes/{s.new_volume()}/region", headers=RAW_F32, timeout=HTTP_TIMEOUT,
                     params={"min": "0,0,0", "size": "256,256,64", "timeout": 10})
    return statuses(r)


def p_slice_256(s):
    """The README's example of a big admitted request: a new 256^2 cut (or 128^2 with --quick)."""
    size = "128,128" if s.quick else "256,256"
    vid = s.new_volume()
    return statuses(requests.get(f"{s.url}/v1/volumes/{vid}/slice", headers=RAW_F32, timeout=900,
                                 params={"axis": "z", "at": 0, "size": size, "timeout": 300}))


def p_two_big_slices_at_once(s):
    """One new 160^2 cut per worker at the same time (cancelled at 20 s if not done)."""
    vids = [s.new_volume(seed=20 + i) for i in range(s.threads)]
    out = []

    def run(vid):
        out.append(probes.slice_of(s, vid, size="160,160", timeout=20).status_code)

    threads = [threading.Thread(target=run, args=(v,)) for v in vids]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return out


def p_many_volumes(s):
    """Many volumes over several exemplars, each queried once: loaded state stays under its
    budget (LRU eviction), the cache budget is split over the loaded ones."""
    out = []
    exemplars = s.small_exemplars
    for i in range(8 if s.quick else 32):
        ex = exemplars[i % len(exemplars)]
        vid = requests.post(f"{s.url}/v1/volumes", json={"exemplar": ex, "seed": 100 + i}, timeout=HTTP_TIMEOUT)
        out.append(vid.status_code)
        out.append(probes.slice_of(s, vid.json()["id"], size="24,24").status_code)
    return out


PROBES = [
    ("line_shaped_slice", p_line_cut),
    ("points_far_apart", p_points_far_apart),
    ("points_scattered", p_points_scattered),
    ("cut_huge_u", p_cut_huge_u),
    ("cut_scattered_until_deadline", p_cut_scattered_until_deadline),
    ("surface_huge_placement_scale", p_surface_huge_scale),
    ("surface_band_refused_at_creation", p_surface_band_refused),
    ("surface_band_built", p_surface_band_built),
    ("blank_png_4096", p_blank_png_4096),
    ("multipart_six_blank_4096", p_multipart_six_blank_4096),
    ("multipart_many_parts", p_multipart_many_parts),
    ("multipart_16_big_parts", p_multipart_16_big_parts),
    ("upload_over_limit", p_upload_over_limit),
    ("field_solve_deadline", p_field_solve_deadline),
    ("field_grid_overflow", p_field_grid_overflow),
    ("synthesis_deadline", p_synthesis_deadline),
    ("stretched_field", p_stretched_field),
    ("region_max_voxels", p_region_max_voxels),
    ("slice_256", p_slice_256),
    ("big_slices_on_every_worker", p_two_big_slices_at_once),
    ("many_volumes", p_many_volumes),
]


def metric(text: str, name: str) -> float:
    lines = support.metric_lines(text, name)
    return float(lines[0].split()[-1]) if lines else float("nan")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("build", nargs="?", default="build")
    ap.add_argument("--cache-mb", type=int, default=256)
    ap.add_argument("--volume-state-mb", type=int, default=None, help="default: the server's (512)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="smaller probes (a few minutes less)")
    ap.add_argument("--only", default="", help="comma-separated probe names")
    args = ap.parse_args()
    build = Path(args.build).resolve()
    os.environ["SOLIDTEX_BIN"] = str(build / "bin" / "solidtex")
    flags = ["--threads", args.threads, "--cache-mb", args.cache_mb]
    if args.volume_state_mb is not None:
        flags += ["--volume-state-mb", args.volume_state_mb]
    out = {"cache_mb": args.cache_mb, "volume_state_mb": args.volume_state_mb or 512, "threads": args.threads,
           "max_request_mb": 1536, "fixed_budget_mb": FIXED_BUDGET_MB, "quick": args.quick}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        factory = ServerFactory(tmp / "servers")
        try:
            srv = factory.start(*flags)
            sampler = Sampler(srv.proc.pid)
            out["start_rss_mb"] = mb(read_status(srv.proc.pid)["VmRSS"])
            s = SimpleNamespace(url=srv.url, client=srv.client, tmp=tmp, quick=args.quick, threads=args.threads)
            # Setup: the demo's exemplar (default analysis parameters) and a few small ones.
            subprocess.run([str(build / "bin" / "solidtex"), "exemplar", "wood", "--size", "96,96", "-o",
                            str(tmp / "wood.png")], check=True, capture_output=True)
            t0 = time.monotonic()
            up = srv.client.upload_exemplar(tmp / "wood.png", grain="x")
            srv.client.wait_for_job(up["job"]["id"], timeout=600, poll=0.1)
            s.exemplar_id = up["exemplar"]["id"]
            out["setup_analysis_seconds"] = round(time.monotonic() - t0, 1)
            s.small_exemplars = []
            for kind in ("stripes", "bricks", "noise", "spots"):
                path = tmp / f"{kind}.png"
                subprocess.run([str(build / "bin" / "solidtex"), "exemplar", kind, "--size", "64,64", "-o", str(path)],
                               check=True, capture_output=True)
                s.small_exemplars.append(support.upload_ready(srv.client, path)["id"])
            s.cube = post_bytes(f"{srv.url}/v1/meshes", support.CUBE_OFF, params={"name": "cube"}).json()["id"]
            seeds = iter(range(1000, 100000))
            s.new_volume = lambda seed=None: probes.create_volume(s, seed=seed if seed is not None else next(seeds)).json()["id"]
            out["after_setup_rss_mb"] = mb(read_status(srv.proc.pid)["VmRSS"])
            results = []
            only = {n for n in args.only.split(",") if n}
            for name, probe in PROBES:
                if only and name not in only:
                    continue
                sampler.reset()
                t0 = time.monotonic()
                try:
                    codes = probe(s)
                    error = None
                except Exception as e:  # a probe that breaks is reported, the rest still run
                    codes, error = [], f"{type(e).__name__}: {e}"
                peak = sampler.peak()
                entry = {"name": name, "statuses": codes, "seconds": round(time.monotonic() - t0, 2),
                         "peak_rss_mb": mb(peak), "rss_after_mb": mb(read_status(srv.proc.pid)["VmRSS"]),
                         "peak_above_cache_mb": mb(peak - args.cache_mb * MB), "alive": srv.running}
                if error:
                    entry["error"] = error
                if not srv.running:
                    entry["log"] = srv.log()
                results.append(entry)
                print(json.dumps(entry), file=sys.stderr, flush=True)
                if not srv.running:
                    break
            out["probes"] = results
            text = srv.client.metrics() if srv.running else ""
            status = read_status(srv.proc.pid) if srv.running else {"VmHWM": 0, "VmRSS": 0}
            peak = max([status["VmHWM"]] + [int(p["peak_rss_mb"] * MB) for p in results])
            out["peak_rss_mb"] = mb(peak)
            out["peak_above_cache_mb"] = mb(peak - args.cache_mb * MB)
            out["bound_mb"] = args.cache_mb + FIXED_BUDGET_MB
            out["within_bound"] = peak <= (args.cache_mb + FIXED_BUDGET_MB) * MB
            out["end"] = {"rss_mb": mb(status["VmRSS"]),
                          "cache_mb": mb(metric(text, "solidtex_cache_bytes")),
                          "volume_state_mb": mb(metric(text, "solidtex_volume_state_bytes")),
                          "volumes_loaded": metric(text, "solidtex_volumes_loaded")}
            out["peak_reset_per_probe"] = sampler.can_clear
            sampler.close()
        finally:
            factory.close()
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
