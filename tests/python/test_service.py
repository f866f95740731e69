"""Liveness, the served contract and Prometheus metrics."""
import json

import requests

from support import REPO, metric_lines


def test_healthz_and_ready_line(shared):
    srv = shared.server
    r = requests.get(srv.url + "/healthz", timeout=10)
    assert r.status_code == 200
    assert r.headers["Content-Type"].startswith("application/json")
    assert isinstance(r.json(), dict)
    assert isinstance(shared.client.healthz(), dict)
    assert f"solidtex serve: listening on http://127.0.0.1:{srv.port}" in srv.log(100000)


def test_openapi_is_the_contract_file(shared):
    expected = json.loads((REPO / "proto" / "openapi.json").read_text())
    r = requests.get(shared.server.url + "/v1/openapi.json", timeout=10)
    assert r.status_code == 200
    assert r.headers["Content-Type"].startswith("application/json")
    assert r.json() == expected
    assert shared.client.openapi() == expected


def test_metrics_after_requests(shared):
    c = shared.client
    c.healthz()
    c.list_exemplars()
    c.get_volume(shared.volume_id)
    c.slice(shared.volume_id, "z", 40, (8, 8), origin=(300, 300))
    r = requests.get(shared.server.url + "/metrics", timeout=10)
    assert r.status_code == 200
    assert r.headers["Content-Type"].startswith("text/plain")
    text = r.text
    assert "solidtex_requests_total" in c.metrics()
    totals = metric_lines(text, "solidtex_requests_total")
    assert totals, text[:2000]
    assert sum(float(line.rsplit(" ", 1)[1]) for line in totals) >= 4
    assert metric_lines(text, "solidtex_queue_depth"), text[:2000]
    buckets = metric_lines(text, "solidtex_request_seconds_bucket")
    assert buckets, text[:2000]
    assert all('le="' in line for line in buckets), buckets[:5]
    assert any('le="+Inf"' in line for line in buckets), buckets[:5]
