#!/usr/bin/env python3
"""Screenshot of the browser app for the README (docs/web-app.png), made the way a user would:
`solidtex serve` on a scratch data directory, an exemplar analysed with the default parameters,
a volume of it, a stored mesh; then, in headless Chromium (Debian's chromium-headless-shell via
Playwright, as the tests), the default 256² cut, one sketch stroke drawn with the mouse (a new
sketch field and the volume made from it) and the mesh textured by that volume and orbited.

    build/venv/bin/python scripts/web-screenshot.py build \\
        --exemplar ../shared/data/exemplars/pebbles.png --mesh ../shared/data/meshes/bunny.off -o docs/web-app.png

Only the app's output is written; the inputs stay where they are. Fails on any console error."""
from __future__ import annotations

import argparse
import io
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import requests

CHROMIUM_ARGS = ["--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
                 "--no-sandbox"]
WAIT_MS = 600_000


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("build", type=Path)
    ap.add_argument("--exemplar", type=Path, required=True)
    ap.add_argument("--mesh", type=Path, required=True)
    ap.add_argument("--resolution", type=int, default=128, help="mesh placement: voxels along its longest side")
    ap.add_argument("-o", "--output", type=Path, required=True)
    args = ap.parse_args()
    from PIL import Image
    from playwright.sync_api import sync_playwright

    port = free_port()
    url = f"http://127.0.0.1:{port}"
    with tempfile.TemporaryDirectory() as data:
        # New cuts of a sketched field at 256² take tens of seconds on 2 cores: a generous deadline.
        server = subprocess.Popen([str(args.build / "bin" / "solidtex"), "serve", "--port", str(port), "--data", data,
                                   "--deadline", "300"])
        try:
            for _ in range(100):
                try:
                    if requests.get(url + "/healthz", timeout=1).ok:
                        break
                except requests.RequestException:
                    time.sleep(0.1)
            up = requests.post(url + "/v1/exemplars", params={"name": args.exemplar.stem}, data=args.exemplar.read_bytes(),
                               headers={"Content-Type": "application/octet-stream"}, timeout=60).json()
            while (job := requests.get(f"{url}/v1/jobs/{up['job']['id']}", timeout=10).json())["state"] not in ("succeeded", "failed"):
                time.sleep(0.5)
            if job["state"] != "succeeded":
                raise SystemExit(f"analysis failed: {job}")
            volume = requests.post(url + "/v1/volumes", timeout=60,
                                   json={"name": args.exemplar.stem, "exemplar": up["exemplar"]["id"], "seed": 1}).json()
            mesh = requests.post(url + "/v1/meshes", params={"name": args.mesh.stem}, data=args.mesh.read_bytes(),
                                 headers={"Content-Type": "application/octet-stream"}, timeout=60).json()
            errors = []
            with sync_playwright() as p:
                browser = p.chromium.launch(executable_path=shutil.which("chromium-headless-shell"), args=CHROMIUM_ARGS)
                page = browser.new_page(viewport={"width": 1240, "height": 860})
                page.on("console", lambda m: m.type == "error" and errors.append(m.text))
                page.on("pageerror", lambda e: errors.append(str(e)))
                page.goto(f"{url}/#volume={volume['id']}")
                done = "v => document.getElementById('cut-panel').dataset.state === 'done' && " \
                       "document.getElementById('cut-canvas').dataset.volume !== v"
                page.wait_for_function(done, arg="", timeout=WAIT_MS)
                page.check("#sketch-mode")
                box = page.locator("#cut-stage").bounding_box()
                stroke = [(0.15, 0.8), (0.3, 0.55), (0.5, 0.5), (0.7, 0.35), (0.85, 0.15)]
                page.mouse.move(box["x"] + stroke[0][0] * box["width"], box["y"] + stroke[0][1] * box["height"])
                page.mouse.down()
                for fx, fy in stroke[1:]:
                    page.mouse.move(box["x"] + fx * box["width"], box["y"] + fy * box["height"], steps=8)
                page.mouse.up()
                page.wait_for_function(done, arg=volume["id"], timeout=WAIT_MS)
                page.select_option("#mesh-select", mesh["id"])
                page.fill("#mesh-resolution", str(args.resolution))
                page.click("#mesh-show")
                page.wait_for_function("() => document.getElementById('mesh-panel').dataset.state === 'done'", timeout=WAIT_MS)
                mesh_box = page.locator("#mesh-canvas").bounding_box()
                page.mouse.move(mesh_box["x"] + 200, mesh_box["y"] + 200)
                page.mouse.down()
                page.mouse.move(mesh_box["x"] + 140, mesh_box["y"] + 215, steps=5)
                page.mouse.up()
                page.mouse.move(0, 0)
                time.sleep(0.5)
                shot = page.screenshot()
                browser.close()
            if errors:
                raise SystemExit(f"console errors: {errors}")
            # A palette keeps the PNG small; the cut and mesh have far fewer colours than that.
            image = Image.open(io.BytesIO(shot)).convert("RGB").quantize(256, method=Image.Quantize.MEDIANCUT)
            args.output.parent.mkdir(parents=True, exist_ok=True)
            image.save(args.output, optimize=True)
            print(f"wrote {args.output} ({args.output.stat().st_size} bytes)")
        finally:
            server.terminate()
            server.wait(30)
    return 0


if __name__ == "__main__":
    sys.exit(main())
