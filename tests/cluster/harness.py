"""Starts and drives the local reference deployment (scripts/cluster.sh) for the cluster test
and bench/bench_cluster.py: N `solidtex serve` replicas behind nginx, on loopback ports."""
from __future__ import annotations

import json
import os
import random
import signal
import socket
import subprocess
import time
from pathlib import Path
from typing import Any, Dict, List, Optional

import requests

REPO = Path(__file__).resolve().parents[2]
CLUSTER_SH = REPO / "scripts" / "cluster.sh"


def _free(port: int) -> bool:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def free_base_port(replicas: int) -> int:
    """A port P such that P..P+replicas and P+20 (the S3 server's) are free now."""
    for _ in range(200):
        base = random.randrange(20000, 60000, 50)
        if all(_free(p) for p in [*range(base, base + replicas + 1), base + 20]):
            return base
    raise RuntimeError("no free block of ports on 127.0.0.1")


class Cluster:
    """A running `scripts/cluster.sh up`; ``state`` is its cluster.json."""

    def __init__(self, directory: Path, replicas: int = 3, balance: str = "hash",
                 storage: Optional[str] = None, serve_flags: str = "", nginx_cache: str = "on",
                 restart_delay: float = 1, timeout: float = 600) -> None:
        self.dir = Path(directory)
        self.dir.mkdir(parents=True, exist_ok=True)
        self.port = free_base_port(replicas)
        env = dict(os.environ, CLUSTER_DIR=str(self.dir), CLUSTER_PORT=str(self.port),
                   CLUSTER_REPLICAS=str(replicas), CLUSTER_BALANCE=balance,
                   CLUSTER_SERVE_FLAGS=serve_flags, CLUSTER_NGINX_CACHE=nginx_cache,
                   CLUSTER_RESTART_DELAY=str(restart_delay))
        if storage:
            env["CLUSTER_STORAGE"] = storage
        state_path = self.dir / "cluster.json"
        state_path.unlink(missing_ok=True)
        self._out = open(self.dir / "cluster-sh.log", "ab")
        self.proc = subprocess.Popen([str(CLUSTER_SH), "up"], env=env, stdout=self._out,
                                     stderr=subprocess.STDOUT, start_new_session=True)
        self.restarted: Dict[int, subprocess.Popen] = {}
        end = time.monotonic() + timeout  # the first S3 run builds versitygw (minutes)
        while not state_path.exists():
            if self.proc.poll() is not None or time.monotonic() > end:
                log = self.script_log()
                self.stop()
                raise AssertionError(f"scripts/cluster.sh up did not come up:\n{log}")
            time.sleep(0.1)
        self.state: Dict[str, Any] = json.loads(state_path.read_text())
        self.url: str = self.state["url"]
        self.replica_urls: List[str] = [r["url"] for r in self.state["replicas"]]

    # ---- introspection ----
    def script_log(self) -> str:
        if not self._out.closed:
            self._out.flush()
        return (self.dir / "cluster-sh.log").read_text(errors="replace")[-6000:]

    def replica_log(self, i: int) -> str:
        return Path(self.state["replicas"][i]["log"]).read_text(errors="replace")

    def replica_of(self, upstream: str) -> int:
        """Index of the replica whose host:port is ``upstream`` (an X-Upstream value)."""
        for i, url in enumerate(self.replica_urls):
            if url.endswith("//" + upstream):
                return i
        raise KeyError(upstream)

    def store_file(self, *parts: str) -> Path:
        """Where the shared store keeps an object (exemplars/<id>/attempts, ...) on disk."""
        st = self.state["storage"]
        if st["kind"] == "dir":
            return Path(st["data"]).joinpath(*parts)
        return Path(st["dir"], st["bucket"], st["prefix"]).joinpath(*parts)

    def pid(self, i: int) -> int:
        proc = self.restarted.get(i)
        return proc.pid if proc else int(self.state["replicas"][i]["pid"])

    # ---- faults ----
    def kill_replica(self, i: int) -> None:
        """kill -9 of replica i."""
        os.kill(self.pid(i), signal.SIGKILL)
        proc = self.restarted.pop(i, None)
        if proc:
            proc.wait(10)

    def restart_replica(self, i: int, timeout: float = 60) -> None:
        """Starts replica i again with its command line, port and storage."""
        r = self.state["replicas"][i]
        env = dict(os.environ, **self.state.get("env", {}))
        log = open(r["log"], "ab")
        self.restarted[i] = subprocess.Popen(r["argv"], env=env, stdout=log, stderr=subprocess.STDOUT)
        log.close()
        end = time.monotonic() + timeout
        while True:
            try:
                if requests.get(r["url"] + "/healthz", timeout=2).status_code == 200:
                    return
            except requests.RequestException:
                pass
            if self.restarted[i].poll() is not None or time.monotonic() > end:
                raise AssertionError(f"replica {i} did not restart:\n{self.replica_log(i)[-3000:]}")
            time.sleep(0.05)

    def reload_state(self) -> Dict[str, Any]:
        """cluster.json as the script last wrote it (its supervisor rewrites it on restarts)."""
        self.state = json.loads((self.dir / "cluster.json").read_text())
        return self.state

    def kill_nginx(self) -> int:
        """kill -9 of nginx, master and workers (its process group); returns the master's pid.
        The script's supervisor starts it again."""
        pid = int(self.reload_state()["nginx"]["pid"])
        os.killpg(pid, signal.SIGKILL)
        return pid

    def kill_store(self) -> int:
        """kill -9 of the S3 server; returns its pid. The script's supervisor starts it again."""
        pid = int(self.reload_state()["storage"]["pid"])
        os.kill(pid, signal.SIGKILL)
        return pid

    def wait_restarted(self, what: str, old_pid: int, timeout: float = 60) -> float:
        """Waits until the supervisor has replaced ``what`` ("nginx" or "storage") whose pid was
        ``old_pid`` and nginx answers again; returns the time (monotonic) it did."""
        end = time.monotonic() + timeout
        while True:
            try:
                if int(self.reload_state()[what]["pid"]) != old_pid and \
                        requests.get(self.url + "/lb-healthz", timeout=2).status_code == 200:
                    return time.monotonic()
            except (ValueError, KeyError, OSError, requests.RequestException):
                pass  # cluster.json is replaced whole, but may be read mid-rename on some filesystems
            if self.proc.poll() is not None or time.monotonic() > end:
                raise AssertionError(f"{what} was not restarted:\n{self.script_log()}")
            time.sleep(0.05)

    def stop(self) -> None:
        for proc in self.restarted.values():
            if proc.poll() is None:
                proc.terminate()
                try:
                    proc.wait(10)
                except subprocess.TimeoutExpired:
                    proc.kill()
        self.restarted.clear()
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)  # the script stops what it started
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait(10)
        self._out.close()

    def __enter__(self) -> "Cluster":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.stop()


def nginx_access_lines(cluster: Cluster) -> List[str]:
    return Path(cluster.state["nginx"]["access_log"]).read_text(errors="replace").splitlines()
