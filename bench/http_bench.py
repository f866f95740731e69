"""Helpers of the HTTP benchmarks (bench_service.py, bench_arrays.py): a server on a free port,
percentiles, client threads."""
import socket
import subprocess
import threading
import time

import requests


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server(binary, data, *flags):
    """`solidtex serve` on a free port with data dir `data`: (process, url) once /healthz answers."""
    port = free_port()
    proc = subprocess.Popen([str(binary), "serve", "--port", str(port), "--data", str(data), *map(str, flags)],
                            stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}"
    for _ in range(300):
        try:
            if requests.get(url + "/healthz", timeout=1).status_code == 200:
                return proc, url
        except requests.RequestException:
            time.sleep(0.1)
    proc.kill()
    raise SystemExit("server did not start")


def percentile(values, p):
    v = sorted(values)
    return v[min(len(v) - 1, int(round(p / 100 * (len(v) - 1))))]


def run_threads(count, target):
    """Runs target(i) for i in range(count) on as many threads; returns the wall seconds."""
    t0 = time.monotonic()
    threads = [threading.Thread(target=target, args=(i,)) for i in range(count)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return time.monotonic() - t0
