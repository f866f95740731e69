"""Volumes as chunked arrays (issue #14): OME-Zarr 0.5 (Zarr v3) under /zarr and Zarr v2 /
OME-Zarr 0.4 under /zarr2, opened by URL with zarr-python 3 over fsspec's HTTP store, and
compared bit for bit with the region endpoint; the HTTP behaviour chunked-array clients rely
on (never 404 for "not computed yet", 404 only outside the array, strong ETags stable across
restarts, immutable caching, CORS, HEAD, Range, If-None-Match); the OME-Zarr reader (ome-zarr)
over the same URL; Neuroglancer's jpeg precomputed chunks."""
from __future__ import annotations

import io

import numpy as np
import pytest
import requests

from support import ANALYSIS, upload_ready

zarr = pytest.importorskip("zarr", reason="zarr-python 3 is not installed (tests/python/requirements.txt)")

EXTENT = 128  # --array-extent: dataset 0 is 128^3 finest voxels, four chunks a side


@pytest.fixture(scope="module")
def volume(tmp_path_factory, binary, exemplars):
    from support import ServerFactory
    factory = ServerFactory(tmp_path_factory.mktemp("arrays"))
    srv = factory.start("--array-extent", EXTENT)
    ex = upload_ready(srv.client, exemplars["spots"])
    vol = srv.client.create_volume(exemplar=ex["id"], seed=3)
    yield srv, vol["id"], factory
    factory.close()


def region_czyx(srv, vid, lo, hi):
    """The region endpoint's sRGB voxels of the box [lo, hi) (z, y, x order) as (c, z, y, x)."""
    (z0, y0, x0), (z1, y1, x1) = lo, hi
    box = srv.client.region(vid, (x0, y0, z0), (x1 - x0, y1 - y0, z1 - z0), fmt="uint8")
    return np.moveaxis(box, -1, 0)


def test_zarr3_group_reads_the_region_endpoints_voxels(volume):
    srv, vid, _ = volume
    group = zarr.open_group(f"{srv.url}/v1/volumes/{vid}/zarr", mode="r", zarr_format=3)
    ome = group.attrs["ome"]
    assert ome["version"] == "0.5"
    (ms,) = ome["multiscales"]
    assert [a["name"] for a in ms["axes"]] == ["c", "z", "y", "x"]
    assert [d["path"] for d in ms["datasets"]] == ["0", "1", "2"]  # the suite's 3 synthesis levels
    assert ms["datasets"][1]["coordinateTransformations"][0]["scale"] == [1.0, 2.0, 2.0, 2.0]
    finest = group["0"]
    assert finest.shape == (3, EXTENT, EXTENT, EXTENT)
    assert finest.chunks == (3, 32, 32, 32)
    assert finest.dtype == np.uint8
    assert list(finest.metadata.dimension_names) == ["c", "z", "y", "x"]
    # one chunk, aligned, then a box across eight chunks
    aligned = finest[:, 32:64, 0:32, 64:96]
    assert np.array_equal(aligned, region_czyx(srv, vid, (32, 0, 64), (64, 32, 96)))
    unaligned = finest[:, 20:45, 30:37, 50:90]
    assert np.array_equal(unaligned, region_czyx(srv, vid, (20, 30, 50), (45, 37, 90)))
    assert unaligned.std() > 5, "a flat box says nothing"
    # a coarser dataset: synthesis level 1 of 0..2, half the side, a different image
    coarse = group["1"]
    assert coarse.shape == (3, EXTENT // 2, EXTENT // 2, EXTENT // 2)
    c = coarse[:, 0:16, 0:16, 0:16]
    assert c.std() > 5
    assert np.array_equal(c, coarse[:, 0:16, 0:16, 0:16])


def test_tensorstore_reads_the_same_voxels_in_both_formats(volume):
    ts = pytest.importorskip("tensorstore", reason="tensorstore is not installed (tests/python/requirements.txt)")
    srv, vid, _ = volume
    # bounded retries: a 503 (overload) is retried a few times, then reported
    ctx = ts.Context({"http_request_retries": {"max_retries": 4, "initial_delay": "100ms", "max_delay": "2s"}})
    want = region_czyx(srv, vid, (40, 3, 70), (72, 19, 101))
    for driver, path in (("zarr3", "zarr/0/"), ("zarr", "zarr2/0/")):
        t = ts.open({"driver": driver, "kvstore": f"{srv.url}/v1/volumes/{vid}/{path}"}, context=ctx, read=True).result()
        assert t.shape == (3, EXTENT, EXTENT, EXTENT)
        got = t[:, 40:72, 3:19, 70:101].read().result()
        assert np.array_equal(got, want), driver


def test_precomputed_raw_chunks_are_the_zarr_chunks_uncompressed(volume):
    srv, vid, _ = volume
    base = f"{srv.url}/v1/volumes/{vid}/precomputed"
    info = requests.get(f"{base}/info", timeout=60).json()
    assert info["@type"] == "neuroglancer_multiscale_volume" and info["num_channels"] == 3
    assert [s["key"] for s in info["scales"]] == ["0", "1", "2"]
    assert info["scales"][0]["size"] == [EXTENT] * 3 and [64, 64, 8] in info["scales"][0]["chunk_sizes"]
    # a 32^3 chunk: x fastest, channel slowest == the C-order (c, z, y, x) zarr chunk
    raw = requests.get(f"{base}/0/64-96_32-64_0-32", timeout=120)
    assert raw.status_code == 200 and raw.headers["Access-Control-Allow-Origin"] == "*"
    v3 = zarr.open_group(f"{srv.url}/v1/volumes/{vid}/zarr", mode="r", zarr_format=3)
    assert raw.content == v3["0"][:, 0:32, 32:64, 64:96].tobytes()
    # a flat slab for 2-D views, and a coarser scale
    flat = np.frombuffer(requests.get(f"{base}/0/0-64_64-128_8-16", timeout=120).content, np.uint8).reshape(3, 8, 64, 64)
    assert np.array_equal(flat, region_czyx(srv, vid, (8, 64, 0), (16, 128, 64)))
    coarse = requests.get(f"{base}/1/0-32_0-32_32-64", timeout=120).content
    assert coarse == v3["1"][:, 32:64, 0:32, 0:32].tobytes()
    for bad in ("0/0-65_0-8_0-8", "0/0-64_0-64_0-64", "0/120-136_0-8_0-8", "0/0-8_0-8", "1/64-96_0-32_0-32", "3/0-8_0-8_0-8"):
        assert requests.get(f"{base}/{bad}", timeout=60).status_code == 404, bad


def test_precomputed_jpeg_chunks_are_the_raw_voxels_up_to_jpeg_loss(volume):
    from PIL import Image
    srv, vid, _ = volume
    base = f"{srv.url}/v1/volumes/{vid}"
    info = requests.get(f"{base}/precomputed-jpeg/info", timeout=60).json()
    raw_info = requests.get(f"{base}/precomputed/info", timeout=60).json()
    assert [s["encoding"] for s in info["scales"]] == ["jpeg"] * 3
    assert [{**s, "encoding": "raw"} for s in info["scales"]] == raw_info["scales"]
    for name, (x0, x1, y0, y1, z0, z1) in (("0-64_64-128_8-16", (0, 64, 64, 128, 8, 16)),
                                           ("96-128_0-32_32-64", (96, 128, 0, 32, 32, 64))):
        r = requests.get(f"{base}/precomputed-jpeg/0/{name}", timeout=120)
        assert r.status_code == 200 and r.headers["Content-Type"] == "image/jpeg"
        raw = requests.get(f"{base}/precomputed/0/{name}", timeout=120)
        assert r.headers["ETag"] != raw.headers["ETag"]
        img = Image.open(io.BytesIO(r.content))
        # Neuroglancer's layout: width x, height y*z (z slices stacked), RGB
        assert img.mode == "RGB" and img.size == (x1 - x0, (y1 - y0) * (z1 - z0))
        got = np.asarray(img).reshape(z1 - z0, y1 - y0, x1 - x0, 3).astype(int)
        want = np.moveaxis(region_czyx(srv, vid, (z0, y0, x0), (z1, y1, x1)), 0, -1).astype(int)
        err = np.abs(got - want)
        assert err.mean() < 8 and np.percentile(err, 99) < 40, (err.mean(), np.percentile(err, 99))  # any misplacement: > 30
        print(f"{name}: jpeg {len(r.content)} bytes, raw {len(raw.content)}, mean error {err.mean():.2f}")
        assert len(r.content) * 2 < len(raw.content), (len(r.content), len(raw.content))
    assert requests.get(f"{base}/precomputed-jpeg/0/0-65_0-8_0-8", timeout=60).status_code == 404


def test_ome_zarr_reader_lists_the_multiscales(volume):
    ome_io = pytest.importorskip("ome_zarr.io", reason="ome-zarr is not installed (tests/python/requirements.txt)")
    from ome_zarr.reader import Multiscales, Reader
    srv, vid, _ = volume
    location = ome_io.parse_url(f"{srv.url}/v1/volumes/{vid}/zarr")
    assert location is not None and location.version == "0.5"
    nodes = list(Reader(location)())
    image = nodes[0]
    assert any(isinstance(spec, Multiscales) for spec in image.specs)
    assert [a["name"] for a in image.metadata["axes"]] == ["c", "z", "y", "x"]
    # one dataset per synthesis level (the suite's 3), each half the side of the one before
    assert [tuple(d.shape) for d in image.data] == [(3, EXTENT >> s, EXTENT >> s, EXTENT >> s) for s in range(3)]
    scales = [t[0]["scale"] for t in image.metadata["coordinateTransformations"]]
    assert scales == [[1.0, 1.0, 1.0, 1.0], [1.0, 2.0, 2.0, 2.0], [1.0, 4.0, 4.0, 4.0]]
    got = np.asarray(image.data[0][:, 10:30, 40:52, 100:128])
    assert np.array_equal(got, region_czyx(srv, vid, (10, 40, 100), (30, 52, 128)))


ARRAY_URLS = ("zarr/zarr.json", "zarr/0/zarr.json", "zarr/0/c/0/1/1/1", "zarr2/.zgroup", "zarr2/.zattrs",
              "zarr2/1/.zarray", "zarr2/1/0/1/0/1", "precomputed/info", "precomputed/0/0-32_0-32_0-32",
              "precomputed-jpeg/info", "precomputed-jpeg/2/0-32_0-32_0-8")


@pytest.mark.parametrize("path", ARRAY_URLS)
def test_head_range_and_if_none_match_on_every_array_endpoint(volume, path):
    srv, vid, _ = volume
    url = f"{srv.url}/v1/volumes/{vid}/{path}"
    full = requests.get(url, timeout=120)
    assert full.status_code == 200, full.text
    body, n, etag = full.content, len(full.content), full.headers["ETag"]
    assert full.headers["Accept-Ranges"] == "bytes"
    exposed = {h.strip() for h in full.headers["Access-Control-Expose-Headers"].split(",")}
    assert {"ETag", "Content-Length", "Content-Range", "Accept-Ranges"} <= exposed
    head = requests.head(url, timeout=120)
    assert head.status_code == 200 and head.content == b""
    for h in ("ETag", "Content-Type", "Cache-Control", "Accept-Ranges", "Access-Control-Allow-Origin"):
        assert head.headers[h] == full.headers[h], h
    assert int(head.headers["Content-Length"]) == n
    for spec, (a, b) in ((f"bytes=3-9", (3, 9)), ("bytes=-5", (n - 5, n - 1)), (f"bytes={n - 3}-", (n - 3, n - 1)),
                         (f"bytes=0-{n + 100}", (0, n - 1))):
        r = requests.get(url, headers={"Range": spec}, timeout=120)
        assert r.status_code == 206, (spec, r.status_code)
        assert r.content == body[a:b + 1], spec
        assert r.headers["Content-Range"] == f"bytes {a}-{b}/{n}", spec
        assert r.headers["ETag"] == etag
    r = requests.get(url, headers={"Range": f"bytes={n}-"}, timeout=120)
    assert r.status_code == 416 and r.headers["Content-Range"] == f"bytes */{n}"
    assert r.headers["Access-Control-Allow-Origin"] == "*"
    h416 = requests.head(url, headers={"Range": f"bytes={n}-"}, timeout=120)
    assert h416.status_code == 416 and h416.content == b""
    for ignored in ("bytes=0-1,4-5", "bytes=x-y", "bytes=9-3", "lines=0-1"):
        r = requests.get(url, headers={"Range": ignored}, timeout=120)
        assert r.status_code == 200 and r.content == body, ignored
    # If-Range naming another representation: the whole body
    r = requests.get(url, headers={"Range": "bytes=0-0", "If-Range": '"stale"'}, timeout=120)
    assert r.status_code == 200 and r.content == body
    for inm in (etag, f'"other", W/{etag}', "*"):
        r = requests.get(url, headers={"If-None-Match": inm}, timeout=120)
        assert r.status_code == 304 and r.content == b"", inm
        assert r.headers["ETag"] == etag and r.headers["Access-Control-Allow-Origin"] == "*"
    assert requests.get(url, headers={"If-None-Match": '"other"'}, timeout=120).status_code == 200


METADATA_URLS = ("zarr/zarr.json", "zarr/0/zarr.json", "zarr/1/zarr.json", "zarr2/.zgroup", "zarr2/.zattrs",
                 "zarr2/0/.zarray", "zarr2/1/.zarray", "precomputed/info", "precomputed-jpeg/info")


def metadata_etags(url, vid):
    return {p: requests.get(f"{url}/v1/volumes/{vid}/{p}", timeout=60).headers["ETag"] for p in METADATA_URLS}


def test_every_metadata_document_has_its_own_etag(volume):
    srv, vid, _ = volume
    first = metadata_etags(srv.url, vid)
    assert len(set(first.values())) == len(METADATA_URLS), first  # e.g. zarr/0 and zarr/1 differ
    assert metadata_etags(srv.url, vid) == first
    # a volume of the same spec: the same chunk ETags (content tag), but its own group documents
    # (they name the volume), so its own metadata ETags
    spec = srv.client.get_volume(vid)
    twin = srv.client.create_volume(exemplar=spec["exemplars"][0], seed=spec["seed"])["id"]
    assert twin != vid
    chunk = "zarr/0/c/0/0/0/0"
    assert (requests.head(f"{srv.url}/v1/volumes/{twin}/{chunk}", timeout=120).headers["ETag"]
            == requests.head(f"{srv.url}/v1/volumes/{vid}/{chunk}", timeout=120).headers["ETag"])
    others = metadata_etags(srv.url, twin)
    assert not set(others.values()) & set(first.values()), others


def test_head_outside_the_array_is_404_without_a_body(volume):
    srv, vid, _ = volume
    r = requests.head(f"{srv.url}/v1/volumes/{vid}/zarr/0/c/0/9/0/0", timeout=60)
    assert r.status_code == 404 and r.content == b"" and int(r.headers["Content-Length"]) > 0
    assert r.headers["Access-Control-Allow-Origin"] == "*"
    r = requests.get(f"{srv.url}/v1/volumes/{vid}/zarr/0/c/0/9/0/0", headers={"Range": "bytes=0-3"}, timeout=60)
    assert r.status_code == 404  # errors are never ranged


def test_zarr2_mirror_reads_the_same_voxels(volume):
    srv, vid, _ = volume
    group = zarr.open_group(f"{srv.url}/v1/volumes/{vid}/zarr2", mode="r", zarr_format=2)
    (ms,) = group.attrs["multiscales"]
    assert ms["version"] == "0.4"
    finest = group["0"]
    assert finest.shape == (3, EXTENT, EXTENT, EXTENT)
    assert np.array_equal(finest[:, 5:40, 60:64, 0:33], region_czyx(srv, vid, (5, 60, 0), (40, 64, 33)))
    v3 = zarr.open_group(f"{srv.url}/v1/volumes/{vid}/zarr", mode="r", zarr_format=3)
    assert np.array_equal(group["2"][:], v3["2"][:])


def test_chunks_are_immutable_cors_and_404_only_outside_the_array(volume, binary):
    srv, vid, factory = volume
    base = f"{srv.url}/v1/volumes/{vid}"
    first = requests.get(f"{base}/zarr/0/c/0/3/2/1", timeout=120)  # never computed before: 200, not 404
    assert first.status_code == 200, first.text
    assert first.headers["Cache-Control"] == "public, max-age=31536000, immutable"
    assert first.headers["Access-Control-Allow-Origin"] == "*"
    assert "ETag" in first.headers["Access-Control-Expose-Headers"]
    etag = first.headers["ETag"]
    assert etag.startswith('"') and etag.endswith('"')
    again = requests.get(f"{base}/zarr/0/c/0/3/2/1", timeout=120)
    assert again.content == first.content and again.headers["ETag"] == etag
    assert again.headers["X-Voxels-Synthesized"] == "0"
    other = requests.get(f"{base}/zarr/0/c/0/3/2/0", timeout=120)
    assert other.headers["ETag"] != etag
    v2 = requests.get(f"{base}/zarr2/0/0/3/2/1", timeout=120)
    assert v2.status_code == 200 and v2.headers["ETag"] != etag
    for outside in ("zarr/0/c/0/4/0/0", "zarr/0/c/0/0/0/-1", "zarr/0/c/1/0/0/0", "zarr/3/c/0/0/0/0",
                    "zarr/0/c/0/0/0/x", "zarr/9/zarr.json", "zarr2/0/0/0/0/4", "zarr2/3/.zarray"):
        r = requests.get(f"{base}/{outside}", timeout=60)
        assert r.status_code == 404, (outside, r.status_code, r.text)
        assert r.headers.get("Access-Control-Allow-Origin") == "*", outside
    assert requests.get(f"{srv.url}/v1/volumes/vol_missing/zarr/zarr.json", timeout=60).status_code == 404
    assert requests.get(f"{base}/zarr/zarr.json", params={"x": 1}, timeout=60).status_code == 400
    metadata = metadata_etags(srv.url, vid)
    # the same chunk, the same bytes and ETag after a restart; the same metadata ETags
    data_dir = srv.data_dir
    assert srv.stop(grace=10) == 0
    restarted = factory.start("--array-extent", EXTENT, data_dir=data_dir)
    r = requests.get(f"{restarted.url}/v1/volumes/{vid}/zarr/0/c/0/3/2/1", timeout=120)
    assert r.status_code == 200 and r.content == first.content and r.headers["ETag"] == etag
    assert metadata_etags(restarted.url, vid) == metadata


@pytest.mark.parametrize("flag,value", [("--array-extent", v) for v in ("33", "16", "0", str((1 << 20) + 32), "x")]
                         + [("--chunk-cache-mb", v) for v in ("-1", "65537", "1.5")])
def test_array_flags_outside_their_range_stop_the_server_naming_the_flag(binary, flag, value, tmp_path):
    import subprocess
    proc = subprocess.run([str(binary), "serve", "--port", "1", "--data", str(tmp_path / "d"), flag, value],
                          capture_output=True, text=True, timeout=30)
    assert proc.returncode == 2, proc
    assert flag in proc.stderr, proc.stderr


def test_chunk_cache_at_its_ends_serves_the_same_bytes(server, exemplars):
    # 0 keeps no encoded chunk (every read goes through the voxel cache), 65536 MiB keeps them all
    got = {}
    for mb in (0, 65536):
        srv = server("--chunk-cache-mb", mb, "--array-extent", 64)
        ex = upload_ready(srv.client, exemplars["spots"])
        vid = srv.client.create_volume(exemplar=ex["id"], seed=2)["id"]
        url = f"{srv.url}/v1/volumes/{vid}/zarr/0/c/0/1/0/1"
        first, again = requests.get(url, timeout=120), requests.get(url, timeout=120)
        assert first.status_code == again.status_code == 200
        assert first.content == again.content and first.headers["ETag"] == again.headers["ETag"]
        assert again.headers["X-Voxels-Synthesized"] == "0"  # from the voxel cache or the chunk cache
        got[mb] = first.content
        srv.stop(grace=10)
    assert got[0] == got[65536]


def test_array_extent_at_its_ends_shapes_the_arrays(server, exemplars):
    # the documented ends of --array-extent: one chunk a side, and 2^20 voxels (32768 chunks)
    for extent in (32, 1 << 20):
        srv = server("--array-extent", extent)
        ex = upload_ready(srv.client, exemplars["spots"])
        vid = srv.client.create_volume(exemplar=ex["id"], seed=1)["id"]
        meta = requests.get(f"{srv.url}/v1/volumes/{vid}/zarr/0/zarr.json", timeout=60).json()
        assert meta["shape"] == [3, extent, extent, extent]
        last = extent // 32 - 1
        r = requests.get(f"{srv.url}/v1/volumes/{vid}/zarr/0/c/0/{last}/{last}/{last}", timeout=120)
        assert r.status_code == 200, r.text
        assert requests.get(f"{srv.url}/v1/volumes/{vid}/zarr/0/c/0/{last + 1}/0/0", timeout=60).status_code == 404
        srv.stop(grace=10)
