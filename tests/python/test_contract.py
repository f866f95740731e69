"""schemathesis over the whole contract (issue 11): every operation of the served
/v1/openapi.json is fuzzed (examples, coverage, fuzzing and stateful phases, links followed)
with every check schemathesis has, against a server that holds a ready exemplar, a volume, a
field and a mesh. The run must end with no server error (5xx other than 503/504), no schema
violation and no other failed check.

Kept fast for 2 cores: small analysis parameters, tiny per-request budgets (--max-voxels and
friends, so that the largest valid request is cheap), a short --deadline and --max-deadline (the
served document then says timeout <= 8, so no request may run longer), a bounded number of
examples per operation and a bounded run time. Path ids and body ids are the fixtures' most of
the time (schemathesis dictionaries), generated otherwise; OpenAPI links carry new ids on. SOLIDTEX_CONTRACT_EXAMPLES and
SOLIDTEX_CONTRACT_SECONDS raise them for a longer hunt; SOLIDTEX_CONTRACT_SEED replays a run.

What the configuration allows, and why:
- positive_data_acceptance also accepts 400/415/422 where the contract documents a refusal
  that JSON Schema cannot state (image and mesh bytes, points in a binary body, cross-field
  rules of sketches, cuts, labels and field specs, the per-request budgets): listed per
  operation in POSITIVE_REFUSALS below.
- The fixtures are never deleted: a hook turns a DELETE of one of their ids into a DELETE of
  an unknown id (schemathesis feeds ids seen in answers into every operation), so that the
  whole run has a ready exemplar, a volume, a field and a mesh to work on.
- QUERY is not among the unexpected methods probed: http_parser (under RESTinio) does not know
  the method, so RESTinio closes the connection on the parse error before any handler runs.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

import support

schemathesis = pytest.importorskip("schemathesis", reason="schemathesis not installed: run scripts/setup-python.sh")

EXAMPLES = int(os.environ.get("SOLIDTEX_CONTRACT_EXAMPLES", "12"))
SECONDS = int(os.environ.get("SOLIDTEX_CONTRACT_SECONDS", "60"))
SEED = os.environ.get("SOLIDTEX_CONTRACT_SEED", "20261")

SERVER_FLAGS = ["--deadline", "5", "--max-deadline", "8", "--max-voxels", "4096", "--max-field-nodes", "32768",
                "--max-mesh-vertices", "4096", "--max-mesh-faces", "8192", "--max-upload-mb", "1",
                "--max-request-mb", "256", "--max-jobs", "2", "--threads", "2", "--queue", "64"]
TETRA = b"OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
SKETCH = {"domain": {"min": [0, 0, 0], "max": [16, 16, 16], "shortest_side_cells": 4},
          "curves": [{"points": [[2, 8, 8], [14, 8, 8]], "plane_normal": [0, 0, 1]}]}

# Statuses a schema-valid request may get besides 2xx/404/409/429 (documented refusals the
# schemas cannot express), per operation.
POSITIVE_REFUSALS = {
    "upload_exemplar": [415, 422, 400],  # image bytes: format, size >= 8, decodable; grain vs parts
    "upload_mesh": [415, 422],           # mesh bytes
    "surface": [400, 415, 422],          # mesh bytes, placed vertices within 2^28, budgets
    "points": [400, 422],                # binary body: multiple of 12 bytes, finite; budgets
    "cut": [400, 422],                   # far corner within 2^28; W*H <= --max-voxels
    "slice": [422],                      # W*H <= --max-voxels, working memory
    "region": [422],                     # W*H*D <= --max-voxels, working memory
    "sample_frames": [422],              # NX*NY*NZ <= 65536
    "create_field": [400, 422],          # sketch rules (points inside the domain, ...), grid size
    "add_curve": [400, 422],             # the curve inside the field's domain, ...
    "field_from_mesh": [400, 422],       # usable crest curves, user curves on the surface
    "create_volume": [400, 422],         # label and field spec values (non-zero, ranges)
}


HOOKS = """
import json, os
import schemathesis

PROTECTED = set(json.loads(os.environ["SOLIDTEX_CONTRACT_PROTECTED"]))


@schemathesis.hook
def before_call(context, case, kwargs):
    if case.method.upper() == "DELETE" and case.path_parameters and case.path_parameters.get("id") in PROTECTED:
        case.path_parameters["id"] = case.path_parameters["id"] + "-kept"
"""


def _toml(value) -> str:
    return json.dumps(value)  # TOML basic strings, arrays and inline tables of these are JSON-like


def config_text(ids: dict) -> str:
    lines = [
        f"seed = {SEED}",
        "workers = 1",
        "request-timeout = 60",
        "[generation]",
        f"max-examples = {EXAMPLES}",
        "[checks.not_a_server_error]",
        'expected-statuses = ["2xx", "3xx", "4xx", "503", "504"]',
        "[phases.coverage]",
        'unexpected-methods = ["get", "put", "post", "delete", "options", "patch", "trace"]',
        "[phases.stateful]",
        "max-steps = 6",
        "[phases.stateful.inference]",
        'algorithms = ["location-headers"]',
    ]
    for name in ("exemplar", "volume", "field", "mesh", "job"):
        lines += [f"[dictionaries.{name}]", f"values = {_toml([ids[name]])}"]
    # Real ids most of the time (the rest stay generated: unknown ids must be 404).
    bindings = {
        "exemplar": (["get_exemplar", "get_exemplar_table"], "path.id"),
        "job": (["get_job"], "path.id"),
        "volume": (["get_volume", "volume_stats", "slice", "cut", "region", "points", "surface"], "path.id"),
        "field": (["get_field", "get_field_file", "sample_frames", "add_curve"], "path.id"),
        "mesh": (["get_mesh", "get_mesh_file"], "path.id"),
    }
    params_by_op: dict = {}
    for dictionary, (ops, key) in bindings.items():
        for op in ops:
            params_by_op.setdefault(op, {})[key] = dictionary
    params_by_op.setdefault("create_volume", {})["body.exemplar"] = "exemplar"
    params_by_op.setdefault("surface", {})["body.mesh"] = "mesh"
    params_by_op.setdefault("field_from_mesh", {})["body.mesh"] = "mesh"
    for op in sorted(set(params_by_op) | set(POSITIVE_REFUSALS)):
        lines += ["[[operations]]", f"include-operation-id = {_toml(op)}"]
        if op in params_by_op:
            table = ", ".join(f'"{k}" = {{ dictionary = "{d}", probability = 0.8 }}'
                              for k, d in params_by_op[op].items())
            lines.append(f"parameters = {{ {table} }}")
        if op in POSITIVE_REFUSALS:
            statuses = ["2xx", "3xx", "404", "409", "429", "503", "504"] + [str(s) for s in POSITIVE_REFUSALS[op]]
            lines += ["[operations.checks.positive_data_acceptance]", f"expected-statuses = {_toml(statuses)}"]
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def fuzzed_server(binary, exemplars, tmp_path_factory):
    base = tmp_path_factory.mktemp("contract")
    factory = support.ServerFactory(base / "servers")
    try:
        srv = factory.start(*SERVER_FLAGS)
        c = srv.client
        small = base / "wood32.png"
        support.run_cli("exemplar", "wood", "-o", small, "--size", "32,32")
        ex = support.upload_ready(c, small, name="wood")
        vol = c.create_volume(exemplar=ex["id"], seed=3)
        field = support.requests.post(srv.url + "/v1/fields", json=SKETCH, timeout=60)
        assert field.status_code == 201, field.text
        mesh = support.post_bytes(srv.url + "/v1/meshes", TETRA)
        assert mesh.status_code == 201, mesh.text
        ids = {"exemplar": ex["id"], "job": ex["job_id"], "volume": vol["id"],
               "field": field.json()["id"], "mesh": mesh.json()["id"]}
        yield srv, ids, base
    finally:
        factory.close()


def test_schemathesis_finds_nothing(fuzzed_server):
    srv, ids, base = fuzzed_server
    config = base / "schemathesis.toml"
    config.write_text(config_text(ids))
    report = base / "report.json"
    cmd = [sys.executable, "-m", "schemathesis.cli", "--config-file", str(config), "--no-color",
           "run", srv.url + "/v1/openapi.json", "--checks", "all",
           # The hook turns a DELETE of a protected fixture into a DELETE of an unknown id (404); the
           # stateful phase draws fixture ids from its pool for DELETEs it links to its own POST and
           # reports that 404 as "created resource not found" (seen twice: POST /v1/volumes -> DELETE
           # of the fixture volume), so that one check cannot hold here.
           "--exclude-checks", "ensure_resource_availability", "--max-time", str(SECONDS),
           # Every answer within the --max-deadline (8 s) and some slack for 2 busy cores.
           "--max-response-time", "30",
           "--report", "json,junit", "--report-json-path", str(report), "--report-dir", str(base / "reports")]
    (base / "contract_hooks.py").write_text(HOOKS)
    env = {**os.environ, "SCHEMATHESIS_HOOKS": "contract_hooks",
           "PYTHONPATH": str(base) + os.pathsep + os.environ.get("PYTHONPATH", ""),
           "SOLIDTEX_CONTRACT_PROTECTED": json.dumps(sorted(ids.values()))}
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=SECONDS + 120, cwd=base, env=env)
    out = proc.stdout + proc.stderr
    (base / "schemathesis.log").write_text(out)
    assert srv.running, f"the server died under schemathesis:\n{srv.log()}\n{out[-6000:]}"
    summary = out[out.rfind("SUMMARY"):] if "SUMMARY" in out else out[-3000:]
    print(summary)
    assert proc.returncode == 0, f"schemathesis exit {proc.returncode}:\n{out[-20000:]}"
    assert "generated" in summary, summary


# Each finding of the schemathesis runs, pinned as a plain request (issue 11).

def test_region_sides_are_bounded_before_their_product(fuzzed_server):
    # Was 500 (std::bad_alloc): 2^22 * 2^22 * 2^20 wrapped int64 to 0 and passed the voxel limit.
    srv, ids, _ = fuzzed_server
    url = f"{srv.url}/v1/volumes/{ids['volume']}/region"
    for size in ("4194304,4194304,1048576", "16777216,16777216,16777216"):
        r = support.requests.get(url, params={"min": "0,0,0", "size": size}, timeout=30)
        support.assert_error(r, 422, "unprocessable", "size")
    r = support.requests.get(url, params={"min": "0,0,0", "size": "16777217,1,1"}, timeout=30)
    support.assert_error(r, 400, "invalid_argument", "size")


def test_any_positive_timeout_is_a_deadline(fuzzed_server):
    # Was 400 below 0.001 s, though the contract says (0, --max-deadline].
    srv, ids, _ = fuzzed_server
    r = support.requests.get(f"{srv.url}/v1/volumes/{ids['volume']}/slice",
                             params={"axis": "z", "at": "0", "size": "4,4", "timeout": "5e-324"}, timeout=30)
    assert r.status_code in (200, 504), r.text
    for bad in ("0", "-1", "300.5", " 1", "+1", "0x10", "inf"):
        r = support.requests.get(f"{srv.url}/v1/volumes/{ids['volume']}/slice",
                                 params={"axis": "z", "at": "0", "size": "4,4", "timeout": bad}, timeout=30)
        support.assert_error(r, 400, "invalid_argument", "timeout")


def test_query_numbers_are_json_numbers(fuzzed_server):
    srv, ids, _ = fuzzed_server
    url = f"{srv.url}/v1/volumes/{ids['volume']}/slice"
    ok = support.requests.get(url, params={"axis": "z", "at": "2.0", "size": "4,4.0", "origin": "1e1,0"}, timeout=30)
    assert ok.status_code == 200, ok.text  # integral numbers are integers, as in JSON Schema
    for field, params in (("size", {"size": " 4,4"}), ("size", {"size": "4,+4"}), ("at", {"at": "0x1"}),
                          ("size", {"size": "4,4.5"}), ("origin", {"origin": "267386881,0"})):
        r = support.requests.get(url, params={"axis": "z", "at": "0", "size": "4,4", **params}, timeout=30)
        support.assert_error(r, 400, "invalid_argument", field)


def test_frames_step_takes_any_positive_value(fuzzed_server):
    # Was 400 below 1e-6.
    srv, ids, _ = fuzzed_server
    r = support.requests.get(f"{srv.url}/v1/fields/{ids['field']}/frames",
                             params={"min": "1,1,1", "size": "2,1,1", "step": "1e-73"}, timeout=30)
    assert r.status_code == 200, r.text


def test_integral_floats_in_json_bodies_are_integers(fuzzed_server):
    # Was 400 "must be an integer" for 150.0, which JSON Schema counts as an integer.
    srv, ids, _ = fuzzed_server
    r = support.requests.post(f"{srv.url}/v1/volumes/{ids['volume']}/cut",
                              json={"origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0], "size": [4.0, 3.0]}, timeout=30)
    assert r.status_code == 200, r.text
    r = support.requests.post(f"{srv.url}/v1/volumes", json={"exemplar": ids["exemplar"], "seed": 5.0}, timeout=30)
    assert r.status_code == 201, r.text
    assert r.json()["seed"] == 5


def test_literal_path_answers_only_its_own_methods(fuzzed_server):
    # Was Allow: GET, DELETE, POST (the /v1/fields/{id} methods leaked into /v1/fields/from-mesh).
    srv, _, _ = fuzzed_server
    r = support.requests.options(f"{srv.url}/v1/fields/from-mesh", timeout=30)
    support.assert_error(r, 405, "method_not_allowed")
    assert r.headers["Allow"] == "POST"
    r = support.requests.get(f"{srv.url}/v1/fields/from-mesh", timeout=30)
    support.assert_error(r, 405, "method_not_allowed")


def test_surface_query_parameters_are_defaults_for_a_json_body(fuzzed_server):
    # Was 400 "unknown query parameter" for the documented resolution/margin/format.
    srv, ids, _ = fuzzed_server
    r = support.requests.post(f"{srv.url}/v1/volumes/{ids['volume']}/surface",
                              params={"format": "json", "resolution": "16", "margin": "0"},
                              json={"mesh": ids["mesh"]}, timeout=60)
    assert r.status_code == 200, r.text
    assert r.json()["placement"]["scale"] == 16


def test_volume_spec_text_values_follow_their_patterns(fuzzed_server):
    srv, ids, _ = fuzzed_server
    for spec, field in (({"exemplar": ids["exemplar"], "field": {"spec": "quat: 1,0,0,0"}}, "field.spec"),
                        ({"exemplar": ids["exemplar"], "field": {"spec": "identity;x"}}, "field.spec"),
                        ({"regions": {"exemplars": [ids["exemplar"]] * 2, "label": "box:0,0,0,+1,1,1"}}, "regions.label"),
                        ({"exemplar": ids["exemplar"], "params": {"plane_weights": [0, 1e-9, 0]}}, "params.plane_weights")):
        r = support.requests.post(f"{srv.url}/v1/volumes", json=spec, timeout=30)
        support.assert_error(r, 400, "invalid_argument", field)
    r = support.requests.post(f"{srv.url}/v1/exemplars", params={"plane_weights": "0,0,0"},
                              data=b"x", headers={"Content-Type": "application/octet-stream"}, timeout=30)
    support.assert_error(r, 400, "invalid_argument", "plane_weights")  # was 'suggested_plane_weights'


def test_names_are_counted_in_characters(fuzzed_server):
    # Was 400 for 200 characters of more than one byte each (bytes were counted).
    srv, ids, _ = fuzzed_server
    r = support.requests.post(f"{srv.url}/v1/volumes", json={"exemplar": ids["exemplar"], "name": "é" * 200}, timeout=30)
    assert r.status_code == 201, r.text
    r = support.requests.post(f"{srv.url}/v1/volumes", json={"exemplar": ids["exemplar"], "name": "é" * 201}, timeout=30)
    support.assert_error(r, 400, "invalid_argument", "name")


def test_served_contract_says_this_servers_max_deadline(fuzzed_server):
    # The document said timeout <= 300 whatever --max-deadline was; a fuzzer then asked for
    # deadlines the server refused (400) or ran for minutes.
    srv, _, _ = fuzzed_server
    doc = support.requests.get(srv.url + "/v1/openapi.json", timeout=30).json()
    maxima = {p["schema"]["maximum"] for ops in doc["paths"].values() for op in ops.values()
              if isinstance(op, dict) for p in op.get("parameters", []) if p["name"] == "timeout"}
    assert maxima == {8}
