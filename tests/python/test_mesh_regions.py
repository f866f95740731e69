"""Per-region exemplars by distance to a mesh surface: bark near the surface, wood inside
(Zhang Fig. 15). Each region is exactly its own texture, so the two sides can be checked
against single-exemplar volumes bit for bit."""
import numpy as np
import requests

from support import RAW_F32, shared_mesh, upload_ready


def test_surface_shell_takes_the_second_texture_near_the_surface(server, exemplars):
    bunny = shared_mesh("bunny.off")
    srv = server()
    c = srv.client
    wood = upload_ready(c, exemplars["wood"])["id"]
    spots = upload_ready(c, exemplars["spots"])["id"]
    mesh = c.upload_mesh(bunny)["id"]
    placement = {"resolution": 48}
    spec = {"regions": {"exemplars": [wood, spots], "label": "surface:2",
                        "mesh": {"id": mesh, "placement": placement}}, "seed": 3}
    r = requests.post(srv.url + "/v1/volumes", json=spec, timeout=120)
    assert r.status_code == 201, r.text
    shell = r.json()["id"]
    only_wood = c.create_volume(exemplar=wood, seed=3)["id"]
    only_spots = c.create_volume(exemplar=spots, seed=3)["id"]

    # Every vertex lies on the surface, so inside the shell: the spots texture.
    def colors(vol):
        r = requests.post(f"{srv.url}/v1/volumes/{vol}/surface",
                          json={"mesh": mesh, "placement": placement, "format": "json"}, timeout=300)
        assert r.status_code == 200, r.text
        return np.asarray(r.json()["colors"], dtype=np.float32)

    assert np.array_equal(colors(shell), colors(only_spots))
    assert not np.array_equal(colors(shell), colors(only_wood))

    # A z-slice through the middle has both: far from the surface the wood texture, bit for bit.
    def cut(vol):
        r = requests.get(f"{srv.url}/v1/volumes/{vol}/slice",
                         params={"axis": "z", "at": 24, "size": "48,48", "timeout": 300}, headers=RAW_F32, timeout=300)
        assert r.status_code == 200, r.text
        return np.frombuffer(r.content, dtype="<f4").reshape(48, 48, 3)

    s, w, p = cut(shell), cut(only_wood), cut(only_spots)
    from_wood = np.all(s == w, axis=2)
    from_spots = np.all(s == p, axis=2)
    assert np.all(from_wood | from_spots), "a voxel matches neither region's texture"
    assert from_wood.sum() > 100 and from_spots.sum() > 100, (from_wood.sum(), from_spots.sum())
    assert from_wood[0, 0] and from_wood[-1, -1], "the corners are far from the bunny: wood"

    # Bad specs: a surface label without a mesh, an unknown mesh.
    bad = {"regions": {"exemplars": [wood, spots], "label": "surface:2"}}
    r = requests.post(srv.url + "/v1/volumes", json=bad, timeout=60)
    assert r.status_code == 400 and r.json()["error"]["field"] == "regions.mesh", r.text
    bad = {"regions": {"exemplars": [wood, spots], "label": "surface:2", "mesh": {"id": "mesh_0000000000000000"}}}
    r = requests.post(srv.url + "/v1/volumes", json=bad, timeout=60)
    assert r.status_code == 404, r.text

    # It survives a restart (the volume keeps its own copy of the mesh).
    c.delete_mesh(mesh)
    srv.kill()
    srv2 = server(data_dir=srv.data_dir)
    r = requests.get(f"{srv2.url}/v1/volumes/{shell}/slice",
                     params={"axis": "z", "at": 24, "size": "48,48", "timeout": 300}, headers=RAW_F32, timeout=300)
    assert r.status_code == 200, r.text
    assert np.array_equal(np.frombuffer(r.content, dtype="<f4").reshape(48, 48, 3), s)


def test_meshes_survive_kill_9(server):
    off = b"OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
    srv = server()
    m = srv.client.upload_mesh(off, name="tet")
    srv.kill()
    srv2 = server(data_dir=srv.data_dir)
    assert srv2.client.get_mesh(m["id"]) == m
    assert [x["id"] for x in srv2.client.list_meshes()] == [m["id"]]
    ply = srv2.client.get_mesh_file(m["id"])
    assert ply.startswith(b"ply\nformat binary_little_endian 1.0\n")
