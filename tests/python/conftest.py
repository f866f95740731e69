"""Fixtures for the end-to-end tests of `solidtex serve`.

SOLIDTEX_BIN names the solidtex executable (default <repo>/build/bin/solidtex); without it
every test that needs it is skipped with a message (see `pytest -rs`).
"""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import support  # noqa: E402
from support import ANALYSIS_CLI, ServerFactory, run_cli, server_with_volume, solidtex_bin  # noqa: E402

KINDS = ("wood", "stripes", "bricks", "noise", "spots")


@pytest.fixture(scope="session")
def binary() -> Path:
    path = solidtex_bin()
    if not path.is_file():
        pytest.skip(f"solidtex executable not found at {path}: build it or set SOLIDTEX_BIN")
    return path


@pytest.fixture(scope="session")
def free_port():
    """``free_port()`` -> a currently free TCP port on 127.0.0.1."""
    return support.free_port


@pytest.fixture
def server(binary, tmp_path):
    """Factory: ``server(*flags, data_dir=None)`` starts `solidtex serve` and waits for
    /healthz; the object has ``.url .data_dir .proc .client .stop() .kill()``. Pass an old
    server's ``data_dir`` to restart on it. Every server is stopped (SIGTERM, then SIGKILL
    after 10 s) at teardown."""
    factory = ServerFactory(tmp_path / "servers")
    yield factory
    factory.close()


@pytest.fixture(scope="session")
def exemplars(binary, tmp_path_factory) -> dict:
    """Procedural 64x64 exemplars from `solidtex exemplar`: kind -> PNG path."""
    d = tmp_path_factory.mktemp("exemplars")
    out = {}
    for kind in KINDS:
        path = d / f"{kind}.png"
        run_cli("exemplar", kind, "-o", path, "--size", "64,64")
        out[kind] = path
    return out


@pytest.fixture(scope="session")
def cli_table(binary, exemplars, tmp_path_factory) -> Path:
    """wood.png analysed by the CLI with the suite's small parameters."""
    path = tmp_path_factory.mktemp("cli") / "t.stx"
    run_cli("analyze", exemplars["wood"], *ANALYSIS_CLI, "-o", path)
    return path


@pytest.fixture(scope="session")
def shared(binary, exemplars, tmp_path_factory):
    """One server for the read-mostly tests: wood analysed (ready) and a volume with seed 7.

    Namespace: server, url, client, exemplar (dict), exemplar_id, volume (dict), volume_id,
    table (bytes), table_path (the downloaded .stx), dir (scratch directory)."""
    with server_with_volume(tmp_path_factory.mktemp("shared"), exemplars["wood"], seed=7,
                            name="wood") as ns:
        ns.table = ns.client.get_exemplar_table(ns.exemplar_id)
        ns.table_path = ns.dir / "server.stx"
        ns.table_path.write_bytes(ns.table)
        yield ns
