"""The client's encoding, request building and error mapping, without a server."""
import io
import json
import struct
import zlib
from urllib.parse import parse_qs, urlsplit

import numpy as np
import pytest
from PIL import Image

from support import FakeSession, fake_response  # (support also puts <repo>/client on sys.path)
from solidtex_client import (BadRequest, Client, Conflict, DeadlineExceeded, JobFailed,
                             MethodNotAllowed, NotFound, PayloadTooLarge, ServiceUnavailable, StorageUnavailable,
                             SolidtexError, TooManyRequests, Unprocessable, UnsupportedMediaType,
                             encode_png, error_from_response)
from solidtex_client import cli as cli_module
from solidtex_client.cli import main as cli_main


def decode_png_raw(data: bytes) -> np.ndarray:
    """Minimal decoder for the unfiltered PNGs encode_png writes."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        assert struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])[0] == zlib.crc32(kind + body)
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, ctype = ihdr[:4]
    ch = {0: 1, 4: 2, 2: 3, 6: 4}[ctype]
    rows = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(h, -1)
    assert (rows[:, 0] == 0).all()
    dt = np.dtype(">u2") if depth == 16 else np.dtype(np.uint8)
    return rows[:, 1:].copy().view(dt).reshape(h, w, ch).astype(dt.newbyteorder("="))


@pytest.mark.parametrize("shape", [(5, 7), (5, 7, 3), (5, 7, 4), (5, 7, 2)])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_encode_png_is_lossless(shape, dtype):
    rng = np.random.default_rng(1)
    a = rng.integers(0, np.iinfo(dtype).max + 1, size=shape).astype(dtype)
    back = decode_png_raw(encode_png(a))
    assert np.array_equal(back.reshape(a.shape), a)
    if dtype == np.uint8:
        assert np.array_equal(np.asarray(Image.open(io.BytesIO(encode_png(a)))), a)


def test_encode_png_float_is_16_bit():
    a = np.array([[0.0, 0.5, 1.0, 2.0, -1.0]], dtype=np.float32)
    back = decode_png_raw(encode_png(a))[:, :, 0]
    assert back.tolist() == [[0, 32768, 65535, 65535, 0]]
    with pytest.raises(ValueError):
        encode_png(np.full((2, 2), np.nan, dtype=np.float32))
    with pytest.raises(ValueError):
        encode_png(np.zeros((2, 2, 5), dtype=np.uint8))


@pytest.mark.parametrize("status,cls", [
    (400, BadRequest), (404, NotFound), (405, MethodNotAllowed), (409, Conflict),
    (413, PayloadTooLarge), (415, UnsupportedMediaType), (422, Unprocessable),
    (429, TooManyRequests), (502, StorageUnavailable), (503, ServiceUnavailable), (504, DeadlineExceeded)])
def test_error_classes_by_status(status, cls):
    e = error_from_response(fake_response(status, {"error": {"code": "c", "message": "m",
                                                              "field": "f"}}))
    assert type(e) is cls and isinstance(e, SolidtexError)
    assert (e.status, e.code, e.message, e.field) == (status, "c", "m", "f")
    assert str(e) == "c: m (f)"


def test_error_details():
    e = error_from_response(fake_response(503, {"error": {"code": "resource_exhausted",
                                                          "message": "queue full", "field": ""}},
                                          {"Retry-After": "3"}))
    assert isinstance(e, ServiceUnavailable) and e.retry_after == 3.0
    assert str(e) == "resource_exhausted: queue full"
    e = error_from_response(fake_response(502, {"error": {"code": "unavailable",
                                                          "message": "storage unavailable: cannot reach", "field": ""}},
                                          {"Retry-After": "1"}))
    assert isinstance(e, StorageUnavailable) and isinstance(e, ServiceUnavailable) and e.retry_after == 1.0
    e = error_from_response(fake_response(500, b"oops"))
    assert type(e) is SolidtexError and e.code == "http_500" and e.message == "oops"
    e = error_from_response(fake_response(503, b"", {"Retry-After": "soon"}))
    assert e.retry_after is None
    j = JobFailed({"id": "j1", "state": "failed",
                   "error": {"code": "corrupt", "message": "bad png", "field": "body"}})
    assert j.status is None and j.code == "corrupt" and j.field == "body"


def test_upload_raw_and_multipart():
    s = FakeSession([fake_response(202, {"exemplar": {"id": "e"}, "job": {"id": "j"}})] * 2)
    c = Client("http://svc:1/", session=s)
    out = c.upload_exemplar(b"\x89PNG-bytes", levels=3, plane_weights=(1, 0.5, 0.25), name="w")
    assert out["job"]["id"] == "j"
    req = s.sent[0]
    u = urlsplit(req.url)
    assert u.path == "/v1/exemplars"
    assert "plane_weights=1,0.5,0.25" in u.query
    assert parse_qs(u.query) == {"levels": ["3"], "plane_weights": ["1,0.5,0.25"], "name": ["w"]}
    assert req.headers["Content-Type"] == "application/octet-stream"
    assert req.body == b"\x89PNG-bytes"

    c.upload_exemplar(np.zeros((4, 4, 3), np.uint8), yz=b"\x89PNGyz", zx=b"\x89PNGzx",
                      mask=np.zeros((4, 4), np.uint8))
    req = s.sent[1]
    assert req.headers["Content-Type"].startswith("multipart/form-data")
    for part in (b'name="xy"', b'name="yz"', b'name="zx"', b'name="mask"'):
        assert part in req.body
    assert b"\x89PNGyz" in req.body


def test_slice_query_accept_and_parse():
    pix = np.arange(2 * 3 * 3, dtype=np.uint8)
    f32 = np.linspace(0, 1, 18).astype("<f4")
    s = FakeSession([
        fake_response(200, pix.tobytes(), {"X-Shape": "2,3,3", "Content-Type": "application/octet-stream"}),
        fake_response(200, f32.tobytes(), {"X-Shape": "2,3,3"}),
        fake_response(200, encode_png(pix.reshape(2, 3, 3)), {"Content-Type": "image/png"}),
    ])
    c = Client("http://svc:1", session=s)
    a = c.slice("v1", "z", 3, (3, 2), origin=(-1, 4))
    assert a.shape == (2, 3, 3) and a.dtype == np.uint8 and np.array_equal(a.ravel(), pix)
    q = parse_qs(urlsplit(s.sent[0].url).query)
    assert q == {"axis": ["z"], "at": ["3"], "origin": ["-1,4"], "size": ["3,2"]}
    assert s.sent[0].headers["Accept"] == "application/octet-stream"
    b = c.slice("v1", "z", 3, (3, 2), dtype="float32", timeout=0.5)
    assert b.dtype == np.float32 and np.array_equal(b.ravel(), f32)
    assert s.sent[1].headers["Accept"] == "application/octet-stream; dtype=float32"
    assert parse_qs(urlsplit(s.sent[1].url).query)["timeout"] == ["0.5"]
    img = c.slice("v1", "z", 3, (3, 2), dtype="png")
    assert img.size == (3, 2) and s.sent[2].headers["Accept"] == "image/png"


def test_points_and_cut_bodies():
    s = FakeSession([fake_response(200, np.ones((2, 3), "<f4").tobytes(), {"X-Shape": "2,3"}),
                     fake_response(200, bytes(12), {"X-Shape": "2,2,3"})])
    c = Client("http://svc:1", session=s)
    rgb = c.points("v", [[1, 2, 3], [4.5, 5, 6]])
    assert rgb.shape == (2, 3) and rgb.dtype == np.float32
    assert np.array_equal(np.frombuffer(s.sent[0].body, "<f4"), [1, 2, 3, 4.5, 5, 6])
    assert s.sent[0].headers["Content-Type"] == "application/octet-stream"
    c.cut("v", (0, 0, 1), (1, 0, 0), (0, 1, 0), (2, 2))
    assert json.loads(s.sent[1].body) == {"origin": [0, 0, 1], "u": [1, 0, 0], "v": [0, 1, 0],
                                         "size": [2, 2]}


def test_create_volume_keywords():
    s = FakeSession([fake_response(201, {"id": "v"}) for _ in range(3)])
    c = Client("http://svc:1", session=s)
    c.create_volume(exemplar="e", field="quat:1,0,0,0", seed=7, params={"scheme": "grid"})
    assert json.loads(s.sent[0].body) == {"exemplar": "e", "field": {"spec": "quat:1,0,0,0"},
                                         "seed": 7, "params": {"scheme": "grid"}}
    c.create_volume(regions=(("a", "b"), "halfspace:1,0,0,0"), field="f123")
    assert json.loads(s.sent[1].body) == {"regions": {"exemplars": ["a", "b"],
                                                      "label": "halfspace:1,0,0,0"},
                                         "field": {"id": "f123"}}
    c.create_volume({"exemplar": "e", "seed": 1}, seed=2)
    assert json.loads(s.sent[2].body) == {"exemplar": "e", "seed": 2}


def test_wait_for_job_raises_on_failure():
    s = FakeSession([fake_response(200, {"id": "j", "state": "running", "percent": 10}),
                     fake_response(200, {"id": "j", "state": "failed", "percent": 10,
                                         "error": {"code": "corrupt", "message": "x", "field": ""}})])
    with pytest.raises(JobFailed) as info:
        Client("http://svc:1", session=s).wait_for_job("j", poll=0.01)
    assert info.value.code == "corrupt"


def test_cli_reports_errors(capsys, tmp_path):
    assert cli_main(["--url", "http://127.0.0.1:9", "slice", "v", "--axis", "z", "--at", "0",
                     "--size", "4,4", "-o", str(tmp_path / "x.png")]) == 1
    assert capsys.readouterr().err.startswith("error: connection: ")


def test_region_answers_and_format_checks():
    box = np.arange(2 * 3 * 4 * 3, dtype=np.uint8)
    s = FakeSession([fake_response(200, box.tobytes()),                  # no X-Shape: from size
                     fake_response(200, bytes(10), {"X-Shape": "2,3,4,3"}),
                     fake_response(200, b" BDV..."),
                     fake_response(200, np.zeros((2, 3), "<f4").tobytes())])
    c = Client("http://svc:1", session=s)
    a = c.region("v", (1, 2, 3), (4, 3, 2), fmt="uint8", timeout=7)
    assert a.shape == (2, 3, 4, 3) and np.array_equal(a.ravel(), box)
    assert s.sent[0].headers["Accept"] == "application/octet-stream"
    assert parse_qs(urlsplit(s.sent[0].url).query) == {"min": ["1,2,3"], "size": ["4,3,2"],
                                                       "timeout": ["7"]}
    with pytest.raises(ValueError, match="10 bytes"):
        c.region("v", (0, 0, 0), (4, 3, 2), fmt="uint8")
    assert c.region("v", (0, 0, 0), (1, 1, 1)) == b" BDV..."
    assert s.sent[2].headers["Accept"] == "application/x-vdb"
    pts = c.points("v", np.array([[0, 0, 0], [1, 1, 1]]))                   # no X-Shape: N x 3
    assert pts.shape == (2, 3) and pts.dtype == np.float32
    for call in (lambda: c.region("v", (0, 0, 0), (1, 1, 1), fmt="png"),
                 lambda: c.slice("v", "z", 0, (1, 1), dtype="vdb"),
                 lambda: c.cut("v", (0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1), dtype="f16")):
        with pytest.raises(ValueError, match="must be one of"):
            call()
    assert len(s.sent) == 4, "a bad format was sent"


def test_cli_volume_scheme_and_number_lists(capsys, monkeypatch):
    session = FakeSession([fake_response(201, {"id": "v1"})])
    monkeypatch.setattr(cli_module, "Client",
                        lambda url, timeout: Client(url, timeout=timeout, session=session))
    assert cli_main(["--url", "http://svc:1", "volume", "--exemplar", "e", "--scheme", "plain",
                     "--seed", "3"]) == 0
    assert json.loads(capsys.readouterr().out) == {"id": "v1"}
    assert json.loads(session.sent[0].body) == {"exemplar": "e", "params": {"scheme": "plain"},
                                               "seed": 3}
    for argv, needle in ((["volume", "--exemplar", "e", "--scheme", "standard"], "invalid choice"),
                         (["slice", "v", "--axis", "z", "--at", "0", "--size", "4", "-o", "x"],
                          "expected 2 comma-separated integers, got '4'"),
                         (["slice", "v", "--axis", "z", "--at", "0", "--size", "4,x", "-o", "x"],
                          "expected 2 comma-separated integers, got '4,x'"),
                         (["upload", "a.png", "--plane-weights", "1,2"],
                          "expected 3 comma-separated numbers, got '1,2'")):
        with pytest.raises(SystemExit) as info:
            cli_main(argv)
        assert info.value.code == 2
        assert needle in capsys.readouterr().err, argv
    assert len(session.sent) == 1


def test_scale_goes_in_the_query_of_slice_and_cut():
    pix = bytes(2 * 3 * 3)
    s = FakeSession([fake_response(200, pix, {"X-Shape": "2,3,3"}) for _ in range(4)])
    c = Client("http://svc:1", session=s)
    c.slice("v", "z", 3, (3, 2), scale=2)
    assert parse_qs(urlsplit(s.sent[0].url).query)["scale"] == ["2"]
    c.slice("v", "z", 3, (3, 2), scale=np.int64(0))           # the default is not sent
    assert "scale" not in parse_qs(urlsplit(s.sent[1].url).query)
    c.cut("v", (0, 0, 1), (1, 0, 0), (0, 1, 0), (3, 2), scale=np.uint8(1), timeout=4)
    assert parse_qs(urlsplit(s.sent[2].url).query) == {"scale": ["1"], "timeout": ["4"]}
    assert json.loads(s.sent[2].body) == {"origin": [0, 0, 1], "u": [1, 0, 0], "v": [0, 1, 0],
                                         "size": [3, 2]}, "scale is a query parameter, not a body key"
    c.cut("v", (0, 0, 1), (1, 0, 0), (0, 1, 0), (3, 2))
    assert urlsplit(s.sent[3].url).query == ""


@pytest.mark.parametrize("bad, error", [(-1, ValueError), (np.int32(-2), ValueError),
                                        (1.0, TypeError), (1.5, TypeError), ("1", TypeError),
                                        (True, TypeError), (None, TypeError)])
def test_bad_scale_raises_naming_it_before_sending(bad, error):
    s = FakeSession([])
    c = Client("http://svc:1", session=s)
    for call in (lambda: c.slice("v", "z", 0, (1, 1), scale=bad),
                 lambda: c.cut("v", (0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1), scale=bad)):
        with pytest.raises(error, match="scale must be a non-negative integer"):
            call()
    assert s.sent == []


def test_undo_curve_request_and_answer():
    fld = {"id": "fld_1", "revision": 3, "curves": 1}
    s = FakeSession([fake_response(200, fld), fake_response(200, fld),
                     fake_response(409, {"error": {"code": "failed_precondition",
                                                   "message": "the sketch would be empty",
                                                   "field": "curves"}})])
    c = Client("http://svc:1", session=s)
    assert c.undo_curve("fld_1") == fld
    assert s.sent[0].method == "DELETE"
    assert urlsplit(s.sent[0].url).path == "/v1/fields/fld_1/curves/last"
    assert urlsplit(s.sent[0].url).query == "" and not s.sent[0].body
    c.undo_curve("fld_1", timeout=90)
    assert parse_qs(urlsplit(s.sent[1].url).query) == {"timeout": ["90"]}
    with pytest.raises(Conflict) as info:
        c.undo_curve("fld_1")
    assert info.value.field == "curves"


def test_revision_is_sent_only_when_given():
    fld = {"id": "fld_1", "revision": 4, "curves": 2}
    s = FakeSession([fake_response(200, fld) for _ in range(4)])
    c = Client("http://svc:1", session=s)
    curve = {"points": [[0, 0, 0], [1, 0, 0]], "plane_normal": [0, 0, 1]}
    c.add_curve("fld_1", curve)
    c.add_curve("fld_1", curve, revision=np.int64(3), timeout=9)
    c.undo_curve("fld_1")
    c.undo_curve("fld_1", revision=4)
    queries = [parse_qs(urlsplit(r.url).query) for r in s.sent]
    assert queries == [{}, {"revision": ["3"], "timeout": ["9"]}, {}, {"revision": ["4"]}]
    assert [r.method for r in s.sent] == ["POST", "POST", "DELETE", "DELETE"]
    assert json.loads(s.sent[1].body) == curve, "revision is a query parameter, not a body key"
    for bad, error in ((0, ValueError), (-1, ValueError), (True, TypeError), (2.0, TypeError), ("2", TypeError)):
        with pytest.raises(error, match="revision must be a positive integer"):
            c.undo_curve("fld_1", revision=bad)
        with pytest.raises(error, match="revision must be a positive integer"):
            c.add_curve("fld_1", curve, revision=bad)
    assert len(s.sent) == 4


def test_cli_slice_scale(capsys, monkeypatch, tmp_path):
    png = encode_png(np.zeros((2, 3, 3), np.uint8))
    session = FakeSession([fake_response(200, png, {"Content-Type": "image/png"})])
    monkeypatch.setattr(cli_module, "Client",
                        lambda url, timeout: Client(url, timeout=timeout, session=session))
    out = tmp_path / "s.png"
    assert cli_main(["--url", "http://svc:1", "slice", "v", "--axis", "z", "--at", "1",
                     "--size", "3,2", "--scale", "2", "-o", str(out)]) == 0
    assert out.read_bytes() == png
    assert parse_qs(urlsplit(session.sent[0].url).query)["scale"] == ["2"]
    assert cli_main(["--url", "http://svc:1", "slice", "v", "--axis", "z", "--at", "1",
                     "--size", "3,2", "--scale", "-1", "-o", str(tmp_path / "x.png")]) == 1
    assert "scale must be a non-negative integer" in capsys.readouterr().err
    assert len(session.sent) == 1 and not (tmp_path / "x.png").exists()


def test_cli_takes_negative_coordinate_lists_after_their_option(monkeypatch, tmp_path):
    assert cli_module.attach_negative_values(["--origin", "-60,-60", "--at", "-4", "-o", "x"]) == \
        ["--origin=-60,-60", "--at=-4", "-o", "x"]
    assert cli_module.attach_negative_values(["--min=-1,0,0", "-o", "-5"]) == ["--min=-1,0,0", "-o", "-5"]
    png = encode_png(np.zeros((2, 3, 3), np.uint8))
    session = FakeSession([fake_response(200, png, {"Content-Type": "image/png"})])
    monkeypatch.setattr(cli_module, "Client",
                        lambda url, timeout: Client(url, timeout=timeout, session=session))
    assert cli_main(["--url", "http://svc:1", "slice", "v", "--axis", "x", "--at", "-40",
                     "--origin", "-60,-60", "--size", "3,2", "-o", str(tmp_path / "s.png")]) == 0
    query = parse_qs(urlsplit(session.sent[0].url).query)
    assert query["at"] == ["-40"] and query["origin"] == ["-60,-60"]
