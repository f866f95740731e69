"""Helpers for the end-to-end tests: starting `solidtex serve`, running the CLI, small checks."""
from __future__ import annotations

import contextlib
import io
import json
import os
import select
import signal
import socket
import struct
import subprocess
import sys
import time
import zlib
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Collection, Dict, Iterable, Iterator, List, Optional, Sequence, Union

import numpy as np
import pytest
import requests

REPO = Path(__file__).resolve().parents[2]
CLIENT_DIR = REPO / "client"
if str(CLIENT_DIR) not in sys.path:
    sys.path.insert(0, str(CLIENT_DIR))

from solidtex_client import Client  # noqa: E402

# Small analyses keep the suite fast on 2 cores; the CLI gets the same values.
ANALYSIS = {"levels": 3, "neighborhood": 5, "candidates": 4, "pca_dims": 8}
ANALYSIS_CLI = ["--levels", "3", "--neighborhood", "5", "--candidates", "4", "--pca-dims", "8"]
HTTP_TIMEOUT = 120
# Accept headers of the raw answers: sRGB uint8, linear float32.
RAW = {"Accept": "application/octet-stream"}
RAW_F32 = {"Accept": "application/octet-stream; dtype=float32"}
# Real meshes shared with the other tools: <repo>/../shared/data/meshes or $SOLIDTEX_MESHES.
MESH_DIR = Path(os.environ.get("SOLIDTEX_MESHES", str(REPO.parent / "shared" / "data" / "meshes")))


def solidtex_bin() -> Path:
    return Path(os.environ.get("SOLIDTEX_BIN", str(REPO / "build" / "bin" / "solidtex")))


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_cli(*args: Any, timeout: float = 300) -> subprocess.CompletedProcess:
    """Run the solidtex executable; fails the test with its output if it exits non-zero."""
    cmd = [str(solidtex_bin())] + [str(a) for a in args]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} exited {proc.returncode}\n"
                             f"stdout:\n{proc.stdout}\nstderr:\n{proc.stderr}")
    return proc


class Server:
    """One running `solidtex serve` process."""

    def __init__(self, binary: Path, data_dir: Path, log_path: Path, flags: Sequence[str],
                 port: Optional[int] = None) -> None:
        self.data_dir = Path(data_dir)
        self.data_dir.mkdir(parents=True, exist_ok=True)
        self.log_path = log_path
        self.flags = [str(f) for f in flags]
        self.port = port or free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.cmd = [str(binary), "serve", "--host", "127.0.0.1", "--port", str(self.port),
                    "--data", str(self.data_dir)] + self.flags
        self._log = open(log_path, "wb")
        self.proc = subprocess.Popen(self.cmd, stdout=self._log, stderr=subprocess.STDOUT)
        self.client = Client(self.url, timeout=HTTP_TIMEOUT)
        try:
            self._wait_healthy(30.0)
        except BaseException:
            self.kill()
            raise

    def _wait_healthy(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        last = ""
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                raise AssertionError(f"server exited with {self.proc.returncode} before it was "
                                     f"healthy: {' '.join(self.cmd)}\n{self.log()}")
            try:
                r = requests.get(self.url + "/healthz", timeout=2)
                if r.status_code == 200:
                    return
                last = f"status {r.status_code}"
            except requests.RequestException as e:
                last = str(e)
            time.sleep(0.05)
        raise AssertionError(f"server not healthy after {seconds} s ({last}): "
                             f"{' '.join(self.cmd)}\n{self.log()}")

    def log(self, tail: int = 4000) -> str:
        try:
            if not self._log.closed:
                self._log.flush()
            return self.log_path.read_bytes()[-tail:].decode("utf-8", "replace")
        except (OSError, ValueError):
            return ""

    @property
    def running(self) -> bool:
        return self.proc.poll() is None

    def stop(self, grace: float = 10.0) -> Optional[int]:
        """SIGTERM, then SIGKILL after ``grace`` seconds; returns the exit code."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(grace)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(10)
        self._close()
        return self.proc.returncode

    def kill(self) -> None:
        """kill -9."""
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(10)
        self._close()

    def _close(self) -> None:
        self.client.close()
        if not self._log.closed:
            self._log.close()


class ServerFactory:
    """Starts servers (``start(*flags, data_dir=None)``) and stops them all at ``close()``."""

    def __init__(self, base_dir: Path) -> None:
        self.base_dir = Path(base_dir)
        self.base_dir.mkdir(parents=True, exist_ok=True)
        self.servers: List[Server] = []

    def start(self, *flags: Any, data_dir: Optional[Path] = None) -> Server:
        binary = solidtex_bin()
        n = len(self.servers)
        if data_dir is None:
            data_dir = self.base_dir / f"data{n}"
        log = self.base_dir / f"server{n}.log"
        server = Server(binary, Path(data_dir), log, [str(f) for f in flags])
        self.servers.append(server)
        return server

    __call__ = start

    def close(self) -> None:
        for s in reversed(self.servers):
            s.stop()


def small_exemplar(tmp_path: Path, kind: str, side: int) -> Path:
    """A procedural `kind` exemplar of side x side pixels (solidtex exemplar), written once."""
    path = tmp_path / f"{kind}{side}.png"
    run_cli("exemplar", kind, "-o", path, "--size", f"{side},{side}")
    return path


def wait_job(client: Client, job_id: str, seconds: float = 60) -> Dict[str, Any]:
    """The job once it has succeeded or failed, or as it is after `seconds`."""
    end = time.monotonic() + seconds
    while True:
        job = client.get_job(job_id)
        if job["state"] in ("succeeded", "failed") or time.monotonic() > end:
            return job
        time.sleep(0.1)


def wait_job_running(client: Client, job_id: str, message: str, seconds: float = 30) -> None:
    """Returns once the job is running; fails with `message` after `seconds`."""
    end = time.monotonic() + seconds
    while client.get_job(job_id)["state"] != "running":
        assert time.monotonic() < end, message
        time.sleep(0.05)


def http_status(url: str) -> int:
    return requests.get(url, timeout=30).status_code


@contextlib.contextmanager
def server_with_volume(base_dir: Path, image: Any, *flags: Any, seed: int,
                       name: Optional[str] = None) -> Iterator[SimpleNamespace]:
    """A server started with ``flags`` below ``base_dir``, ``image`` uploaded (as ``name``)
    and analysed, and a volume of it with ``seed``; the server stops when the block ends.

    Yields a namespace: server, url, client, exemplar (dict), exemplar_id, volume (dict),
    volume_id, dir (``base_dir``)."""
    factory = ServerFactory(Path(base_dir) / "servers")
    try:
        srv = factory.start(*flags)
        ex = upload_ready(srv.client, image, name=name)
        vol = srv.client.create_volume(exemplar=ex["id"], seed=seed)
        yield SimpleNamespace(server=srv, url=srv.url, client=srv.client, exemplar=ex,
                              exemplar_id=ex["id"], volume=vol, volume_id=vol["id"],
                              dir=Path(base_dir))
    finally:
        factory.close()


def upload_ready(client: Client, image: Any, **params: Any) -> Dict[str, Any]:
    """Upload with the small analysis parameters, wait for the job; returns the exemplar."""
    up = client.upload_exemplar(image, **{**ANALYSIS, **params})
    client.wait_for_job(up["job"]["id"], timeout=120, poll=0.1)
    return client.get_exemplar(up["exemplar"]["id"])


def png_pixels(data: bytes) -> np.ndarray:
    from PIL import Image
    img = Image.open(io.BytesIO(data))
    img.load()
    return np.asarray(img.convert("RGB"))


def file_pixels(path: Path) -> np.ndarray:
    return png_pixels(Path(path).read_bytes())


def srgb8(linear: Any) -> np.ndarray:
    """The sRGB8 encoding (as float64 integers) of linear colors, as the service encodes them."""
    c = np.clip(np.asarray(linear, np.float64), 0, 1)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    return np.rint(s * 255)


def shared_mesh(name: str) -> Path:
    """The path of a shared mesh file; skips the test (with a message) when it is absent."""
    path = MESH_DIR / name
    if not path.is_file():
        pytest.skip(f"shared mesh {path} not found (set SOLIDTEX_MESHES or add ../shared/data)")
    return path


def client_cli(url: str, *args: Any, check: bool = True) -> subprocess.CompletedProcess:
    """Run ``python -m solidtex_client.cli --url URL ARGS``; with ``check`` a non-zero exit
    fails the test with the command's output."""
    env = {**os.environ, "PYTHONPATH": str(CLIENT_DIR) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    cmd = [sys.executable, "-m", "solidtex_client.cli", "--url", url, *[str(a) for a in args]]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    if check:
        assert proc.returncode == 0, (f"{' '.join(cmd)}: exit {proc.returncode}\n"
                                      f"{proc.stdout}\n{proc.stderr}")
    return proc


def fake_response(status: int, body: Any = b"", headers: Optional[Dict[str, str]] = None
                  ) -> requests.Response:
    """A ``requests.Response`` with ``status``, ``body`` (bytes, or JSON for anything else)
    and ``headers``, for the client tests without a server."""
    r = requests.Response()
    r.status_code = status
    r._content = body if isinstance(body, bytes) else json.dumps(body).encode()
    r.headers.update(headers or {})
    r.encoding = "utf-8"
    return r


class FakeSession(requests.Session):
    """Records the prepared requests (``sent``) and answers from a list of canned responses."""

    def __init__(self, answers: Iterable[requests.Response]) -> None:
        super().__init__()
        self.answers = list(answers)
        self.sent: List[requests.PreparedRequest] = []

    def send(self, request, **kwargs):
        self.sent.append(request)
        r = self.answers.pop(0)
        r.request = request
        return r


def assert_error(response: requests.Response, status: Union[int, Collection[int]],
                 code: Optional[str] = None,
                 field_contains: Optional[str] = None) -> Dict[str, Any]:
    """The answer has ``status`` (or one of the statuses) and the documented error body;
    returns the error object."""
    statuses = {status} if isinstance(status, int) else set(status)
    assert response.status_code in statuses, (
        f"expected {sorted(statuses)}, got {response.status_code}: {response.text[:500]}")
    assert response.headers.get("Content-Type", "").startswith("application/json"), \
        response.headers.get("Content-Type")
    body = response.json()
    assert set(body) == {"error"}, body
    err = body["error"]
    for key in ("code", "message", "field"):
        assert isinstance(err.get(key), str), f"error.{key} missing or not a string: {body}"
    assert err["code"], body
    assert err["message"], body
    if code is not None:
        assert err["code"] == code, body
    if field_contains is not None:
        assert field_contains in err["field"], body
    return err


def png_with_header(width: int, height: int) -> bytes:
    """A tiny PNG whose IHDR claims width x height (RGB8), with valid CRCs and one IDAT."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr)
            + chunk(b"IDAT", zlib.compress(b"\x00" * 64)) + chunk(b"IEND", b""))


def post_bytes(url: str, body: bytes, params: Optional[Dict[str, Any]] = None,
               timeout: float = 60) -> requests.Response:
    """POST ``body`` as ``application/octet-stream`` (an image, mesh or points upload)."""
    return requests.post(url, params=params, data=body,
                         headers={"Content-Type": "application/octet-stream"}, timeout=timeout)


def raw_post(url: str, path: str, body: bytes, content_type: str = "application/octet-stream",
             timeout: float = 30.0) -> int:
    """POST ``body`` over a plain socket, stopping the upload as soon as the server answers
    (a server may reject an oversized body before reading it). Returns the status code."""
    host, port = url.split("//", 1)[1].split(":")
    sock = socket.create_connection((host, int(port)), timeout=timeout)
    try:
        head = (f"POST {path} HTTP/1.1\r\nHost: {host}:{port}\r\nContent-Type: {content_type}\r\n"
                f"Content-Length: {len(body)}\r\nConnection: close\r\n\r\n").encode()
        sock.sendall(head)
        sent, answer = 0, b""
        end = time.monotonic() + timeout
        while sent < len(body) and time.monotonic() < end:
            readable, _, _ = select.select([sock], [], [], 0)
            if readable:
                break
            try:
                sent += sock.send(body[sent:sent + 65536])
            except (BrokenPipeError, ConnectionResetError):
                break
        while time.monotonic() < end and b"\r\n" not in answer:
            try:
                chunk = sock.recv(65536)
            except ConnectionResetError:
                break
            if not chunk:
                break
            answer += chunk
        line = answer.split(b"\r\n", 1)[0].decode("latin-1")
        if not line.startswith("HTTP/"):
            raise AssertionError(f"no HTTP answer (sent {sent} of {len(body)} bytes): {answer[:200]!r}")
        return int(line.split()[1])
    finally:
        sock.close()


def metric_lines(text: str, name: str) -> List[str]:
    """Sample lines of metric ``name`` (``name`` or ``name{...}`` followed by a value)."""
    out = []
    for line in text.splitlines():
        if line.startswith("#"):
            continue
        if line.startswith(name + " ") or line.startswith(name + "{"):
            out.append(line)
    return out


# A closed unit cube (12 triangles), the smallest valid mesh upload.
CUBE_OFF = b"""OFF
8 12 0
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
3 0 2 1
3 0 3 2
3 4 5 6
3 4 6 7
3 0 1 5
3 0 5 4
3 2 3 7
3 2 7 6
3 1 2 6
3 1 6 5
3 0 4 7
3 0 7 3
"""
