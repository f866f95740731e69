#!/usr/bin/env python3
"""Source of the API contract: writes proto/openapi.json (served at GET /v1/openapi.json).

Edit this file, run `python3 proto/openapi.py`, commit both. `--check` fails when the JSON is
stale (a ctest runs it); server/routes_test.cpp checks the routes against the JSON.
"""
import json
def ref(n): return {"$ref": f"#/components/schemas/{n}"}
def err(desc): return {"description": desc, "content": {"application/json": {"schema": ref("Error")}}}
def js(schema, desc="OK"): return {"description": desc, "content": {"application/json": {"schema": schema}}}
def qp(name, desc, schema=None, required=False):
    return {"name": name, "in": "query", "required": required, "description": desc, "schema": schema or {"type": "string"}}
def pid(desc="Opaque id."): return {"name": "id", "in": "path", "required": True, "description": desc, "schema": {"type": "string"}}
timeout = qp("timeout", "Deadline in seconds for this request, (0, server max]; default: the server's --deadline (30 s). Past it the synthesis is cancelled and the answer is 504.", {"type": "number"})
E = {"400": err("Malformed request: bad JSON, unknown key or query parameter, value out of range; `field` names it."),
     "404": err("No such resource."), "405": err("Method not allowed on this path."),
     "413": err("Body larger than the upload limit."), "415": err("Unsupported Content-Type or image format."),
     "422": err("Well-formed but unusable: image too large in pixels (checked from its header), corrupt image, too many voxels."),
     "429": err("Too many concurrent analysis jobs."), "503": err("Worker queue full (see Retry-After) or shutting down."),
     "504": err("The request's deadline passed; the work was cancelled.")}
def errs(*codes): return {c: E[c] for c in codes}
image_out = {"description": "The cut. PNG (8-bit sRGB) by default; with `Accept: application/octet-stream` raw sRGB8 bytes (H x W x 3, row-major) and with `Accept: application/octet-stream; dtype=float32` raw little-endian float32 linear RGB; raw answers carry `X-Shape: H,W,3` and `X-Dtype`.",
    "headers": {"X-Shape": {"schema": {"type": "string"}}, "X-Dtype": {"schema": {"type": "string"}}, "X-Voxels-Synthesized": {"schema": {"type": "integer"}, "description": "Voxels this request synthesized over all levels (0 when everything was cached)."}},
    "content": {"image/png": {"schema": {"type": "string", "format": "binary"}}, "application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}
analysis_params = [
    qp("name", "Free-form label.", {"type": "string"}),
    qp("levels", "Pyramid levels L.", {"type": "integer", "minimum": 1, "maximum": 8, "default": 4}),
    qp("neighborhood", "Template size N (odd).", {"type": "integer", "minimum": 3, "maximum": 15, "default": 9}),
    qp("candidates", "Candidate triples per pixel N_T.", {"type": "integer", "minimum": 1, "maximum": 32, "default": 12}),
    qp("pca_dims", "Appearance-space dimensions per plane.", {"type": "integer", "minimum": 1, "maximum": 64, "default": 20}),
    qp("seed", "Seeds the k-NN trees.", {"type": "integer", "minimum": 0, "default": 1}),
    qp("plane_weights", "Suggested plane weights 'A,B,C' stored with the table.", {"type": "string"}),
    qp("grain", "'x': the exemplar's stripes run along its x axis and the solid's grain along world x: xy = E, zx = E transposed, yz = E with suggested weight 0.1 (as `solidtex analyze --grain x`).", {"type": "string", "enum": ["x"]}),
    qp("mask_weight", "Weight of the feature-mask channel relative to color.", {"type": "number", "minimum": 0, "maximum": 10, "default": 1}),
]
S = {
 "Error": {"type": "object", "required": ["error"], "properties": {"error": {"type": "object", "required": ["code", "message", "field"], "properties": {
     "code": {"type": "string", "description": "Machine-readable: invalid_argument, not_found, unsupported, too_large, corrupt, unprocessable, version_mismatch, cancelled, deadline_exceeded, resource_exhausted, rate_limited, already_exists, failed_precondition, method_not_allowed, internal, io."},
     "message": {"type": "string"}, "field": {"type": "string", "description": "The input the error is about (body, a JSON path, a query parameter); may be empty."}}}}},
 "Job": {"type": "object", "required": ["id", "kind", "state", "percent"], "properties": {
     "id": {"type": "string"}, "kind": {"type": "string", "enum": ["analysis"]}, "exemplar_id": {"type": "string"},
     "state": {"type": "string", "enum": ["queued", "running", "succeeded", "failed"]},
     "percent": {"type": "number", "minimum": 0, "maximum": 100}, "seconds": {"type": "number"},
     "error": {"description": "null unless failed", "oneOf": [{"type": "null"}, {"type": "object"}]}}},
 "LevelReport": {"type": "object", "properties": {"level": {"type": "integer"}, "spacing": {"type": "integer"}, "mean_crossbar_error": {"type": "number"}, "random_crossbar_error": {"type": "number"}, "coherent_fraction": {"type": "number"}}},
 "Exemplar": {"type": "object", "required": ["id", "state"], "properties": {
     "id": {"type": "string"}, "name": {"type": "string"}, "state": {"type": "string", "enum": ["analyzing", "ready", "failed"]},
     "job_id": {"type": "string"}, "grain": {"type": "string"}, "seconds": {"type": "number"}, "planes": {"type": "integer", "enum": [1, 3]}, "has_mask": {"type": "boolean"},
     "width": {"type": "integer"}, "height": {"type": "integer"}, "params": {"type": "object"},
     "levels": {"type": "array", "items": ref("LevelReport")}, "table_bytes": {"type": "integer"},
     "error": {"oneOf": [{"type": "null"}, {"type": "object"}]}}},
 "ExemplarCreated": {"type": "object", "required": ["exemplar", "job"], "properties": {"exemplar": ref("Exemplar"), "job": ref("Job")}},
 "Field": {"type": "object", "required": ["id", "revision"], "properties": {
     "id": {"type": "string"}, "revision": {"type": "integer", "description": "1 at creation, +1 per added curve."},
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
     "seed": {"type": "integer"}, "params": {"type": "object"}}},
 "Cut": {"type": "object", "additionalProperties": False, "required": ["origin", "u", "v", "size"], "properties": {
     "origin": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3, "description": "World units (finest voxels)."},
     "u": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3, "description": "Step per output column, voxel units."},
     "v": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3, "description": "Step per output row, voxel units."},
     "size": {"type": "array", "items": {"type": "integer"}, "minItems": 2, "maxItems": 2, "description": "W, H."}}},
 "Mesh": {"type": "object", "required": ["id"], "properties": {
     "id": {"type": "string"}, "name": {"type": "string"}, "format": {"type": "string", "enum": ["ply", "obj", "off"]},
     "vertices": {"type": "integer", "description": "Every vertex position of the file, unreferenced ones included (they get colors too); OBJ texture coordinates and normals are ignored."}, "triangles": {"type": "integer", "description": "After fan triangulation of polygons and removal of duplicate and degenerate faces."},
     "bounds": {"type": "object", "properties": {"min": {"type": "array", "items": {"type": "number"}}, "max": {"type": "array", "items": {"type": "number"}}}},
     "defects": {"type": "object", "description": "What the reader tolerated: duplicate_faces and degenerate_faces (dropped), unreferenced_vertices, boundary_edges (holes), non_manifold_edges, components.",
                 "properties": {k: {"type": "integer"} for k in ["duplicate_faces", "degenerate_faces", "unreferenced_vertices", "boundary_edges", "non_manifold_edges", "components", "polygons_triangulated"]}}}},
 "Placement": {"type": "object", "additionalProperties": False, "description": "Mesh coordinates to world (finest-voxel) coordinates: world = scale * mesh + translate. Omitted: fit the mesh's bounding box, enlarged by `margin` on every side, to `resolution` voxels along its longest side, with the box's minimum corner at the origin.",
     "properties": {"resolution": {"type": "integer", "minimum": 8, "maximum": 4096, "default": 512}, "margin": {"type": "number", "minimum": 0, "maximum": 1, "default": 0.25, "description": "Fraction of the longest side added on every side (the paper enlarges by 20-30%)."},
                    "scale": {"type": "number", "exclusiveMinimum": 0}, "translate": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}}},
 "SurfaceRequest": {"type": "object", "additionalProperties": False, "required": ["mesh"], "properties": {
     "mesh": {"type": "string", "description": "Id of a stored mesh."},
     "placement": ref("Placement"),
     "format": {"type": "string", "enum": ["ply", "json"], "default": "ply"},
     "points": {"type": "array", "description": "Extra surface points (mesh coordinates) to color as well (JSON format only).", "items": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}}}},
 "SurfaceColors": {"type": "object", "properties": {
     "vertices": {"type": "integer"}, "colors": {"type": "array", "description": "Linear RGB per vertex (float).", "items": {"type": "array", "items": {"type": "number"}}},
     "point_colors": {"type": "array", "items": {"type": "array", "items": {"type": "number"}}},
     "placement": {"type": "object", "properties": {"scale": {"type": "number"}, "translate": {"type": "array", "items": {"type": "number"}}}},
     "stats": {"type": "object", "description": "target_voxels (distinct finest voxels the surface needs), bounding_voxels (voxels of the placed mesh's bounding box), fraction (synthesized voxels over all levels / bounding_voxels), voxels_synthesized, levels (per-level dependent-set sizes)."}}},
 "FieldFromMesh": {"type": "object", "additionalProperties": False, "required": ["mesh", "kind"], "properties": {
     "mesh": {"type": "string"}, "kind": {"type": "string", "enum": ["curvature", "features"], "description": "curvature: principal-curvature frames at surface vertices (Gorla et al.), x along the direction of least curvature, y along the normal; features: crest lines (edges whose dihedral angle exceeds feature_angle_degrees, chained) and any user `curves`, used as sketch curves with x along the curve."},
     "placement": ref("Placement"),
     "shortest_side_cells": {"type": "integer", "minimum": 2, "maximum": 256, "default": 24},
     "max_constraints": {"type": "integer", "minimum": 1, "maximum": 20000, "default": 2000, "description": "curvature: at most this many vertex frames: one per occupied cube of the field's grid spacing (the cube grows by 25% until the budget holds), so usually fewer."},
     "feature_angle_degrees": {"type": "number", "minimum": 1, "maximum": 179, "default": 60},
     "curves": {"type": "array", "description": "features: user polylines on the surface (mesh coordinates); normals are taken from the nearest vertices.", "items": {"type": "array", "items": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}}}}},
 "Stats": {"type": "object", "properties": {"volume": {"type": "string"}, "levels": {"type": "array", "items": {"type": "object", "properties": {"level": {"type": "integer"}, "voxels_synthesized": {"type": "integer"}, "cached_voxels": {"type": "integer"}}}},
     "cache": {"type": "object", "properties": {"bytes": {"type": "integer"}, "budget_bytes": {"type": "integer"}, "hits": {"type": "integer"}, "misses": {"type": "integer"}, "bricks": {"type": "integer"}, "evicted_bricks": {"type": "integer"}}},
     "requests": {"type": "integer"}, "recent": {"type": "array", "description": "The last requests (newest last): kind, target voxels and dependent-set sizes per level.", "items": {"type": "object"}}}},
}
paths = {
 "/healthz": {"get": {"operationId": "healthz", "summary": "Liveness.", "responses": {"200": js({"type": "object"})}}},
 "/metrics": {"get": {"operationId": "metrics", "summary": "Prometheus text: requests and latency histograms per route, voxels synthesized, cache bytes, queue depth.", "responses": {"200": {"description": "OK", "content": {"text/plain": {"schema": {"type": "string"}}}}}}},
 "/v1/openapi.json": {"get": {"operationId": "openapi", "summary": "This document.", "responses": {"200": js({"type": "object"})}}},
 "/v1/exemplars": {
   "get": {"operationId": "list_exemplars", "summary": "List exemplars.", "responses": {"200": js({"type": "object", "properties": {"exemplars": {"type": "array", "items": ref("Exemplar")}}})}},
   "post": {"operationId": "upload_exemplar", "summary": "Upload an exemplar; its analysis runs in the background.",
     "description": "Body: the image bytes (any Content-Type but multipart/form-data and application/json), or multipart/form-data with parts `xy` (or `image`), optional `yz` and `zx` (all three or only one), and optional `mask` (with three planes also `mask_yz` and `mask_zx`). PNG, JPEG, TIFF, OpenEXR; gray/RGB/RGBA, 8/16-bit or float. Analysis parameters in the query. The upload is stored before the answer, so an acknowledged upload survives a restart (its analysis is re-run).",
     "parameters": analysis_params,
     "requestBody": {"required": True, "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}, "multipart/form-data": {"schema": {"type": "object", "properties": {"xy": {"type": "string", "format": "binary"}, "yz": {"type": "string", "format": "binary"}, "zx": {"type": "string", "format": "binary"}, "mask": {"type": "string", "format": "binary"}, "mask_yz": {"type": "string", "format": "binary"}, "mask_zx": {"type": "string", "format": "binary"}}}}}},
     "responses": {"202": {"description": "Accepted; poll the job.", "headers": {"Location": {"schema": {"type": "string"}}}, "content": {"application/json": {"schema": ref("ExemplarCreated")}}}, **errs("400", "413", "415", "422", "429", "503")}}},
 "/v1/exemplars/{id}": {"parameters": [pid()],
   "get": {"operationId": "get_exemplar", "summary": "One exemplar.", "responses": {"200": js(ref("Exemplar")), **errs("404")}},
   "delete": {"operationId": "delete_exemplar", "summary": "Delete an exemplar not used by any volume.", "responses": {"204": {"description": "Deleted."}, "409": err("A volume uses it, or its analysis is still running."), **errs("404")}}},
 "/v1/exemplars/{id}/table": {"parameters": [pid()],
   "get": {"operationId": "get_exemplar_table", "summary": "The .stx candidate-triple table (the same bytes `solidtex analyze` writes for the same inputs).", "responses": {"200": {"description": "OK", "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}, "409": err("Not ready."), **errs("404")}}},
 "/v1/jobs/{id}": {"parameters": [pid()],
   "get": {"operationId": "get_job", "summary": "State and progress of a background job.", "responses": {"200": js(ref("Job")), **errs("404")}}},
 "/v1/fields": {
   "get": {"operationId": "list_fields", "summary": "List fields.", "responses": {"200": js({"type": "object", "properties": {"fields": {"type": "array", "items": ref("Field")}}})}},
   "post": {"operationId": "create_field", "summary": "Solve a frame field from a sketch (schema: sketch.schema.json).", "parameters": [timeout],
     "requestBody": {"required": True, "content": {"application/json": {"schema": {"$ref": "sketch.schema.json"}}}},
     "responses": {"201": {"description": "Created.", "headers": {"Location": {"schema": {"type": "string"}}}, "content": {"application/json": {"schema": ref("Field")}}}, **errs("400", "413", "415", "422", "503", "504")}}},
 "/v1/fields/{id}": {"parameters": [pid()],
   "get": {"operationId": "get_field", "summary": "One field.", "responses": {"200": js(ref("Field")), **errs("404")}},
   "delete": {"operationId": "delete_field", "summary": "Delete a field (volumes keep their own copies).", "responses": {"204": {"description": "Deleted."}, **errs("404")}}},
 "/v1/fields/{id}/file": {"parameters": [pid()],
   "get": {"operationId": "get_field_file", "summary": "The .stf field file of the current revision (usable with `solidtex slice --field`).", "responses": {"200": {"description": "OK", "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}, **errs("404")}}},
 "/v1/fields/{id}/curves": {"parameters": [pid()],
   "post": {"operationId": "add_curve", "summary": "Add one curve (a sketch curve object) and re-solve incrementally; the revision increases.", "parameters": [timeout],
     "requestBody": {"required": True, "content": {"application/json": {"schema": {"$ref": "sketch.schema.json#/$defs/curve"}}}},
     "responses": {"200": js(ref("Field")), **errs("400", "404", "413", "415", "503", "504")}}},
 "/v1/fields/{id}/frames": {"parameters": [pid()],
   "get": {"operationId": "sample_frames", "summary": "Frames on a regular grid of points, for display.",
     "parameters": [qp("min", "X,Y,Z world units.", required=True), qp("size", "Points per axis NX,NY,NZ (product <= 65536).", required=True), qp("step", "World units between points (default 1).", {"type": "number"})],
     "responses": {"200": js(ref("Frames")), **errs("400", "404", "422")}}},
 "/v1/volumes": {
   "get": {"operationId": "list_volumes", "summary": "List volumes.", "responses": {"200": js({"type": "object", "properties": {"volumes": {"type": "array", "items": ref("Volume")}}})}},
   "post": {"operationId": "create_volume", "summary": "Create a volume from ready exemplars, a field and synthesis parameters (schema: volume.schema.json).",
     "requestBody": {"required": True, "content": {"application/json": {"schema": {"$ref": "volume.schema.json"}}}},
     "responses": {"201": {"description": "Created.", "headers": {"Location": {"schema": {"type": "string"}}}, "content": {"application/json": {"schema": ref("Volume")}}}, "409": err("An exemplar is not ready."), **errs("400", "404", "413", "415")}}},
 "/v1/volumes/{id}": {"parameters": [pid()],
   "get": {"operationId": "get_volume", "summary": "One volume.", "responses": {"200": js(ref("Volume")), **errs("404")}},
   "delete": {"operationId": "delete_volume", "summary": "Delete a volume and drop its cache.", "responses": {"204": {"description": "Deleted."}, **errs("404")}}},
 "/v1/volumes/{id}/slice": {"parameters": [pid()],
   "get": {"operationId": "slice", "summary": "Axis-aligned cut: pixel (i, j) is finest voxel (u0+i, v0+j, at) for axis z, (at, u0+i, v0+j) for x, (u0+i, at, v0+j) for y.",
     "parameters": [qp("axis", "x, y or z.", {"type": "string", "enum": ["x", "y", "z"]}, True), qp("at", "Voxel index along the axis.", {"type": "integer"}, True),
                    qp("origin", "U,V (default 0,0).", {"type": "string"}), qp("size", "W,H.", {"type": "string"}, True), timeout],
     "responses": {"200": image_out, **errs("400", "404", "422", "503", "504")}}},
 "/v1/volumes/{id}/cut": {"parameters": [pid()],
   "post": {"operationId": "cut", "summary": "Arbitrary planar cut: pixel (i, j) is the voxel nearest origin + i*u + j*v.", "parameters": [timeout],
     "requestBody": {"required": True, "content": {"application/json": {"schema": ref("Cut")}}},
     "responses": {"200": image_out, **errs("400", "404", "413", "415", "422", "503", "504")}}},
 "/v1/volumes/{id}/region": {"parameters": [pid()],
   "get": {"operationId": "region", "summary": "A box of voxels. Default: an OpenVDB file with one Vec3s grid 'color' (linear RGB, index space = finest voxels). `Accept: application/octet-stream` gives raw sRGB8 (D x H x W x 3, x fastest), `; dtype=float32` raw linear float32.",
     "parameters": [qp("min", "X,Y,Z voxel indices.", {"type": "string"}, True), qp("size", "W,H,D voxels.", {"type": "string"}, True), timeout],
     "responses": {"200": {"description": "The voxels.", "headers": {"X-Shape": {"schema": {"type": "string"}}, "X-Dtype": {"schema": {"type": "string"}}},
                            "content": {"application/x-vdb": {"schema": {"type": "string", "format": "binary"}}, "application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}, **errs("400", "404", "422", "503", "504")}}},
 "/v1/volumes/{id}/points": {"parameters": [pid()],
   "post": {"operationId": "points", "summary": "Colors at world points (each rounded to its nearest finest voxel).", "parameters": [timeout],
     "requestBody": {"required": True, "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary", "description": "Little-endian float32 x,y,z per point."}}, "application/json": {"schema": {"type": "object", "additionalProperties": False, "required": ["points"], "properties": {"points": {"type": "array", "items": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}}}}}}},
     "responses": {"200": {"description": "Linear RGB per point: raw little-endian float32 (N x 3, `X-Shape: N,3`) by default, or JSON {\"rgb\": [[r,g,b], ...]} with `Accept: application/json`.",
                            "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}, "application/json": {"schema": {"type": "object", "properties": {"rgb": {"type": "array"}}}}}}, **errs("400", "404", "413", "415", "422", "503", "504")}}},
 "/v1/meshes": {
   "get": {"operationId": "list_meshes", "summary": "List meshes.", "responses": {"200": js({"type": "object", "properties": {"meshes": {"type": "array", "items": ref("Mesh")}}})}},
   "post": {"operationId": "upload_mesh", "summary": "Store a mesh: OBJ, PLY (ASCII or binary) or OFF, detected from the bytes; polygons are fan-triangulated; defects (duplicate faces, holes, non-manifold edges, several components, unreferenced vertices) are tolerated and reported.",
     "parameters": [qp("name", "Free-form label.")], "requestBody": {"required": True, "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}},
     "responses": {"201": {"description": "Created.", "headers": {"Location": {"schema": {"type": "string"}}}, "content": {"application/json": {"schema": ref("Mesh")}}}, **errs("400", "413", "415", "422", "503")}}},
 "/v1/meshes/{id}": {"parameters": [pid()],
   "get": {"operationId": "get_mesh", "summary": "One mesh (summary and defects).", "responses": {"200": js(ref("Mesh")), **errs("404")}},
   "delete": {"operationId": "delete_mesh", "summary": "Delete a mesh.", "responses": {"204": {"description": "Deleted."}, **errs("404")}}},
 "/v1/meshes/{id}/file": {"parameters": [pid()],
   "get": {"operationId": "get_mesh_file", "summary": "The mesh as stored: binary little-endian PLY of the cleaned triangles (positions in mesh coordinates).", "responses": {"200": {"description": "OK", "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}, **errs("404")}}},
 "/v1/volumes/{id}/surface": {"parameters": [pid()],
   "post": {"operationId": "surface", "summary": "Texture a mesh: synthesize only the voxels its vertices need (each vertex takes the color of its nearest finest voxel, exactly what `points` answers at the placed vertex) and return the colored mesh.",
     "description": "Body: a SurfaceRequest (application/json) naming a stored mesh, or the mesh bytes themselves (any other Content-Type) with `resolution`, `margin` and `format` in the query. PLY answers are binary little-endian with float x,y,z (mesh coordinates), uchar red, green, blue (sRGB8) per vertex and the triangles; headers X-Target-Voxels, X-Bounding-Voxels, X-Voxels-Synthesized.",
     "parameters": [timeout, qp("resolution", "With a mesh body: voxels along the longest side.", {"type": "integer"}), qp("margin", "With a mesh body.", {"type": "number"}), qp("format", "With a mesh body: ply or json.", {"type": "string"})],
     "requestBody": {"required": True, "content": {"application/json": {"schema": ref("SurfaceRequest")}, "application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}},
     "responses": {"200": {"description": "The colored mesh.", "content": {"application/x-ply": {"schema": {"type": "string", "format": "binary"}}, "application/json": {"schema": ref("SurfaceColors")}}}, **errs("400", "404", "413", "415", "422", "503", "504")}}},
 "/v1/fields/from-mesh": {
   "post": {"operationId": "field_from_mesh", "summary": "Solve a frame field from a stored mesh's geometry: principal-curvature frames or crest-line curves as soft constraints (harmonic interpolation, like sketches). The field's domain is the placed mesh's box (world units), so a volume using it should place the mesh the same way.", "parameters": [timeout],
     "requestBody": {"required": True, "content": {"application/json": {"schema": ref("FieldFromMesh")}}},
     "responses": {"201": {"description": "Created.", "headers": {"Location": {"schema": {"type": "string"}}}, "content": {"application/json": {"schema": ref("Field")}}}, **errs("400", "404", "415", "422", "503", "504")}}},
 "/v1/volumes/{id}/stats": {"parameters": [pid()],
   "get": {"operationId": "volume_stats", "summary": "Voxels per level, cache bytes and hits, the last requests' dependent-set sizes.", "responses": {"200": js(ref("Stats")), **errs("404")}}},
}
doc = {"openapi": "3.0.3", "info": {"title": "solidtex", "version": "1.0.0", "description": "Lazy solid-texture volumes (Zhang et al. 2011). Errors always have the shape {\"error\": {\"code\", \"message\", \"field\"}}. Ids are opaque strings. Synthesis requests run on a bounded worker pool: when its queue is full the answer is 503 with Retry-After. World units are finest-level voxels."},
       "paths": paths, "components": {"schemas": S}}

if __name__ == "__main__":
    import pathlib, sys
    target = pathlib.Path(__file__).with_name("openapi.json")
    text = json.dumps(doc, indent=1)
    if sys.argv[1:] == ["--check"]:
        if target.read_text() != text:
            sys.exit("proto/openapi.json is stale: run python3 proto/openapi.py")
    else:
        target.write_text(text)
