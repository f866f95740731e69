"""Back-pressure and deadlines: a full worker queue answers 503 + Retry-After, a passed
deadline 504, and the server keeps serving afterwards."""
import threading
import time

import pytest
import requests

from support import RAW, assert_error, metric_lines, post_bytes, server_with_volume

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def busy(binary, exemplars, tmp_path_factory):
    with server_with_volume(tmp_path_factory.mktemp("limits"), exemplars["wood"],
                            "--threads", "1", "--queue", "1", seed=3) as ns:
        yield ns


def small_slice_eventually(url: str, volume_id: str, seconds: float = 30) -> requests.Response:
    """A tiny slice, retried on 503 for up to ``seconds``."""
    end = time.monotonic() + seconds
    while True:
        r = requests.get(f"{url}/v1/volumes/{volume_id}/slice",
                         params={"axis": "z", "at": -50, "size": "4,4"}, headers=RAW, timeout=60)
        if r.status_code != 503 or time.monotonic() > end:
            return r
        time.sleep(min(1.0, float(r.headers.get("Retry-After", "1") or 1)))


def test_queue_full_answers_503_with_retry_after(busy):
    n = 8
    barrier = threading.Barrier(n)
    answers = [None] * n

    def fire(i: int) -> None:
        barrier.wait()
        try:
            answers[i] = requests.get(
                f"{busy.url}/v1/volumes/{busy.volume_id}/slice",
                params={"axis": "z", "at": 20 + 9 * i, "size": "96,96"}, headers=RAW, timeout=120)
        except requests.RequestException as e:  # recorded, asserted below
            answers[i] = e

    threads = [threading.Thread(target=fire, args=(i,)) for i in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(180)
    assert not any(t.is_alive() for t in threads), "requests hung"
    errors = [a for a in answers if not isinstance(a, requests.Response)]
    assert not errors, errors
    statuses = sorted(a.status_code for a in answers)
    assert set(statuses) <= {200, 503}, statuses
    assert 503 in statuses, f"no request was turned away: {statuses}"
    assert 200 in statuses, statuses
    for a in answers:
        if a.status_code == 200:
            assert len(a.content) == 96 * 96 * 3
        else:
            assert_error(a, 503)
            assert "Retry-After" in a.headers, a.headers
            assert int(a.headers["Retry-After"]) >= 0

    assert requests.get(busy.url + "/healthz", timeout=30).status_code == 200
    assert small_slice_eventually(busy.url, busy.volume_id).status_code == 200
    depth = metric_lines(busy.client.metrics(), "solidtex_queue_depth")
    assert depth and all(float(line.rsplit(" ", 1)[1]) == 0 for line in depth), depth


def test_deadline_answers_504_and_cancels(busy):
    cut = {"origin": [500.5, -300.25, 77.5], "u": [0.6, 0.8, 0], "v": [-0.48, 0.36, 0.8],
           "size": [160, 160]}
    t0 = time.monotonic()
    r = requests.post(f"{busy.url}/v1/volumes/{busy.volume_id}/cut", params={"timeout": "0.05"},
                      json=cut, headers=RAW, timeout=120)
    elapsed = time.monotonic() - t0
    assert_error(r, 504, "deadline_exceeded")
    assert elapsed < 5, f"504 came after {elapsed:.1f} s"
    assert requests.get(busy.url + "/healthz", timeout=30).status_code == 200
    # the worker is free again soon: the cancelled synthesis does not run on
    t0 = time.monotonic()
    r = small_slice_eventually(busy.url, busy.volume_id)
    assert r.status_code == 200, r.text
    assert time.monotonic() - t0 < 15


def test_too_many_analysis_jobs_is_429(server, exemplars):
    srv = server("--max-jobs", "1")
    data = exemplars["noise"].read_bytes()
    params = {"levels": 3, "neighborhood": 7, "candidates": 8, "pca_dims": 12}
    first = post_bytes(srv.url + "/v1/exemplars", data, params=params)
    assert first.status_code == 202, first.text
    second = post_bytes(srv.url + "/v1/exemplars", data, params=params)
    assert_error(second, 429)
    from solidtex_client import TooManyRequests
    with pytest.raises(TooManyRequests):
        srv.client.upload_exemplar(data, **params)
    srv.client.wait_for_job(first.json()["job"]["id"], timeout=120, poll=0.1)
    # the refused uploads left nothing behind, and a new one is accepted now
    assert [e["id"] for e in srv.client.list_exemplars()] == [first.json()["exemplar"]["id"]]
    third = post_bytes(srv.url + "/v1/exemplars", data, params=params)
    assert third.status_code == 202, third.text


def test_client_disconnect_cancels_the_synthesis(busy):
    """A client that hangs up frees its worker long before the synthesis would have ended."""
    # Four fine passes of 8 subpasses: the default schedule cuts this in under half a second,
    # this one takes about 11 s on this machine (five would exceed --max-request-mb: 422; so
    # would four with patch votes, whose support adds two planes: medoid colours keep it).
    heavy = busy.client.create_volume(exemplar=busy.exemplar_id, seed=3,
                                      params={"passes": 4, "finest_subpass_size": 2, "color": "medoid"})
    cut = {"origin": [-900.5, 410.25, -33.5], "u": [0.8, 0, 0.6], "v": [0, 1, 0], "size": [160, 160]}
    with pytest.raises(requests.exceptions.ReadTimeout):
        requests.post(f"{busy.url}/v1/volumes/{heavy['id']}/cut", params={"timeout": "120"},
                      json=cut, headers=RAW, timeout=0.5)
    # Cancelled, the only worker is idle soon.
    t0 = time.monotonic()
    busy_workers = None
    while time.monotonic() - t0 < 6:
        busy_workers = requests.get(busy.url + "/healthz", timeout=30).json()["workers_busy"]
        if busy_workers == 0:
            break
        time.sleep(0.1)
    assert busy_workers == 0, "the worker still runs the abandoned cut"
    assert time.monotonic() - t0 < 6
    stats = busy.client.volume_stats(heavy["id"])
    assert all(r["kind"] != "cut" or r["samples"] != 160 * 160 for r in stats["recent"]), \
        f"the abandoned cut was recorded as completed: {stats['recent']}"
