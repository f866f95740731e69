"""Issue 11: memory per loaded volume outside the voxel cache is counted and bounded. Loaded
volumes' state (tables, fields, surface bands, synthesizers) is reported per volume
(GET /v1/volumes/{id}/stats "state") and in total (/metrics); past --volume-state-mb the least
recently used idle volumes are evicted, and volumes idle for --idle-evict-s too. An evicted
volume is rebuilt at its next query and answers the same bytes (synthesis is spatially
deterministic)."""
from __future__ import annotations

import threading
import time
from typing import Dict

import pytest
import requests

from support import CUBE_OFF, HTTP_TIMEOUT, RAW_F32, ServerFactory, metric_lines, post_bytes, upload_ready

MB = 1 << 20
# Each 64x64 exemplar's volume state (a 3-level table with packed candidate lists, shared by
# the three planes; its synthesizer and field) is about 1.4 MB: the budget holds two volumes.
BUDGET_MB = 3


def metrics(s) -> Dict[str, float]:
    text = s.client.metrics()
    out = {}
    for name in ("solidtex_volume_state_bytes", "solidtex_volume_state_budget_bytes", "solidtex_volumes_loaded",
                 "solidtex_volume_state_loads_total", "solidtex_cache_bytes", "solidtex_cache_budget_bytes"):
        lines = metric_lines(text, name)
        assert len(lines) == 1, (name, text[-2000:])
        out[name] = float(lines[0].split()[-1])
    for reason in ("budget", "idle"):
        lines = metric_lines(text, "solidtex_volume_evictions_total")
        mine = [l for l in lines if f'reason="{reason}"' in l]
        assert len(mine) == 1, lines
        out["evictions_" + reason] = float(mine[0].split()[-1])
    return out


def state(s, vid: str) -> dict:
    st = s.client.volume_stats(vid)["state"]
    parts = st["synthesizer_bytes"] + st["table_bytes"] + st["field_bytes"] + st["surface_bytes"]
    assert st["bytes"] == parts, st
    return st


def slice_bytes(s, vid: str, size: str = "12,10", at: int = 3) -> bytes:
    r = requests.get(f"{s.url}/v1/volumes/{vid}/slice", params={"axis": "z", "at": at, "origin": "-5,2", "size": size},
                     headers=RAW_F32, timeout=HTTP_TIMEOUT)
    assert r.status_code == 200, r.text
    return r.content


def points_bytes(s, vid: str, pts) -> bytes:
    r = requests.post(f"{s.url}/v1/volumes/{vid}/points", json={"points": pts}, headers=RAW_F32, timeout=HTTP_TIMEOUT)
    assert r.status_code == 200, r.text
    return r.content


def wait_for(predicate, seconds: float, what: str) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if predicate():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out after {seconds} s waiting for {what}")


@pytest.fixture(scope="module")
def budget(binary, exemplars, tmp_path_factory):
    """A server with --volume-state-mb 3 (no idle eviction) and one volume per exemplar kind."""
    factory = ServerFactory(tmp_path_factory.mktemp("volume-state"))
    try:
        s = factory.start("--threads", "2", "--volume-state-mb", BUDGET_MB, "--idle-evict-s", "0")
        s.volumes = {}
        for kind in ("wood", "stripes", "bricks", "noise"):
            # isotropic layouts (one table plane), so that two volumes' state fits the budget
            ex = upload_ready(s.client, exemplars[kind], grain="none")
            s.volumes[kind] = s.client.create_volume(exemplar=ex["id"], seed=3)["id"]
        yield s
    finally:
        factory.close()


def test_state_is_counted_and_the_total_stays_under_the_budget(budget):
    s = budget
    m = metrics(s)
    assert m["solidtex_volume_state_budget_bytes"] == BUDGET_MB * MB
    assert m["solidtex_volumes_loaded"] == 0  # nothing is built before the first query
    for vid in s.volumes.values():
        st = state(s, vid)
        assert not st["loaded"] and st["bytes"] == 0 and st["loads"] == 0, st
    first = {}
    for kind, vid in s.volumes.items():
        first[kind] = slice_bytes(s, vid)
        st = state(s, vid)
        assert st["loaded"] and st["loads"] >= 1 and st["active_requests"] == 0, st
        assert st["table_bytes"] > MB and st["synthesizer_bytes"] > 0 and st["field_bytes"] > 0, st
        assert st["surface_bytes"] == 0, st
        assert st["bytes"] < BUDGET_MB * MB / 2, st  # two fit: the test's premise
        m = metrics(s)
        assert 0 < m["solidtex_volume_state_bytes"] <= BUDGET_MB * MB, m
        loaded = [v for v in s.volumes.values() if state(s, v)["loaded"]]
        assert m["solidtex_volumes_loaded"] == len(loaded) <= 2, m
        assert m["solidtex_volume_state_bytes"] == sum(state(s, v)["bytes"] for v in loaded), m
        assert m["solidtex_cache_bytes"] <= m["solidtex_cache_budget_bytes"], m
    m = metrics(s)
    assert m["evictions_budget"] >= 2, m
    assert m["evictions_idle"] == 0, m
    # The evicted ones are the least recently used: wood and stripes.
    assert not state(s, s.volumes["wood"])["loaded"]
    assert not state(s, s.volumes["stripes"])["loaded"]
    assert state(s, s.volumes["noise"])["loaded"]
    # Each answers the same bytes again, rebuilt from its table, while others go.
    for kind, vid in s.volumes.items():
        assert slice_bytes(s, vid) == first[kind], kind
        assert metrics(s)["solidtex_volume_state_bytes"] <= BUDGET_MB * MB
    st = state(s, s.volumes["wood"])
    assert st["loads"] == 2 and st["evictions"] >= 1, st


def test_an_evicted_volume_answers_the_same_bytes_as_before(budget):
    s = budget
    wood = s.volumes["wood"]
    before = slice_bytes(s, wood, size="24,20", at=-7)  # its cache now holds these voxels
    pts = [[0.4, -3.2, 7.9], [-120.0, 44.0, 3.0], [5000.0, 1.0, -2.0]]
    points_before = points_bytes(s, wood, pts)
    for kind in ("stripes", "bricks", "noise"):  # evicts wood (and its cache)
        slice_bytes(s, s.volumes[kind], size="4,4")
    st = state(s, wood)
    assert not st["loaded"] and st["bytes"] == 0, st
    assert s.client.volume_stats(wood)["cache"]["bytes"] == 0
    assert slice_bytes(s, wood, size="24,20", at=-7) == before
    assert points_bytes(s, wood, pts) == points_before
    # A volume of the same spec that was never evicted agrees too.
    ex = s.client.get_volume(wood)["exemplars"][0]
    twin = s.client.create_volume(exemplar=ex, seed=3)["id"]
    assert slice_bytes(s, twin, size="24,20", at=-7) == before


def test_a_running_request_keeps_its_state(budget, tmp_path):
    s = budget
    slow, other = s.volumes["bricks"], s.volumes["stripes"]
    ex = s.client.get_volume(slow)["exemplars"][0]
    fresh = s.client.create_volume(exemplar=ex, seed=5)["id"]  # nothing cached: the cut takes a while
    out = {}

    def run():
        out["bytes"] = slice_bytes(s, fresh, size="96,96")

    t = threading.Thread(target=run)
    t.start()
    try:
        wait_for(lambda: state(s, fresh)["active_requests"] == 1, 60, "the slow request to start")
        # Other volumes come and go meanwhile; the running one is never evicted.
        for kind in ("wood", "stripes", "noise"):
            slice_bytes(s, s.volumes[kind], size="4,4")
            st = state(s, fresh)
            if st["active_requests"] == 1:
                assert st["loaded"], st
            assert metrics(s)["solidtex_volumes_loaded"] <= 3
    finally:
        t.join(HTTP_TIMEOUT)
    assert "bytes" in out
    assert state(s, fresh)["active_requests"] == 0
    # Evict it, then the same cut again from scratch: the same bits.
    for vid in (other, s.volumes["noise"], s.volumes["wood"]):
        slice_bytes(s, vid, size="4,4")
    assert not state(s, fresh)["loaded"]
    assert slice_bytes(s, fresh, size="96,96") == out["bytes"]
    assert metrics(s)["solidtex_volume_state_bytes"] <= BUDGET_MB * MB


def test_idle_volumes_are_evicted_and_rebuilt(server, exemplars):
    s = server("--threads", "2", "--idle-evict-s", "2")
    wood = upload_ready(s.client, exemplars["wood"])["id"]
    stripes = upload_ready(s.client, exemplars["stripes"])["id"]
    plain = s.client.create_volume(exemplar=wood, seed=2)["id"]
    # A stored field (the volume's own copy of its grid) and a surface label (a distance band,
    # built at creation) are part of the state too.
    sketch = {"domain": {"min": [-20, -20, -20], "max": [20, 20, 20], "shortest_side_cells": 6},
              "curves": [{"axis": "x", "plane_normal": [0, 0, 1], "points": [[-10, -5, 0], [0, 5, 0], [10, -5, 0]]}]}
    field = s.client.create_field(sketch)["id"]
    steered = s.client.create_volume(exemplar=wood, field={"id": field}, seed=2)["id"]
    mesh = post_bytes(f"{s.url}/v1/meshes", CUBE_OFF, params={"name": "cube"}).json()["id"]
    r = requests.post(f"{s.url}/v1/volumes", timeout=HTTP_TIMEOUT, json={"regions": {
        "exemplars": [wood, stripes], "label": "surface:2", "mesh": {"id": mesh, "placement": {"resolution": 48}}}})
    assert r.status_code == 201, r.text
    shell = r.json()["id"]
    st = state(s, shell)
    if st["loaded"]:  # loaded at creation (unless it idled out already)
        assert st["surface_bytes"] > 0, st
    pts = [[24.0, 24.0, 6.0], [24.0, 24.0, 24.0], [7.0, 30.0, 12.0], [-3.0, 0.5, 2.0]]
    first = {plain: slice_bytes(s, plain)}
    first[steered] = slice_bytes(s, steered)
    assert state(s, steered)["field_bytes"] > 10000  # a 6+ cell grid, not a constant
    first[shell] = points_bytes(s, shell, pts)
    assert state(s, shell)["surface_bytes"] > 0
    for vid in first:
        wait_for(lambda: not state(s, vid)["loaded"], 10, f"{vid} to be evicted when idle")
    m = metrics(s)
    assert m["evictions_idle"] >= 3, m
    assert m["solidtex_volumes_loaded"] == 0 and m["solidtex_volume_state_bytes"] == 0, m
    assert m["solidtex_cache_bytes"] == 0, m  # evicted volumes take their caches with them
    assert slice_bytes(s, plain) == first[plain]
    assert slice_bytes(s, steered) == first[steered]
    assert points_bytes(s, shell, pts) == first[shell]
    for vid in first:
        assert state(s, vid)["loads"] >= 2


def test_state_options_are_validated(binary, tmp_path):
    import subprocess
    for flags in (["--volume-state-mb", "-1"], ["--idle-evict-s", "-2"], ["--idle-evict-s", "nan"]):
        proc = subprocess.run([str(binary), "serve", "--data", str(tmp_path / "d"), *flags], capture_output=True,
                              text=True, timeout=30)
        assert proc.returncode == 2, (flags, proc.stdout, proc.stderr)
        assert flags[0] in proc.stderr, proc.stderr
