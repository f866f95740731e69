"""Colored-PLY parsing, the software renderer and the mesh client methods, without a server."""
import json
import time
from urllib.parse import parse_qs, urlsplit

import numpy as np
import pytest
from PIL import Image

from support import FakeSession, fake_response  # (support also puts <repo>/client on sys.path)
from solidtex_client import Client, ColoredMesh, PlyFormatError, parse_colored_ply
from solidtex_client import cli as cli_module
from solidtex_client.render import camera_basis, render

# A unit square in the plane z = 0 (two triangles), seen face-on from +z at azimuth 0.
SQUARE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]], np.int32)


def square(colors, z=0.0, offset=0):
    v = SQUARE_V.copy()
    v[:, 2] = z
    return v, np.asarray(colors, np.uint8).reshape(-1, 3), SQUARE_F + offset


def merge(*parts):
    vs, cs, fs = zip(*parts)
    return ColoredMesh(np.concatenate(vs), np.concatenate(cs), np.concatenate(fs))


def ply_header(n, m, vertex_props=None, face_prop="property list uchar int vertex_indices",
               fmt="binary_little_endian 1.0", extra=""):
    props = vertex_props or ["float x", "float y", "float z", "uchar red", "uchar green",
                             "uchar blue"]
    lines = ["ply", f"format {fmt}", "comment made by a test", f"element vertex {n}"]
    lines += [f"property {p}" for p in props]
    lines += [f"element face {m}", face_prop]
    return ("\n".join(lines) + "\n" + extra + "end_header\n").encode()


# -- parse_colored_ply ---------------------------------------------------------------------


def test_colored_ply_round_trip_and_layout():
    mesh = merge(square([[1, 2, 3], [4, 5, 6], [7, 8, 9], [250, 251, 252]]))
    data = mesh.to_ply()
    head = data[:data.index(b"end_header\n") + 11].decode()
    assert "format binary_little_endian 1.0" in head
    assert "element vertex 4" in head and "element face 2" in head
    assert len(data) - len(head) == 4 * 15 + 2 * 13
    back = parse_colored_ply(data)
    assert back.vertices.dtype == np.float32 and back.vertices.shape == (4, 3)
    assert back.colors.dtype == np.uint8 and back.colors.shape == (4, 3)
    assert back.faces.dtype == np.int32 and back.faces.shape == (2, 3)
    assert np.array_equal(back.vertices, mesh.vertices)
    assert np.array_equal(back.colors, mesh.colors)
    assert np.array_equal(back.faces, mesh.faces)


def test_colored_ply_hand_built_bytes():
    # written field by field (not by to_ply), with a comment and obj_info line
    body = b"".join(np.array([x, y, z], "<f4").tobytes() + bytes([r, g, b])
                    for (x, y, z), (r, g, b) in [((0.5, -1, 2), (10, 20, 30)),
                                                 ((1, 2, 3), (40, 50, 60)),
                                                 ((-4, 5, 6.25), (70, 80, 255))])
    body += bytes([3]) + np.array([2, 0, 1], "<i4").tobytes()
    data = ply_header(3, 1, extra="obj_info hello\n") + body
    m = parse_colored_ply(data)
    assert m.vertices.tolist() == [[0.5, -1, 2], [1, 2, 3], [-4, 5, 6.25]]
    assert m.colors.tolist() == [[10, 20, 30], [40, 50, 60], [70, 80, 255]]
    assert m.faces.tolist() == [[2, 0, 1]]
    # an empty mesh is a valid answer too
    empty = parse_colored_ply(ply_header(0, 0))
    assert empty.vertices.shape == (0, 3) and empty.faces.shape == (0, 3)


def _vertex_bytes(n):
    return b"".join(np.zeros(3, "<f4").tobytes() + bytes(3) for _ in range(n))


def _face_bytes(*faces, count=3):
    return b"".join(bytes([count]) + np.array(f, "<i4").tobytes() for f in faces)


@pytest.mark.parametrize("data,needle", [
    (b"", "magic"),
    (b"solid cube\nfacet normal 0 0 1\n", "magic"),
    (b"ply\nformat binary_little_endian 1.0\nelement vertex 0\n", "end_header"),
    (ply_header(3, 1, fmt="ascii 1.0") + b"0 0 0 0 0 0\n" * 3 + b"3 0 1 2\n", "binary_little_endian"),
    (ply_header(3, 1, fmt="binary_big_endian 1.0") + _vertex_bytes(3) + _face_bytes([0, 1, 2]),
     "binary_little_endian"),
    (ply_header(3, 1, vertex_props=["float x", "float y", "float z", "uchar red", "uchar green"])
     + _vertex_bytes(3) + _face_bytes([0, 1, 2]), "blue"),
    (ply_header(3, 1, vertex_props=["float x", "float y", "float z", "float nx", "uchar red",
                                    "uchar green", "uchar blue"])
     + _vertex_bytes(3) + _face_bytes([0, 1, 2]), "nx"),
    (ply_header(3, 1, vertex_props=["double x", "float y", "float z", "uchar red", "uchar green",
                                    "uchar blue"])
     + _vertex_bytes(3) + _face_bytes([0, 1, 2]), "type double"),
    (ply_header(3, 1, face_prop="property list int int vertex_indices")
     + _vertex_bytes(3) + _face_bytes([0, 1, 2]), "list uchar int"),
    (ply_header(4, 1) + _vertex_bytes(4) + bytes([4]) + np.array([0, 1, 2, 3], "<i4").tobytes(),
     "body has"),
    (ply_header(3, 1) + _vertex_bytes(3) + _face_bytes([0, 1, 2], count=4), "only triangles"),
    (ply_header(3, 1) + _vertex_bytes(3) + _face_bytes([0, 1, 3]), "out of range"),
    (ply_header(3, 1) + _vertex_bytes(3) + _face_bytes([0, -1, 2]), "out of range"),
    (ply_header(3, 2) + _vertex_bytes(3) + _face_bytes([0, 1, 2]), "body has"),
    (ply_header(3, 1) + _vertex_bytes(3) + _face_bytes([0, 1, 2]) + b"\0", "body has"),
    (ply_header(3, 1, extra="element edge 0\n") + _vertex_bytes(3) + _face_bytes([0, 1, 2]),
     "elements"),
])
def test_colored_ply_rejects_other_layouts(data, needle):
    with pytest.raises(PlyFormatError) as info:
        parse_colored_ply(data)
    assert isinstance(info.value, ValueError)
    assert needle in str(info.value), str(info.value)


# -- render --------------------------------------------------------------------------------


def test_render_uniform_square_centre_and_border():
    mesh = merge(square([[10, 200, 30]] * 4))
    img = render(mesh, azimuth=0, elevation=0, size=(21, 15), light=False)
    assert img.shape == (15, 21, 3) and img.dtype == np.uint8
    assert img[7, 10].tolist() == [10, 200, 30]
    # the square fills the height but not the width; its border pixels stay white
    assert img[0].tolist() == [[255, 255, 255]] * 21
    assert img[:, 0].tolist() == [[255, 255, 255]] * 15
    obj = (img != 255).any(-1)
    assert obj[1:-1, 4:-4].all()           # 13 x 13 pixels inside the square
    assert not obj[:, :3].any() and not obj[:, -3:].any()


def test_render_interpolates_colors():
    # red on the left (x = 0), blue on the right (x = 1)
    mesh = merge(square([[255, 0, 0], [0, 0, 255], [0, 0, 255], [255, 0, 0]]))
    img = render(mesh, azimuth=0, elevation=0, size=(41, 41), light=False).astype(int)
    centre = img[20, 20]
    assert np.all(np.abs(centre - [128, 0, 128]) <= 1), centre
    row = img[20, 3:-3]
    assert np.all(np.diff(row[:, 0]) <= 0) and np.all(np.diff(row[:, 2]) >= 0)
    assert row[0, 0] > 230 and row[-1, 2] > 230


def test_render_depth_test_and_view_direction():
    red = square([[255, 0, 0]] * 4, z=0.5)          # nearer to a camera on +z
    blue = square([[0, 0, 255]] * 4, z=-0.5, offset=4)
    for parts in ((red, blue), (blue, red)):       # drawing order does not matter
        mesh = merge(*parts)
        assert render(mesh, 0, 0, (31, 31), light=False)[15, 15].tolist() == [255, 0, 0]
        assert render(mesh, 180, 0, (31, 31), light=False)[15, 15].tolist() == [0, 0, 255]
    # from above (elevation 90), a square in the plane y = 0 is seen face-on
    flat = ColoredMesh(SQUARE_V[:, [0, 2, 1]], np.full((4, 3), 90, np.uint8), SQUARE_F)
    top = render(flat, 0, 90, (20, 20), light=False)
    assert (top[2:-2, 2:-2] == 90).all()


def test_camera_basis_is_orthonormal_and_right_handed():
    for az, el, up in [(0, 0, "y"), (30, 20, "y"), (-120, 60, "y"), (0, 90, "y"), (45, -30, "z")]:
        r, u, c = camera_basis(az, el, up)
        m = np.stack([r, u, c])
        assert np.allclose(m @ m.T, np.eye(3), atol=1e-12)
        assert np.allclose(np.cross(r, u), c, atol=1e-12)
    r, u, c = camera_basis(0, 0, "y")
    assert np.allclose([r, u, c], np.eye(3))


def test_render_lambert_shading():
    mesh = merge(square([[200, 100, 50]] * 4))
    flat = render(mesh, 0, 0, (21, 21), light=False)[10, 10].astype(float)
    lit = render(mesh, 0, 0, (21, 21), light=True)[10, 10].astype(float)
    shade = lit / flat
    assert np.all(shade <= 1.0 + 1e-9) and np.all(shade >= 0.35 - 0.01), shade
    assert np.ptp(shade) < 0.02, shade            # one factor for all channels
    # a face seen more obliquely is darker (|n . l| smaller)
    oblique = render(mesh, 70, 0, (21, 21), light=True)
    obj = (oblique != 255).any(-1)
    assert obj.any()
    assert oblique[obj].astype(float).mean(0)[0] < lit[0] - 20


def sphere(n_around=360, n_down=140):
    th = np.linspace(0, np.pi, n_down + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_around, endpoint=False)
    t, p = np.meshgrid(th, ph, indexing="ij")
    ring = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], -1).reshape(-1, 3)
    v = np.concatenate([[[0, 1, 0]], ring, [[0, -1, 0]]])
    idx = 1 + np.arange(len(ring)).reshape(len(th), n_around)
    a, b = idx[:-1], np.roll(idx[:-1], -1, 1)
    c, d = idx[1:], np.roll(idx[1:], -1, 1)
    caps = [np.stack([np.zeros(n_around, int), idx[0], np.roll(idx[0], -1)], -1),
            np.stack([np.full(n_around, len(v) - 1), np.roll(idx[-1], -1), idx[-1]], -1)]
    f = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3),
                        np.stack([b, c, d], -1).reshape(-1, 3)] + caps)
    colors = np.rint((v * 0.5 + 0.5) * 255).astype(np.uint8)
    return ColoredMesh(v, colors, f)


def test_render_100k_triangles_fast_and_without_holes():
    mesh = sphere()
    assert len(mesh.faces) > 100_000
    size = 128
    t0 = time.monotonic()
    img = render(mesh, azimuth=30, elevation=20, size=(size, size))
    seconds = time.monotonic() - t0
    print(f"rendered {len(mesh.faces)} triangles at {size}x{size} in {seconds:.2f} s")
    assert seconds < 5.0
    obj = (img != 255).any(-1)
    # the sphere's silhouette is a disc centred in the image, radius 64 - 6.4 pixels
    yy, xx = np.mgrid[0:size, 0:size] + 0.5
    r = np.hypot(xx - size / 2, yy - size / 2)
    radius = size / 2 - 0.05 * size
    assert obj[r < radius - 1.0].all(), "holes inside the silhouette"
    assert not obj[r > radius + 1.0].any(), "pixels outside the silhouette"
    assert len(np.unique(img[obj], axis=0)) > 500


# -- client methods ------------------------------------------------------------------------


PLY_HEADERS = {"Content-Type": "application/x-ply", "X-Target-Voxels": "3",
               "X-Bounding-Voxels": "64", "X-Voxels-Synthesized": "40"}


def test_mesh_methods_build_requests(tmp_path):
    path = tmp_path / "tri.off"
    path.write_bytes(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    s = FakeSession([fake_response(201, {"id": "m1"}), fake_response(201, {"id": "m2"}),
                     fake_response(200, {"meshes": [{"id": "m1"}]}),
                     fake_response(200, {"id": "m1"}), fake_response(204),
                     fake_response(200, b"ply\n..."),
                     fake_response(201, {"id": "f1", "revision": 1})])
    c = Client("http://svc:1", session=s)
    assert c.upload_mesh(path)["id"] == "m1"
    req = s.sent[0]
    assert urlsplit(req.url).path == "/v1/meshes"
    assert parse_qs(urlsplit(req.url).query) == {"name": ["tri.off"]}
    assert req.headers["Content-Type"] == "application/octet-stream"
    assert req.body == path.read_bytes()
    c.upload_mesh(b"OFF\n...", name="a b")
    assert urlsplit(s.sent[1].url).query == "name=a%20b"
    assert c.list_meshes() == [{"id": "m1"}]
    assert c.get_mesh("m1") == {"id": "m1"}
    assert c.delete_mesh("m1") is None and s.sent[4].method == "DELETE"
    assert c.get_mesh_file("m1") == b"ply\n..."
    assert urlsplit(s.sent[5].url).path == "/v1/meshes/m1/file"
    fld = c.field_from_mesh("m1", "features", placement={"resolution": 40},
                            shortest_side_cells=8, curves=[np.zeros((2, 3))], timeout=5)
    assert fld["id"] == "f1"
    req = s.sent[6]
    assert urlsplit(req.url).path == "/v1/fields/from-mesh"
    assert parse_qs(urlsplit(req.url).query) == {"timeout": ["5"]}
    assert json.loads(req.body) == {"mesh": "m1", "kind": "features",
                                    "placement": {"resolution": 40}, "shortest_side_cells": 8,
                                    "curves": [[[0, 0, 0], [0, 0, 0]]]}


def test_surface_requests_and_answers():
    colored = merge(square([[1, 2, 3], [4, 5, 6], [7, 8, 9], [10, 11, 12]]))
    colors = [[0.1, 0.2, 0.30000001192092896], [1e-8, 0.5, 1.0], [0, 0, 0], [0.25, 0.75, 0.125]]
    s = FakeSession([
        fake_response(200, colored.to_ply(), PLY_HEADERS),
        fake_response(200, {"vertices": 4, "colors": colors, "point_colors": [[0.5, 0.5, 0.5]],
                            "placement": {"scale": 2.0, "translate": [1, 2, 3]},
                            "stats": {"target_voxels": 3}}, {"Content-Type": "application/json"}),
        fake_response(200, colored.to_ply(), PLY_HEADERS),
    ])
    c = Client("http://svc:1", session=s)
    m = c.surface("v1", mesh_id="m1", placement={"scale": 2.0, "translate": [1, 2, 3]})
    assert isinstance(m, ColoredMesh)
    assert np.array_equal(m.colors, colored.colors) and np.array_equal(m.faces, colored.faces)
    assert m.header_int("x-target-voxels") == 3 and m.header_int("X-Voxels-Synthesized") == 40
    req = s.sent[0]
    assert urlsplit(req.url).path == "/v1/volumes/v1/surface"
    assert req.headers["Content-Type"] == "application/json"
    assert req.headers["Accept"] == "application/x-ply"
    assert json.loads(req.body) == {"mesh": "m1", "format": "ply",
                                    "placement": {"scale": 2.0, "translate": [1, 2, 3]}}

    out = c.surface("v1", mesh_id="m1", fmt="json", points=[[0.5, 0.5, 0]], timeout=9)
    assert out["colors"].dtype == np.float32 and out["colors"].shape == (4, 3)
    assert np.array_equal(out["colors"], np.array(colors, np.float32))
    assert out["point_colors"].shape == (1, 3)
    assert out["placement"]["scale"] == 2.0
    req = s.sent[1]
    assert json.loads(req.body) == {"mesh": "m1", "format": "json", "points": [[0.5, 0.5, 0]]}
    assert parse_qs(urlsplit(req.url).query) == {"timeout": ["9"]}

    c.surface("v2", mesh=b"OFF\nraw", placement={"resolution": 40, "margin": 0.1})
    req = s.sent[2]
    assert req.body == b"OFF\nraw"
    assert req.headers["Content-Type"] == "application/octet-stream"
    assert parse_qs(urlsplit(req.url).query) == {"resolution": ["40"], "margin": ["0.1"],
                                                 "format": ["ply"]}
    with pytest.raises(ValueError):
        c.surface("v", mesh=b"x", placement={"scale": 1, "translate": [0, 0, 0]})
    with pytest.raises(ValueError):
        c.surface("v", mesh_id="m", mesh=b"x")
    with pytest.raises(ValueError):
        c.surface("v")
    with pytest.raises(ValueError):
        c.surface("v", mesh_id="m", fmt="obj")
    assert len(s.sent) == 3


def test_cli_render_offline(tmp_path, monkeypatch, capsys):
    colored = merge(square([[200, 40, 40], [200, 40, 40], [40, 40, 200], [40, 40, 200]]))
    session = FakeSession([fake_response(200, colored.to_ply(), PLY_HEADERS)])
    monkeypatch.setattr(cli_module, "Client",
                        lambda url, timeout: Client(url, timeout=timeout, session=session))
    mesh_path = tmp_path / "sq.obj"
    mesh_path.write_bytes(b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    out, ply = tmp_path / "view.png", tmp_path / "c.ply"
    rc = cli_module.main(["--url", "http://svc:1", "render", str(mesh_path), "--volume", "v9",
                          "-o", str(out), "--size", "41,31", "--resolution", "64",
                          "--azimuth", "0", "--elevation", "0", "--no-light", "--ply", str(ply)])
    assert rc == 0, capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out)
    assert summary["vertices"] == 4 and summary["triangles"] == 2
    assert summary["voxels_synthesized"] == 40
    req = session.sent[0]
    assert urlsplit(req.url).path == "/v1/volumes/v9/surface"
    assert parse_qs(urlsplit(req.url).query) == {"resolution": ["64"], "format": ["ply"]}
    assert req.body == mesh_path.read_bytes()
    img = Image.open(out)
    assert img.format == "PNG" and img.size == (41, 31)
    px = np.asarray(img.convert("RGB"))
    assert np.all(np.abs(px[15, 20].astype(int) - [120, 40, 120]) <= 1), px[15, 20]
    assert np.array_equal(parse_colored_ply(ply.read_bytes()).colors, colored.colors)
