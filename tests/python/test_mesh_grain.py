"""Grain follows a curvature-derived field: on a cylinder, principal-curvature frames put the
grain (frame x) along the axis, so a striped exemplar's stripes run along the axis: colors
change slowly along it and quickly around it. With the identity field (grain along world x,
across the z-axis cylinder) the same measure is clearly worse."""
import numpy as np
import requests

from support import ANALYSIS

AROUND, ALONG = 64, 40


def cylinder_obj(radius=20.0, height=60.0):
    lines = []
    for j in range(ALONG + 1):
        for i in range(AROUND):
            a = 2 * np.pi * i / AROUND
            lines.append(f"v {radius * np.cos(a):.6f} {radius * np.sin(a):.6f} {height * j / ALONG:.6f}")
    for j in range(ALONG):
        for i in range(AROUND):
            a = 1 + j * AROUND + i
            b = 1 + j * AROUND + (i + 1) % AROUND
            lines.append(f"f {a} {b} {b + AROUND} {a + AROUND}")
    return ("\n".join(lines) + "\n").encode()


def along_over_around(colors):
    lum = colors.reshape(ALONG + 1, AROUND, 3).mean(axis=2)
    inner = lum[4:-4]  # away from the open ends
    along = np.abs(np.diff(inner, axis=0)).mean()
    around = np.abs(np.diff(inner, axis=1)).mean()
    return along / around


def test_curvature_field_turns_the_grain_along_a_cylinder(server, exemplars):
    srv = server()
    c = srv.client
    ex = c.upload_exemplar(exemplars["stripes"], grain="x", **ANALYSIS)
    c.wait_for_job(ex["job"]["id"], timeout=300)
    mesh = c.upload_mesh(cylinder_obj(), name="cylinder")["id"]
    placement = {"resolution": 96}
    r = requests.post(srv.url + "/v1/fields/from-mesh", timeout=300,
                      json={"mesh": mesh, "kind": "curvature", "placement": placement, "shortest_side_cells": 8})
    assert r.status_code == 201, r.text
    field = r.json()["id"]

    def colors(field_spec):
        spec = {"exemplar": ex["exemplar"]["id"], "seed": 5}
        if field_spec:
            spec["field"] = field_spec
        vol = requests.post(srv.url + "/v1/volumes", json=spec, timeout=60).json()["id"]
        r = requests.post(f"{srv.url}/v1/volumes/{vol}/surface", params={"timeout": 300}, timeout=600,
                          json={"mesh": mesh, "placement": placement, "format": "json"})
        assert r.status_code == 200, r.text
        return np.asarray(r.json()["colors"], dtype=np.float64)

    with_field = along_over_around(colors({"id": field}))
    identity = along_over_around(colors(None))
    print(f"along/around color change: curvature field {with_field:.3f}, identity {identity:.3f}")
    assert with_field < 0.6, with_field
    assert with_field < 0.7 * identity, (with_field, identity)
