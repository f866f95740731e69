#!/usr/bin/env python3
"""Source of the API contract: writes proto/openapi.json (served at GET /v1/openapi.json).

Edit this file, run `python3 proto/openapi.py`, commit both. `--check` fails when the JSON is
stale (a ctest runs it); server/routes_test.cpp checks the routes against the JSON.

The request-body schemas of sketches and volume specs live in proto/sketch.schema.json and
proto/volume.schema.json (JSON Schema 2020-12, the dialect of OpenAPI 3.1); they are bundled
here under components/schemas (their $defs become components of their own), so that the
document is self-contained and every $ref resolves inside it.

The ranges below are the server's: a request the schemas accept is refused only for reasons
that JSON Schema cannot state, and each such reason is named in a description (cross-field
rules, image and mesh contents, the per-request budgets of `solidtex serve` flags: 422).
Tests: tests/python/test_contract.py runs schemathesis over the served document.
"""
import json
import pathlib

HERE = pathlib.Path(__file__).resolve().parent
MAX_COORD = 1 << 28   # world coordinates, voxel indices (synth/synthesis/target.cpp)
MAX_SIDE = 1 << 24    # pixels per side of a slice, voxels per side of a region (the ceiling of --max-voxels)
MAX_CUT_SIDE = 1 << 20  # pixels per side of a cut
MAX_ORIGIN = MAX_COORD - MAX_SIDE  # origin/min of a slice or region: origin + size stays within 2^28
MAX_SEED = 1 << 30
ID_MAX = 64           # characters of an id named in a body


def ref(n): return {"$ref": f"#/components/schemas/{n}"}
def err(desc): return {"description": desc, "content": {"application/json": {"schema": ref("Error")}}}
def js(schema, desc="OK"): return {"description": desc, "content": {"application/json": {"schema": schema}}}
def qp(name, desc, schema=None, required=False):
    return {"name": name, "in": "query", "required": required, "description": desc, "schema": schema or {"type": "string"}}
def qlist(name, desc, items, n, required=False):
    """A query parameter of exactly n comma-separated values (`size=W,H`)."""
    return {"name": name, "in": "query", "required": required, "description": desc, "style": "form", "explode": False,
            "schema": {"type": "array", "items": items, "minItems": n, "maxItems": n}}
def pid(desc="Opaque id."): return {"name": "id", "in": "path", "required": True, "description": desc, "schema": {"type": "string", "minLength": 1}}
def integer(lo, hi, **kw): return {"type": "integer", "minimum": lo, "maximum": hi, **kw}
def number(lo, hi, **kw): return {"type": "number", "minimum": lo, "maximum": hi, **kw}
coord = number(-MAX_COORD, MAX_COORD)
vec3 = {"type": "array", "items": coord, "minItems": 3, "maxItems": 3}
timeout = qp("timeout", "Deadline in seconds for this request, (0, --max-deadline] (default 300 s; a server started with another --max-deadline serves that maximum here); default: the server's --deadline (30 s). "
             "Past it the synthesis is cancelled and the answer is 504.", {"type": "number", "exclusiveMinimum": 0, "maximum": 300})
LIMITS_422 = ("Well-formed but over a per-request budget of the server (flags of `solidtex serve`): more output samples than --max-voxels "
              "(default 4194304), working memory estimated above --max-request-mb (default 1536; the cost model runs before any work), "
              "a field grid above --max-field-nodes (default 262144), a mesh above --max-mesh-vertices/--max-mesh-faces; or unusable "
              "content (a corrupt image or mesh, an image smaller than 8 or larger than --max-image-side pixels per side).")
E = {"400": err("Malformed request: bad JSON, unknown key or query parameter, value out of range, a rule between fields broken; `field` names it."),
     "404": err("No such resource."), "405": err("Method not allowed on this path."),
     "413": err("Body larger than --max-upload-mb (default 64 MiB); no other request is answered 413."),
     "415": err("Unsupported Content-Type, or an image or mesh format that is not recognised from its bytes."),
     "422": err(LIMITS_422),
     "429": err("Too many concurrent analysis jobs (--max-jobs)."),
     "502": err("The storage backend (`--storage s3://...`) cannot be reached or refuses service right now (code `unavailable`, "
                "see Retry-After); retry later, from this or any replica."),
     "503": err("Worker queue full (see Retry-After) or shutting down; retry later, here or on another replica."),
     "504": err("The request's deadline passed; the work was cancelled.")}
# Every answer that may be 503 touches the store too, so may be 502.
def errs(*codes): return {c: E[c] for c in sorted(set(codes) | ({"502"} if "503" in codes else set()))}
# Chunked-array views (server/chunked_arrays.h): every answer carries CORS headers.
CORS = {"Access-Control-Allow-Origin": {"schema": {"type": "string"}}, "Access-Control-Expose-Headers": {"schema": {"type": "string"}}}
# Their successful answers are conditional and ranged (server/conditional_get.h): HEAD (as on
# every GET route), If-None-Match with the ETag -> 304, a single `Range: bytes=a-b | a- | -n` ->
# 206 or 416; other Range forms (several ranges, other units) are ignored: 200 with everything.
RANGED = ("HEAD answers the same status and headers without the body. `If-None-Match` naming the ETag: 304. "
          "A single `Range: bytes=a-b`, `bytes=a-` or `bytes=-n` (with an `If-Range` naming the ETag, if any): 206 with those bytes "
          "and `Content-Range: bytes a-b/total`, or 416 with `Content-Range: bytes */total` when it starts past the end; "
          "several ranges, other units and malformed headers are ignored (200, the whole body). Every 200 says `Accept-Ranges: bytes`.")
STR = {"schema": {"type": "string"}}
ARRAY_HEADERS = {**CORS, "ETag": STR, "Cache-Control": STR, "Accept-Ranges": STR}
ZARR_META = {"description": "Metadata (JSON); a strong ETag from (volume spec, --array-extent, the document's path), so every document has its own, stable across restarts; Cache-Control: public, max-age=60.",
             "headers": ARRAY_HEADERS,
             "content": {"application/json": {"schema": {"type": "object"}}}}
ZARR_CHUNK_OUT = {"description": "zstd-compressed chunk bytes; a strong ETag from (volume spec, format, dataset, chunk), stable across restarts; Cache-Control: public, max-age=31536000, immutable.",
                  "headers": {**ARRAY_HEADERS, "X-Voxels-Synthesized": {"schema": {"type": "integer"}}},
                  "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}
RANGE_OUT = {"206": {"description": "Partial content: the requested bytes of the 200 body (Range).", "headers": {**ARRAY_HEADERS, "Content-Range": STR}},
             "304": {"description": "Not modified: If-None-Match named the ETag; no body.", "headers": {**CORS, "ETag": STR, "Cache-Control": STR}},
             "416": {**err("Range not satisfiable: the range starts past the end (`Content-Range: bytes */total`)."), "headers": {**CORS, "Content-Range": STR}}}
# Slices, cuts and regions: voxels are a pure function of (volume, request), so the answer is
# immutable; its ETag hashes its bytes (server/api.cpp, Api::mark_immutable).
IMMUTABLE_IMAGE = ("The answer is immutable: a strong ETag (\"img-\" and a hash of the body) and `Cache-Control: public, "
                   "max-age=31536000, immutable`; deleting the volume does not reach caches that kept it.")
IMAGE_RANGE_OUT = {"206": {"description": "Partial content: the requested bytes of the 200 body (Range).", "headers": {"ETag": STR, "Cache-Control": STR, "Content-Range": STR}},
                   "304": {"description": "Not modified: If-None-Match named the ETag; no body.", "headers": {"ETag": STR, "Cache-Control": STR}},
                   "416": {**err("Range not satisfiable: the range starts past the end (`Content-Range: bytes */total`)."), "headers": {"Content-Range": STR}}}
def array_op(op_id, summary, ok, codes):
    return {"operationId": op_id, "summary": summary, "description": RANGED, "responses": {"200": ok, **RANGE_OUT, **errs(*codes)}}
PRECOMPUTED_CHUNK = {"name": "chunk", "in": "path", "required": True, "description": "x0-x1_y0-y1_z0-z1 voxel bounds of the scale: inside it, at most 64 a side and 32768 voxels (else 404).", "schema": {"type": "string", "pattern": "^[0-9]+-[0-9]+_[0-9]+-[0-9]+_[0-9]+-[0-9]+$"}}
def zarr_index(name, desc):
    return {"name": name, "in": "path", "required": True, "description": desc + " Past the array (or not an index): 404.", "schema": {"type": "integer", "minimum": 0}}
ZARR_SCALE = zarr_index("scale", "Dataset: 0 is the finest synthesis level, s has voxels 2^s finest voxels wide.")
ZARR_CHUNK = [zarr_index("c", "Channel chunk: always 0 (the 3 channels are one chunk)."), zarr_index("cz", "Chunk index along z."),
              zarr_index("cy", "Chunk index along y."), zarr_index("cx", "Chunk index along x.")]
def created(schema, links):
    return {"description": "Created.", "headers": {"Location": {"schema": {"type": "string"}}},
            "content": {"application/json": {"schema": schema}}, "links": links}
def link(op, pointer="/id", desc=None, body=None):
    """An OpenAPI link to operation `op` whose `id` is taken from the answer at `pointer`."""
    out = {"operationId": op}
    if pointer is not None:
        out["parameters"] = {"path.id": f"$response.body#{pointer}"}
    if body is not None:
        out["requestBody"] = body
    if desc:
        out["description"] = desc
    return out
def links_to(ops, pointer="/id", deletes=True):
    """Links to `ops` with the id at `pointer`; from a list (deletes=False) not to DELETE, so
    that following links from a listing never removes what others stored."""
    return {op: link(op, pointer) for op in ops if deletes or not op.startswith("delete_")}
EXEMPLAR_OPS = ["get_exemplar", "get_exemplar_table", "delete_exemplar"]
FIELD_OPS = ["get_field", "get_field_file", "sample_frames", "add_curve", "delete_field"]
VOLUME_OPS = ["get_volume", "volume_stats", "slice", "cut", "region", "points", "surface", "delete_volume"]
MESH_OPS = ["get_mesh", "get_mesh_file", "delete_mesh"]
image_out = {"description": "The cut. PNG (8-bit sRGB) by default; with `Accept: application/octet-stream` raw sRGB8 bytes (H x W x 3, row-major) and with `Accept: application/octet-stream; dtype=float32` raw little-endian float32 linear RGB; raw answers carry `X-Shape: H,W,3` and `X-Dtype`.",
    "headers": {"ETag": STR, "Cache-Control": STR, "X-Shape": {"schema": {"type": "string"}}, "X-Dtype": {"schema": {"type": "string"}}, "X-Voxels-Synthesized": {"schema": {"type": "integer"}, "description": "Voxels this request synthesized over all levels (0 when everything was cached)."}},
    "content": {"image/png": {"schema": {"type": "string", "format": "binary"}}, "application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}
revision_param = qp("revision", "The field revision this change is meant for (the one the client shows). When given and the field is at another revision (another client, or a retry, changed it since), the answer is 409 naming `revision` and saying the current one, and nothing changes. Absent: whatever revision is current.", integer(1, 2**31 - 1))
REVISION_409 = ("`revision` was given and the field is at another revision: nothing changed (`field` is `revision`; the message says the current revision). "
                "Also when another replica wrote the same next revision at the same moment (`field` is `revision`): nothing changed; read the field and retry.")
scale_param = qp("scale", "Dataset s of the volume's pyramid, as /zarr's: 0 (default) the finest voxels; s > 0 synthesis level L-1-s, whose voxels are 2^s finest voxels wide (voxel i covers finest voxels [i*2^s, (i+1)*2^s)) and are that level's own colours, not filters of finer ones; nothing finer is synthesized, so coarse cuts are fast previews. Coordinates and sizes are then in that dataset's voxels. Past the volume's coarsest dataset (L-1; region volumes have dataset 0 only): 404.", integer(0, 7, default=0))
analysis_params = [
    qp("name", "Free-form label, at most 200 characters.", {"type": "string", "maxLength": 200}),
    qp("levels", "Pyramid levels L, or 'auto' (default): the most levels whose coarsest template (N * 2^(L-1) pixels) spans at most half the exemplar's shorter side, with N = 9: 2 for shorter sides of 36 to 71 pixels, 3 for 72 to 143, 4 for 144 to 287, 5 for 288 to 575. The exemplar's `params.levels` and `levels` report the count used.",
       {"oneOf": [integer(1, 8), {"type": "string", "enum": ["auto"]}], "default": "auto"}),
    qp("neighborhood", "Template size N (odd).", {"type": "integer", "enum": [3, 5, 7, 9, 11, 13, 15], "default": 9}),
    qp("candidates", "Candidate triples per pixel N_T.", integer(1, 32, default=12)),
    qp("pca_dims", "Appearance-space dimensions per plane.", integer(1, 64, default=20)),
    qp("seed", "Seeds the k-NN trees.", integer(0, MAX_SEED, default=1)),
    {**qlist("plane_weights", "Suggested plane weights A,B,C (xy, yz, zx) stored with the table, each in [0, 1], not all 0 (one at least 1e-6).", number(0, 1), 3),
     "schema": {"type": "array", "items": number(0, 1), "minItems": 3, "maxItems": 3, "contains": {"minimum": 1e-6}}},
    qp("grain", "Grain layout. 'x': the exemplar's stripes run along its x axis and the solid's grain along world x: xy = E, zx = E transposed, yz = E with suggested weight 0.3 (as `solidtex analyze --grain x`). 'y': stripes along its y axis, grain along world y: xy = E, yz = E transposed, zx = E with weight 0.3. 'auto' (default): 'x' or 'y' when the exemplar is strongly striped along that axis (structure-tensor coherence >= 0.43 at the pixel scale or after a 1 or 2 px blur, within 20 degrees), isotropic otherwise and with yz/zx parts. 'none': isotropic. 'crossed': isotropic, xy = E and yz = zx = E transposed, so that two of the three crossbars compare the exemplar's profiles in the same direction (better for exemplars whose two directions differ; about 3x the analysis time). The exemplar's `grain` reports the layout applied ('', 'x', 'y' or 'crossed'). 'x', 'y' and 'crossed' not with yz/zx parts.", {"type": "string", "enum": ["auto", "none", "x", "y", "crossed"], "default": "auto"}),
    qp("mask_weight", "Weight of the feature-mask channel relative to color.", number(0, 10, default=1)),
]


def bundle(file, names):
    """The JSON Schema in proto/`file` as components: its root and each of its $defs under the
    names in `names` ("" names the root); refs to its $defs are rewritten to components."""
    schema = json.loads((HERE / file).read_text())
    defs = schema.pop("$defs", {})
    for k in ("$schema", "$id"):
        schema.pop(k, None)
    def rewrite(node):
        if isinstance(node, dict):
            return {k: (f"#/components/schemas/{names[v[len('#/$defs/'):]]}" if k == "$ref" and isinstance(v, str) and v.startswith("#/$defs/") else rewrite(v))
                    for k, v in node.items()}
        if isinstance(node, list):
            return [rewrite(v) for v in node]
        return node
    out = {names[""]: rewrite(schema)}
    for k, v in defs.items():
        out[names[k]] = rewrite(v)
    return out


nullable_error = {"description": "null unless failed: {code, message, field} as in Error.", "oneOf": [{"type": "null"}, ref("ErrorDetail")]}
S = {
 "Error": {"type": "object", "required": ["error"], "properties": {"error": ref("ErrorDetail")}},
 "ErrorDetail": {"type": "object", "required": ["code", "message", "field"], "properties": {
     "code": {"type": "string", "description": "Machine-readable: invalid_argument, not_found, unsupported, too_large, corrupt, unprocessable, version_mismatch, cancelled, deadline_exceeded, resource_exhausted, rate_limited, unavailable, already_exists, failed_precondition, method_not_allowed, internal, io."},
     "message": {"type": "string"}, "field": {"type": "string", "description": "The input the error is about (body, a JSON path, a query parameter); may be empty."}}},
 "Job": {"type": "object", "required": ["id", "kind", "state", "percent"], "properties": {
     "id": {"type": "string"}, "kind": {"type": "string", "enum": ["analysis"]}, "exemplar_id": {"type": "string"},
     "state": {"type": "string", "enum": ["queued", "running", "succeeded", "failed"]},
     "percent": {"type": "number", "minimum": 0, "maximum": 100}, "seconds": {"type": "number"},
     "error": nullable_error},
     "description": "With several replicas on one data directory, the replica holding the job's lease runs it; through the others the job shows as running with percent 0 until its result is stored, and one of them takes it over when the lease (--job-lease-seconds) expires."},
 "LevelReport": {"type": "object", "properties": {"level": {"type": "integer"}, "spacing": {"type": "integer"}, "mean_crossbar_error": {"type": "number"}, "random_crossbar_error": {"type": "number"}, "coherent_fraction": {"type": "number"}}},
 "Exemplar": {"type": "object", "required": ["id", "state"], "properties": {
     "id": {"type": "string"}, "name": {"type": "string"}, "state": {"type": "string", "enum": ["analyzing", "ready", "failed"]},
     "job_id": {"type": "string"}, "grain": {"type": "string"}, "seconds": {"type": "number"}, "planes": {"type": "integer", "enum": [1, 3]}, "has_mask": {"type": "boolean"},
     "width": {"type": "integer"}, "height": {"type": "integer"}, "params": {"type": "object"},
     "levels": {"type": "array", "items": ref("LevelReport")}, "table_bytes": {"type": "integer"},
     "error": nullable_error}},
 "ExemplarCreated": {"type": "object", "required": ["exemplar", "job"], "properties": {"exemplar": ref("Exemplar"), "job": ref("Job")}},
 "Field": {"type": "object", "required": ["id", "revision"], "properties": {
     "id": {"type": "string"}, "revision": {"type": "integer", "description": "1 at creation, +1 per added or removed curve."},
     "curves": {"type": "integer"}, "dims": {"type": "array", "items": {"type": "integer"}}, "origin": {"type": "array", "items": {"type": "number"}},
     "spacing": {"type": "number"}, "singular_nodes": {"type": "integer"}, "residual": {"type": "number"}, "seconds": {"type": "number"}, "has_scales": {"type": "boolean"},
     "from_mesh": {"type": "object", "description": "Only in the answer of POST /v1/fields/from-mesh: kind, frames and curves used, dropped_curves (crest chains that define no frame), placement {scale, translate}."}},
     "description": "`curves` counts sketch elements: each curve, plus one for a batch of explicit frames."},
 "Frames": {"type": "object", "properties": {"points": {"type": "array", "items": {"type": "array", "items": {"type": "number"}}},
     "quaternions": {"type": "array", "description": "Unit quaternions (w, x, y, z) at the points.", "items": {"type": "array", "items": {"type": "number"}}},
     "scales": {"type": "array", "description": "Per-axis scales at the points (1,1,1 without a scale field).", "items": {"type": "array", "items": {"type": "number"}}}}},
 "Volume": {"type": "object", "required": ["id"], "properties": {"id": {"type": "string"}, "name": {"type": "string"},
     "exemplars": {"type": "array", "items": {"type": "string"}}, "label": {"type": "string"},
     "field": {"type": "object", "description": "Where the field came from: {\"kind\": \"identity\"}, {\"kind\": \"spec\", \"spec\"} or {\"kind\": \"stored\", \"id\", \"revision\"} (the volume keeps its own copy of that revision).", "properties": {"kind": {"type": "string", "enum": ["identity", "spec", "stored"]}, "spec": {"type": "string"}, "id": {"type": "string"}, "revision": {"type": "integer"}}},
     "field_description": {"type": "string", "description": "Human-readable description of the field, e.g. 'identity' or 'quat:0.92,0,0,0.38'."},
     "seed": {"type": "integer"}, "params": {"type": "object", "description": "The synthesis params as given, with the appearance-changing defaults pinned to the values it was created with (`typicality`, `passes`, `init`, `color`, `finest_subpass_size`, `balance`, `finest_typicality_scale`, `init_band`, `finest_match`, `finest_sources`; volumes stored before each was pinned come back with what their voxels were made with: typicality 0, 2 passes, slab init, mean colors, finest_subpass_size 2, balance 0, finest_typicality_scale 1, init_band 0, finest_match triple, finest_sources square; new volumes pin typicality \"auto\", which resolves per table, and volumes made before auto keep the 0.5 they pinned), so later defaults never change a stored volume. `balance` in [0, 4] (default 1) weighs the exemplar table's usage penalties, which even out which exemplar regions synthesis uses."}}},
 "Cut": {"type": "object", "additionalProperties": False, "required": ["origin", "u", "v", "size"],
     "description": f"The far corner origin + W*u + H*v must lie within +-2^28 too (else 400); W*H at most --max-voxels (else 422).",
     "properties": {
     "origin": {**vec3, "description": "Voxels of dataset `scale` (world units, the finest voxels, by default)."},
     "u": {**vec3, "description": "Step per output column, in voxels of dataset `scale`."},
     "v": {**vec3, "description": "Step per output row, in voxels of dataset `scale`."},
     "size": {"type": "array", "items": integer(1, MAX_CUT_SIDE), "minItems": 2, "maxItems": 2, "description": "W, H."},
     "resample": {"type": "string", "enum": ["auto", "nearest", "cubic"], "default": "auto", "description": "nearest: each pixel is the voxel nearest its position. cubic: the Catmull-Rom (tricubic) combination of the 4x4x4 voxels around it, clamped to their range: no jaggies along tilted planes, softer 1-voxel detail; at most 1024^2 pixels reading at most 8 Mi voxels (else 422 naming size). auto: cubic when the volume's exemplars carry little 1-pixel detail (every exemplar's finest Laplacian band under 43 % of its two finest bands' energy), else nearest; the answer's X-Resample header says which. At integer positions all give that voxel."}}},
 "PointsRequest": {"type": "object", "additionalProperties": False, "required": ["points"], "properties": {
     "points": {"type": "array", "minItems": 1, "items": vec3, "description": "World points; at most --max-voxels of them (else 422)."}}},
 "Mesh": {"type": "object", "required": ["id"], "properties": {
     "id": {"type": "string"}, "name": {"type": "string"}, "format": {"type": "string", "enum": ["ply", "obj", "off"]},
     "vertices": {"type": "integer", "description": "Every vertex position of the file, unreferenced ones included (they get colors too); OBJ texture coordinates and normals are ignored."}, "triangles": {"type": "integer", "description": "After fan triangulation of polygons and removal of duplicate and degenerate faces."},
     "bounds": {"type": "object", "properties": {"min": {"type": "array", "items": {"type": "number"}}, "max": {"type": "array", "items": {"type": "number"}}}},
     "defects": {"type": "object", "description": "What the reader tolerated: duplicate_faces and degenerate_faces (dropped), unreferenced_vertices, boundary_edges (holes), non_manifold_edges, components.",
                 "properties": {k: {"type": "integer"} for k in ["duplicate_faces", "degenerate_faces", "unreferenced_vertices", "boundary_edges", "non_manifold_edges", "components", "polygons_triangulated"]}}}},
 "SurfaceRequest": {"type": "object", "additionalProperties": False, "required": ["mesh"], "properties": {
     "mesh": {"type": "string", "maxLength": ID_MAX, "description": "Id of a stored mesh."},
     "placement": ref("Placement"),
     "format": {"type": "string", "enum": ["ply", "json"], "default": "ply"},
     "points": {"type": "array", "description": "Extra surface points (mesh coordinates) to color as well (format json only).", "items": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}}},
     "if": {"required": ["points"]}, "then": {"required": ["format"], "properties": {"format": {"const": "json"}}}},
 "SurfaceColors": {"type": "object", "properties": {
     "vertices": {"type": "integer"}, "colors": {"type": "array", "description": "Linear RGB per vertex (float).", "items": {"type": "array", "items": {"type": "number"}}},
     "point_colors": {"type": "array", "items": {"type": "array", "items": {"type": "number"}}},
     "placement": {"type": "object", "properties": {"scale": {"type": "number"}, "translate": {"type": "array", "items": {"type": "number"}}}},
     "stats": {"type": "object", "description": "target_voxels (distinct finest voxels the surface needs), bounding_voxels (voxels of the placed mesh's bounding box), fraction (synthesized voxels over all levels / bounding_voxels), voxels_synthesized, levels (per-level dependent-set sizes)."}}},
 "FieldFromMesh": {"type": "object", "additionalProperties": False, "required": ["mesh", "kind"], "properties": {
     "mesh": {"type": "string", "maxLength": ID_MAX}, "kind": {"type": "string", "enum": ["curvature", "features"], "description": "curvature: principal-curvature frames at surface vertices (Gorla et al.), x along the direction of least curvature, y along the normal; features: crest lines (edges whose dihedral angle exceeds feature_angle_degrees, chained) and any user `curves`, used as sketch curves with x along the curve."},
     "placement": ref("Placement"),
     "shortest_side_cells": integer(2, 256, default=24),
     "max_constraints": integer(1, 20000, default=2000, description="curvature: at most this many vertex frames: one per occupied cube of the field's grid spacing (the cube grows by 25% until the budget holds), so usually fewer."),
     "feature_angle_degrees": number(1, 179, default=60),
     "curves": {"type": "array", "description": "features: user polylines on the surface (mesh coordinates); normals are taken from the nearest vertices.", "items": {"type": "array", "items": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}}}}},
 "Stats": {"type": "object", "properties": {"volume": {"type": "string"}, "levels": {"type": "array", "items": {"type": "object", "properties": {"level": {"type": "integer"}, "voxels_synthesized": {"type": "integer"}, "cached_voxels": {"type": "integer"}}}},
     "cache": {"type": "object", "description": "The volume's voxel cache: bytes is all it holds (bricks of 8^3 voxels), within its share of --cache-mb (budget_bytes); bytes_per_voxel is bytes over the cached voxels of every level (bricks hold their present voxels only: about 12.3 per voxel in full bricks, 14.6 in one-layer bricks).", "properties": {"bytes": {"type": "integer"}, "budget_bytes": {"type": "integer"}, "bytes_per_voxel": {"type": "number"}, "hits": {"type": "integer"}, "misses": {"type": "integer"}, "bricks": {"type": "integer"}, "evicted_bricks": {"type": "integer"}}},
     "state": ref("VolumeState"),
     "requests": {"type": "integer"}, "recent": {"type": "array", "description": "The last requests (newest last): kind, target voxels and dependent-set sizes per level.", "items": {"type": "object"}}}},
 "VolumeState": {"type": "object", "additionalProperties": False,
     "description": "What the volume keeps loaded between requests outside its voxel cache, in resident bytes. Built at the first query (at creation for a surface label), evicted least recently used first when all loaded volumes together pass --volume-state-mb (default 512; never a state a running request uses, nor the most recently used one) or after --idle-evict-s (default 300) without requests, and rebuilt at the next query with the same bits. All byte counts are 0 while not loaded. /metrics gives the totals over the service (solidtex_volume_state_bytes, a table shared by several volumes counting once).",
     "required": ["loaded", "bytes", "synthesizer_bytes", "table_bytes", "field_bytes", "surface_bytes", "active_requests", "loads", "evictions", "idle_seconds"],
     "properties": {
     "loaded": {"type": "boolean"},
     "bytes": {"type": "integer", "minimum": 0, "description": "The sum of the four parts below."},
     "synthesizer_bytes": {"type": "integer", "minimum": 0, "description": "Synthesizers' own state: per-level correction constants, stencils, schedules."},
     "table_bytes": {"type": "integer", "minimum": 0, "description": "The candidate-triple tables in use (decoded: stacks, appearance vectors, candidates), shared with other loaded volumes of the same exemplars."},
     "field_bytes": {"type": "integer", "minimum": 0, "description": "The frame field (a stored field's quaternion grid)."},
     "surface_bytes": {"type": "integer", "minimum": 0, "description": "A surface label's distance band."},
     "active_requests": {"type": "integer", "minimum": 0, "description": "Requests running on the state now."},
     "loads": {"type": "integer", "minimum": 0, "description": "Times the state was built since the server started."},
     "evictions": {"type": "integer", "minimum": 0, "description": "Times it was evicted since the server started."},
     "idle_seconds": {"type": "number", "minimum": 0, "description": "Since its last request ended (or since it was created or the server started); 0 while a request runs."}}},
 **bundle("sketch.schema.json", {"": "Sketch", "vec3": "SketchVec3", "curve": "SketchCurve", "scalePoint": "SketchScalePoint", "frame": "SketchFrame"}),
 **bundle("volume.schema.json", {"": "VolumeSpec", "synthesisParams": "SynthesisParams", "placement": "Placement"}),
}

MESH_EXAMPLE = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
exemplar_links = {**links_to(EXEMPLAR_OPS, "/exemplar/id"), "get_job": link("get_job", "/job/id")}
WEB_DESCRIPTION = ("Read from the web root at every request (server/static_files.h). A strong ETag made of the bytes and `Cache-Control: no-cache`, so that browsers revalidate: "
                   "`If-None-Match` naming the ETag gets 304. HEAD and a single byte range as on the array views (206, 416).")
WEB_HEADERS = {"ETag": STR, "Cache-Control": STR, "Accept-Ranges": STR}
WEB_CONDITIONAL = {"206": {"description": "Partial content (a single `Range: bytes=...`).", "headers": {"ETag": STR, "Content-Range": STR}},
                   "304": {"description": "Not modified: If-None-Match named the ETag; no body.", "headers": {"ETag": STR, "Cache-Control": STR}},
                   "416": {**err("Range not satisfiable."), "headers": {"Content-Range": STR}}}
paths = {
 "/": {"get": {"operationId": "web_app", "summary": "The browser app (index.html of --web-root, by default the source tree's web/): upload exemplars, create volumes, browse and sketch cuts, orbit textured meshes. It loads its other files from /web/{file}. 404 when the server has no web root.",
     "description": WEB_DESCRIPTION, "responses": {"200": {"description": "The page.", "headers": WEB_HEADERS, "content": {"text/html": {"schema": {"type": "string"}}}}, **WEB_CONDITIONAL, **errs("400", "404")}}},
 "/web/{file}": {"parameters": [{"name": "file", "in": "path", "required": True, "description": "A file directly in the web root: 1 to 128 characters of [A-Za-z0-9_.-], not starting with '.' (any other name, a directory or a symbolic link: 404).", "schema": {"type": "string", "minLength": 1}}],
   "get": {"operationId": "web_file", "summary": "A file of the browser app; its Content-Type follows the extension (text/javascript for its ES modules).", "description": WEB_DESCRIPTION,
     "responses": {"200": {"description": "The file.", "headers": WEB_HEADERS, "content": {t: {"schema": {"type": "string", "format": "binary"}} for t in ("text/html", "text/javascript", "text/css", "application/json", "image/svg+xml", "image/png", "text/plain", "application/octet-stream")}},
                   **WEB_CONDITIONAL, **errs("400", "404", "422")}}},
 "/healthz": {"get": {"operationId": "healthz", "summary": "Liveness and readiness: 200 with status ok; 503 with status stopping once shutdown has begun, so balancers stop sending work.", "responses": {"200": js({"type": "object", "required": ["status"], "properties": {"status": {"type": "string", "enum": ["ok"]}, "queue_depth": {"type": "integer"}, "workers_busy": {"type": "integer"}}}), "503": js({"type": "object", "required": ["status"], "properties": {"status": {"type": "string", "enum": ["stopping"]}, "queue_depth": {"type": "integer"}, "workers_busy": {"type": "integer"}}}), **errs("400")}}},
 "/metrics": {"get": {"operationId": "metrics", "summary": "Prometheus text: requests and latency histograms per route, voxels synthesized, cache bytes and budget, queue depth, loaded volumes' state bytes and budget (solidtex_volume_state_bytes, solidtex_volume_state_budget_bytes, solidtex_volumes_loaded) and evictions by reason.", "responses": {"200": {"description": "OK", "content": {"text/plain": {"schema": {"type": "string"}}}}}}},
 "/v1/openapi.json": {"get": {"operationId": "openapi", "summary": "This document.", "responses": {"200": js({"type": "object"})}}},
 "/v1/exemplars": {
   "get": {"operationId": "list_exemplars", "summary": "List exemplars.", "responses": {"200": {**js({"type": "object", "properties": {"exemplars": {"type": "array", "items": ref("Exemplar")}}}),
       "links": {**links_to(EXEMPLAR_OPS, "/exemplars/0/id", deletes=False), "create_volume": link("create_volume", None, "A volume of the first exemplar.", {"exemplar": "$response.body#/exemplars/0/id"})}}, **errs("400")}},
   "post": {"operationId": "upload_exemplar", "summary": "Upload an exemplar; its analysis runs in the background.",
     "description": "Body: the image bytes (any Content-Type but multipart/form-data, application/json and application/x-www-form-urlencoded), or multipart/form-data with parts `xy` (or `image`), optional `yz` and `zx` (all three or only one), and optional `mask` (with three planes also `mask_yz` and `mask_zx`); at most 16 parts. PNG, JPEG, TIFF, OpenEXR, recognised from the bytes (else 415); gray/RGB/RGBA, 8/16-bit or float; at least 8 and at most --max-image-side (8192) pixels per side and --max-image-pixels in all (else 422, checked from the header); analysing it must fit --max-request-mb (else 422). Analysis parameters in the query. The upload is stored before the answer, so an acknowledged upload survives a restart (its analysis is re-run).",
     "parameters": analysis_params,
     "requestBody": {"required": True, "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary", "minLength": 1}}, "multipart/form-data": {"schema": {"type": "object", "required": ["xy"], "additionalProperties": False, "properties": {"xy": {"type": "string", "format": "binary"}, "yz": {"type": "string", "format": "binary"}, "zx": {"type": "string", "format": "binary"}, "mask": {"type": "string", "format": "binary"}, "mask_yz": {"type": "string", "format": "binary"}, "mask_zx": {"type": "string", "format": "binary"}}}}}},
     "responses": {"202": {"description": "Accepted; poll the job.", "headers": {"Location": {"schema": {"type": "string"}}}, "content": {"application/json": {"schema": ref("ExemplarCreated")}}, "links": exemplar_links}, **errs("400", "413", "415", "422", "429", "503")}}},
 "/v1/exemplars/{id}": {"parameters": [pid()],
   "get": {"operationId": "get_exemplar", "summary": "One exemplar.", "responses": {"200": {**js(ref("Exemplar")), "links": {"create_volume": link("create_volume", None, "A volume of this exemplar.", {"exemplar": "$response.body#/id"})}}, **errs("404", "503")}},
   "delete": {"operationId": "delete_exemplar", "summary": "Delete an exemplar not used by any volume.", "responses": {"204": {"description": "Deleted."}, "409": err("A volume uses it."), **errs("404", "503")}}},
 "/v1/exemplars/{id}/table": {"parameters": [pid()],
   "get": {"operationId": "get_exemplar_table", "summary": "The .stx candidate-triple table (the same bytes `solidtex analyze` writes for the same inputs).", "responses": {"200": {"description": "OK", "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}, "409": err("Not ready."), **errs("404", "503")}}},
 "/v1/jobs/{id}": {"parameters": [pid()],
   "get": {"operationId": "get_job", "summary": "State and progress of a background job.", "responses": {"200": js(ref("Job")), **errs("404", "503")}}},
 "/v1/fields": {
   "get": {"operationId": "list_fields", "summary": "List fields.", "responses": {"200": {**js({"type": "object", "properties": {"fields": {"type": "array", "items": ref("Field")}}}), "links": links_to(FIELD_OPS, "/fields/0/id", deletes=False)}, **errs("400")}},
   "post": {"operationId": "create_field", "summary": "Solve a frame field from a sketch (schema: Sketch, from proto/sketch.schema.json). Rules between fields (points inside the domain, consecutive points distinct, one normal per point, frames defined along the curve, non-zero quaternions) are checked too (400); a grid above --max-field-nodes is refused (422).", "parameters": [timeout],
     "requestBody": {"required": True, "content": {"application/json": {"schema": ref("Sketch")}}},
     "responses": {"201": created(ref("Field"), links_to(FIELD_OPS)), **errs("400", "413", "415", "422", "503", "504")}}},
 "/v1/fields/{id}": {"parameters": [pid()],
   "get": {"operationId": "get_field", "summary": "One field.", "responses": {"200": js(ref("Field")), **errs("404", "503")}},
   "delete": {"operationId": "delete_field", "summary": "Delete a field (volumes keep their own copies). A curve being added or removed finishes first; 504 when that takes past the server's --deadline (nothing deleted).", "responses": {"204": {"description": "Deleted."}, **errs("404", "503", "504")}}},
 "/v1/fields/{id}/file": {"parameters": [pid()],
   "get": {"operationId": "get_field_file", "summary": "The .stf field file of the current revision (usable with `solidtex slice --field`).", "responses": {"200": {"description": "OK", "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}, **errs("404", "503")}}},
 "/v1/fields/{id}/curves": {"parameters": [pid()],
   "post": {"operationId": "add_curve", "summary": "Add one curve (a sketch curve object, schema SketchCurve) and re-solve incrementally; the revision increases. The curve must lie inside the field's domain (400). Changes of one field run one at a time: waiting for another counts against the deadline.", "parameters": [revision_param, timeout],
     "requestBody": {"required": True, "content": {"application/json": {"schema": ref("SketchCurve")}}},
     "responses": {"200": {**js(ref("Field")), "links": {"remove_last_curve": link("remove_last_curve", "/id", "Undo: remove the curve just added.")}},
                   "409": err(REVISION_409), **errs("400", "404", "413", "415", "422", "503", "504")}}},
 "/v1/fields/{id}/curves/last": {"parameters": [pid()],
   "delete": {"operationId": "remove_last_curve", "summary": "Undo the last added curve: the next revision holds the sketch without its last curve. It is bit for bit the newest earlier revision with exactly those curves (the one before the curve was added), or, when there is none (a field created with several curves), solved afresh. Volumes keep the revision they copied. Give `revision` (the one shown) so that a stale page or a retried request never removes a curve it did not see.", "parameters": [revision_param, timeout],
     "responses": {"200": js(ref("Field")), "409": err(REVISION_409 + " Without that: the sketch has no curve, or its only curve would leave it with neither curves nor frames (delete the field instead)."), **errs("400", "404", "422", "503", "504")}}},
 "/v1/fields/{id}/frames": {"parameters": [pid()],
   "get": {"operationId": "sample_frames", "summary": "Frames on a regular grid of points, for display.",
     "parameters": [qlist("min", "X,Y,Z world units of the first point.", {"type": "number"}, 3, True),
                    qlist("size", "Points per axis NX,NY,NZ; their product at most 65536 (else 422).", integer(1, 65536), 3, True),
                    qp("step", "World units between points.", {"type": "number", "exclusiveMinimum": 0, "maximum": 1e6, "default": 1})],
     "responses": {"200": js(ref("Frames")), **errs("400", "404", "422", "503")}}},
 "/v1/volumes": {
   "get": {"operationId": "list_volumes", "summary": "List volumes.", "responses": {"200": {**js({"type": "object", "properties": {"volumes": {"type": "array", "items": ref("Volume")}}}), "links": links_to(VOLUME_OPS, "/volumes/0/id", deletes=False)}, **errs("400")}},
   "post": {"operationId": "create_volume", "summary": "Create a volume from ready exemplars, a field and synthesis parameters (schema: VolumeSpec, from proto/volume.schema.json). The exemplars must exist (404) and be ready (409), a stored field must exist (404); label and field spec values are checked (400).",
     "requestBody": {"required": True, "content": {"application/json": {"schema": ref("VolumeSpec")}}},
     "responses": {"201": created(ref("Volume"), links_to(VOLUME_OPS)), "409": err("An exemplar is not ready."), **errs("400", "404", "413", "415", "422", "503")}}},
 "/v1/volumes/{id}": {"parameters": [pid()],
   "get": {"operationId": "get_volume", "summary": "One volume.", "responses": {"200": js(ref("Volume")), **errs("404", "503")}},
   "delete": {"operationId": "delete_volume", "summary": "Delete a volume and drop its cache.", "responses": {"204": {"description": "Deleted."}, **errs("404", "503")}}},
 "/v1/volumes/{id}/slice": {"parameters": [pid()],
   "get": {"operationId": "slice", "summary": "Axis-aligned cut: pixel (i, j) is the voxel (u0+i, v0+j, at) of dataset `scale` (the finest voxels by default) for axis z, (at, u0+i, v0+j) for x, (u0+i, at, v0+j) for y. W*H at most --max-voxels (else 422).",
     "parameters": [qp("axis", "x, y or z.", {"type": "string", "enum": ["x", "y", "z"]}, True), qp("at", "Voxel index along the axis.", integer(-MAX_COORD, MAX_COORD), True),
                    qlist("origin", "U,V (default 0,0), each in [-2^28, 2^28 - 2^24].", integer(-MAX_COORD, MAX_ORIGIN), 2),
                    qlist("size", "W,H, each in [1, 2^24].", integer(1, MAX_SIDE), 2, True), scale_param, timeout],
     "description": IMMUTABLE_IMAGE + " " + RANGED,
     "responses": {"200": image_out, **IMAGE_RANGE_OUT, **errs("400", "404", "422", "503", "504")}}},
 "/v1/volumes/{id}/cut": {"parameters": [pid()],
   "post": {"operationId": "cut", "summary": "Arbitrary planar cut: pixel (i, j) is the voxel of dataset `scale` (the finest voxels by default) nearest origin + i*u + j*v, all in that dataset's voxels, or with `resample` cubic their Catmull-Rom resampling around that position (`resample` auto, the default, picks per volume).", "parameters": [scale_param, timeout],
     "requestBody": {"required": True, "content": {"application/json": {"schema": ref("Cut")}}},
     "description": IMMUTABLE_IMAGE,
     "responses": {"200": {**image_out, "headers": {**image_out["headers"], "X-Resample": {"schema": {"type": "string", "enum": ["nearest", "cubic"]}, "description": "How the pixels sampled the voxels (what `resample` auto stood for)."}}},
                   **errs("400", "404", "413", "415", "422", "503", "504")}}},
 "/v1/volumes/{id}/region": {"parameters": [pid()],
   "get": {"operationId": "region", "summary": "A box of voxels; W*H*D at most --max-voxels (else 422). Default: an OpenVDB file with one Vec3s grid 'color' (linear RGB, index space = finest voxels). `Accept: application/octet-stream` gives raw sRGB8 (D x H x W x 3, x fastest), `; dtype=float32` raw linear float32.",
     "parameters": [qlist("min", "X,Y,Z voxel indices, each in [-2^28, 2^28 - 2^24].", integer(-MAX_COORD, MAX_ORIGIN), 3, True),
                    qlist("size", "W,H,D voxels, each in [1, 2^24].", integer(1, MAX_SIDE), 3, True), timeout],
     "description": IMMUTABLE_IMAGE + " " + RANGED,
     "responses": {**IMAGE_RANGE_OUT, "200": {"description": "The voxels.", "headers": {"X-Shape": {"schema": {"type": "string"}}, "X-Dtype": {"schema": {"type": "string"}}, "X-Voxels-Synthesized": {"schema": {"type": "integer"}}, "ETag": STR, "Cache-Control": STR},
                            "content": {"application/x-vdb": {"schema": {"type": "string", "format": "binary"}}, "application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}, **errs("400", "404", "422", "503", "504")}}},
 "/v1/volumes/{id}/points": {"parameters": [pid()],
   "post": {"operationId": "points", "summary": "Colors at world points (each its nearest finest voxel, or with `resample` their Catmull-Rom resampling); at most --max-voxels points (else 422).",
     "parameters": [timeout, qp("resample", "nearest (default): each point's nearest finest voxel. cubic: the Catmull-Rom (tricubic) combination of the 4x4x4 voxels around it, clamped to their range, as plane cuts resample (dense points, such as a bake's texels, share their voxels; scattered ones read up to 64 each): at most 1024^2 points reading at most 8 Mi voxels (else 422 naming points). auto: what the volume's cuts use (cubic when its exemplars carry little 1-pixel detail), nearest past cubic's bounds. The answer's X-Resample says which.", {"type": "string", "enum": ["auto", "nearest", "cubic"], "default": "nearest"})],
     "requestBody": {"required": True, "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary", "minLength": 12, "description": "Little-endian float32 x,y,z per point: a non-empty multiple of 12 bytes, finite, within +-2^28 (else 400)."}}, "application/json": {"schema": ref("PointsRequest")}}},
     "responses": {"200": {"description": "Linear RGB per point: raw little-endian float32 (N x 3, `X-Shape: N,3`) by default, or JSON {\"rgb\": [[r,g,b], ...]} with `Accept: application/json`.",
                            "headers": {"X-Shape": {"schema": {"type": "string"}}, "X-Dtype": {"schema": {"type": "string"}}, "X-Voxels-Synthesized": {"schema": {"type": "integer"}}, "X-Resample": {"schema": {"type": "string", "enum": ["nearest", "cubic"]}}},
                            "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}, "application/json": {"schema": {"type": "object", "properties": {"rgb": {"type": "array", "items": {"type": "array", "items": {"type": "number"}}}}}}}}, **errs("400", "404", "413", "415", "422", "503", "504")}}},
 "/v1/meshes": {
   "get": {"operationId": "list_meshes", "summary": "List meshes.", "responses": {"200": {**js({"type": "object", "properties": {"meshes": {"type": "array", "items": ref("Mesh")}}}), "links": links_to(MESH_OPS, "/meshes/0/id", deletes=False)}, **errs("400")}},
   "post": {"operationId": "upload_mesh", "summary": "Store a mesh: OBJ, PLY (ASCII or binary) or OFF, detected from the bytes (else 415); polygons are fan-triangulated; defects (duplicate faces, holes, non-manifold edges, several components, unreferenced vertices) are tolerated and reported. A mesh without a usable triangle, or with out-of-range indices, is refused (422), as is one above --max-mesh-vertices / --max-mesh-faces.",
     "parameters": [qp("name", "Free-form label, at most 200 characters.", {"type": "string", "maxLength": 200})],
     "requestBody": {"required": True, "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary", "minLength": 1}, "example": MESH_EXAMPLE}}},
     "responses": {"201": created(ref("Mesh"), {**links_to(MESH_OPS),
                                                "field_from_mesh": link("field_from_mesh", None, "A curvature field of this mesh.", {"mesh": "$response.body#/id", "kind": "curvature"})}),
                   **errs("400", "413", "415", "422", "503")}}},
 "/v1/meshes/{id}": {"parameters": [pid()],
   "get": {"operationId": "get_mesh", "summary": "One mesh (summary and defects).", "responses": {"200": js(ref("Mesh")), **errs("404", "503")}},
   "delete": {"operationId": "delete_mesh", "summary": "Delete a mesh.", "responses": {"204": {"description": "Deleted."}, **errs("404", "503")}}},
 "/v1/meshes/{id}/file": {"parameters": [pid()],
   "get": {"operationId": "get_mesh_file", "summary": "The mesh as stored: binary little-endian PLY of the cleaned triangles (positions in mesh coordinates).", "responses": {"200": {"description": "OK", "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}, **errs("404", "503")}}},
 "/v1/volumes/{id}/surface": {"parameters": [pid()],
   "post": {"operationId": "surface", "summary": "Texture a mesh: synthesize only the voxels its vertices need (each vertex takes the color of its nearest finest voxel, exactly what `points` answers at the placed vertex) and return the colored mesh.",
     "description": "Body: a SurfaceRequest (application/json) naming a stored mesh, or the mesh bytes themselves (any other Content-Type) with `resolution`, `margin` and `format` in the query (with a JSON body they are not accepted: 400). Vertices and extra points together at most --max-voxels (else 422). PLY answers are binary little-endian with float x,y,z (mesh coordinates), uchar red, green, blue (sRGB8) per vertex and the triangles; headers X-Target-Voxels, X-Bounding-Voxels, X-Voxels-Synthesized.",
     "parameters": [timeout, qp("resolution", "With a mesh body: voxels along the longest side.", integer(8, 4096, default=512)), qp("margin", "With a mesh body: fraction of the longest side added on every side.", number(0, 1, default=0.25)),
                    qp("format", "With a mesh body: ply or json.", {"type": "string", "enum": ["ply", "json"], "default": "ply"})],
     "requestBody": {"required": True, "content": {"application/json": {"schema": ref("SurfaceRequest")}, "application/octet-stream": {"schema": {"type": "string", "format": "binary", "minLength": 1}, "example": MESH_EXAMPLE}}},
     "responses": {"200": {"description": "The colored mesh.", "headers": {"X-Target-Voxels": {"schema": {"type": "integer"}}, "X-Bounding-Voxels": {"schema": {"type": "integer"}}, "X-Voxels-Synthesized": {"schema": {"type": "integer"}}},
                           "content": {"application/x-ply": {"schema": {"type": "string", "format": "binary"}}, "application/json": {"schema": ref("SurfaceColors")}}}, **errs("400", "404", "413", "415", "422", "503", "504")}}},
 "/v1/fields/from-mesh": {
   "post": {"operationId": "field_from_mesh", "summary": "Solve a frame field from a stored mesh's geometry: principal-curvature frames or crest-line curves as soft constraints (harmonic interpolation, like sketches). The field's domain is the placed mesh's box (world units), so a volume using it should place the mesh the same way. A mesh without usable feature curves is refused (422).", "parameters": [timeout],
     "requestBody": {"required": True, "content": {"application/json": {"schema": ref("FieldFromMesh")}}},
     "responses": {"201": created(ref("Field"), links_to(FIELD_OPS)), **errs("400", "404", "413", "415", "422", "503", "504")}}},
 "/v1/volumes/{id}/zarr/zarr.json": {"parameters": [pid()],
   "get": array_op("zarr_group", "OME-Zarr 0.5 (Zarr v3) group of the volume: `attributes.ome.multiscales` with one dataset per synthesis level (dataset s = synthesis level L-1-s, scale 2^s; levels are synthesis levels, not box filters; region volumes serve the finest only) and inline consolidated metadata. The arrays are [c, z, y, x] uint8 sRGB windows of --array-extent^3 finest voxels from the origin, chunks [3, 32, 32, 32], zstd. Open it with zarr-python: `zarr.open_group(URL, mode='r')`, in Neuroglancer as `zarr3://URL/` (without zarr.json).",
                   ZARR_META, ("400", "404", "503"))},
 "/v1/volumes/{id}/zarr/{scale}/zarr.json": {"parameters": [pid(), ZARR_SCALE],
   "get": array_op("zarr_array", "Zarr v3 array metadata of dataset `scale`.", ZARR_META, ("400", "404", "503"))},
 "/v1/volumes/{id}/zarr/{scale}/c/{c}/{cz}/{cy}/{cx}": {"parameters": [pid(), ZARR_SCALE, *ZARR_CHUNK],
   "get": array_op("zarr_chunk", "One chunk (default chunk-key encoding), synthesized when first asked for: zstd-compressed bytes of a C-order (c, z, y, x) uint8 block, exactly the region endpoint's sRGB voxels of that box at that level. Never 404 for voxels not computed yet; 404 only outside the array.",
                   ZARR_CHUNK_OUT, ("400", "404", "422", "503", "504"))},
 "/v1/volumes/{id}/zarr2/.zgroup": {"parameters": [pid()],
   "get": array_op("zarr2_group", "Zarr v2 group of the volume (OME-Zarr 0.4 mirror of /zarr).", ZARR_META, ("400", "404", "503"))},
 "/v1/volumes/{id}/zarr2/.zattrs": {"parameters": [pid()],
   "get": array_op("zarr2_attributes", "OME-Zarr 0.4 multiscales of the Zarr v2 group.", ZARR_META, ("400", "404", "503"))},
 "/v1/volumes/{id}/zarr2/{scale}/.zarray": {"parameters": [pid(), ZARR_SCALE],
   "get": array_op("zarr2_array", "Zarr v2 array metadata of dataset `scale` (dimension separator '/', compressor zstd).", ZARR_META, ("400", "404", "503"))},
 "/v1/volumes/{id}/zarr2/{scale}/{c}/{cz}/{cy}/{cx}": {"parameters": [pid(), ZARR_SCALE, *ZARR_CHUNK],
   "get": array_op("zarr2_chunk", "One Zarr v2 chunk: the same bytes as the Zarr v3 chunk at the same indices.", ZARR_CHUNK_OUT, ("400", "404", "422", "503", "504"))},
 "/v1/volumes/{id}/precomputed/info": {"parameters": [pid()],
   "get": array_op("precomputed_info", "Neuroglancer precomputed `info` of the volume: one scale per synthesis level (key s = dataset s of /zarr, resolution 2^s), num_channels 3, uint8, raw encoding; chunk sizes 32^3 and the flat 64x64x8, 64x8x64, 8x64x64 for 2-D views. Open in Neuroglancer as `precomputed://URL` (without /info).",
                   ZARR_META, ("400", "404", "503"))},
 "/v1/volumes/{id}/precomputed/{scale}/{chunk}": {"parameters": [pid(), zarr_index("scale", "Scale key (dataset)."), PRECOMPUTED_CHUNK],
   "get": array_op("precomputed_chunk", "One raw chunk: uint8 sRGB, x fastest, channel slowest (the bytes of a C-order (c, z, y, x) Zarr chunk of the same box, uncompressed).",
                   ZARR_CHUNK_OUT, ("400", "404", "422", "503", "504"))},
 "/v1/volumes/{id}/precomputed-jpeg/info": {"parameters": [pid()],
   "get": array_op("precomputed_jpeg_info", "The precomputed `info` of /precomputed with `\"encoding\": \"jpeg\"` in every scale: lossy chunks several times smaller than raw, for viewing over slow links. Open in Neuroglancer as `precomputed://URL` (without /info).",
                   ZARR_META, ("400", "404", "503"))},
 "/v1/volumes/{id}/precomputed-jpeg/{scale}/{chunk}": {"parameters": [pid(), zarr_index("scale", "Scale key (dataset)."), PRECOMPUTED_CHUNK],
   "get": array_op("precomputed_jpeg_chunk", "One jpeg chunk (Neuroglancer's jpeg encoding): a baseline JPEG (quality 90, 4:4:4) of width x and height y*z, the chunk's z slices stacked top to bottom, RGB; the voxels of the raw chunk of the same name up to JPEG loss. Its ETag differs from the raw chunk's.",
                   {**ZARR_CHUNK_OUT, "description": "JPEG bytes; strong ETag, immutable like the raw chunks.", "content": {"image/jpeg": {"schema": {"type": "string", "format": "binary"}}}},
                   ("400", "404", "422", "503", "504"))},
 "/v1/volumes/{id}/stats": {"parameters": [pid()],
   "get": {"operationId": "volume_stats", "summary": "Voxels per level, cache bytes and hits, the loaded state's resident bytes and evictions, the last requests' dependent-set sizes.", "responses": {"200": js(ref("Stats")), **errs("404")}}},
}
doc = {"openapi": "3.1.0", "info": {"title": "solidtex", "version": "1.0.0", "description": "Lazy solid-texture volumes (Zhang et al. 2011). Errors always have the shape {\"error\": {\"code\", \"message\", \"field\"}}. Ids are opaque strings. Synthesis requests run on a bounded worker pool: when its queue is full the answer is 503 with Retry-After. World units are finest-level voxels. Query parameters are strict: an unknown or repeated one is refused (400). Lists in the query are comma-separated (`size=64,64`). The limits that depend on flags of `solidtex serve` are given with their defaults; over them the answer is 422 (413 only for a body over --max-upload-mb). Every GET route also answers HEAD: the same status and headers (Content-Length of the body GET would send), no body."},
       "paths": paths, "components": {"schemas": S}}

if __name__ == "__main__":
    import sys
    target = HERE / "openapi.json"
    text = json.dumps(doc, indent=1)
    if sys.argv[1:] == ["--check"]:
        if target.read_text() != text:
            sys.exit("proto/openapi.json is stale: run python3 proto/openapi.py")
    else:
        target.write_text(text)
