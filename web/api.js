// The solidtex HTTP API as the app uses it (proto/openapi.json): one function per call, JSON in
// and out, raw sRGB8 pixels for cuts. Every failure is an ApiError carrying the server's
// {"error": {code, message, field}}; an aborted request rejects with the AbortError of fetch.

export class ApiError extends Error {
  constructor(status, code, message, field) {
    super(field ? `${field}: ${message}` : message);
    this.status = status;
    this.code = code;
    this.field = field;
  }
}

async function failure(response) {
  let code = "http_" + response.status, message = response.statusText || "request failed", field = "";
  try {
    const body = await response.json();
    if (body && body.error) ({ code, message, field } = body.error);
  } catch (_) {
    // not the documented error body (e.g. a proxy's page): keep the status line
  }
  return new ApiError(response.status, code, message, field);
}

function query(params) {
  const q = new URLSearchParams();
  for (const [k, v] of Object.entries(params || {})) {
    if (v === undefined || v === null || v === "") continue;
    q.set(k, Array.isArray(v) ? v.join(",") : String(v));
  }
  const s = q.toString();
  return s ? "?" + s : "";
}

async function call(method, path, { params, json, body, contentType, accept, signal } = {}) {
  const headers = {};
  if (json !== undefined) {
    headers["Content-Type"] = "application/json";
    body = JSON.stringify(json);
  } else if (body !== undefined) {
    headers["Content-Type"] = contentType || "application/octet-stream";
  }
  if (accept) headers["Accept"] = accept;
  const response = await fetch(path + query(params), { method, headers, body, signal });
  if (!response.ok) throw await failure(response);
  return response;
}

async function callJson(method, path, options) {
  const response = await call(method, path, options);
  return response.status === 204 ? null : response.json();
}

export const listExemplars = () => callJson("GET", "/v1/exemplars").then((j) => j.exemplars);
export const getExemplar = (id) => callJson("GET", `/v1/exemplars/${encodeURIComponent(id)}`);
export const getJob = (id) => callJson("GET", `/v1/jobs/${encodeURIComponent(id)}`);
export const listFields = () => callJson("GET", "/v1/fields").then((j) => j.fields);
export const getField = (id) => callJson("GET", `/v1/fields/${encodeURIComponent(id)}`);
export const listVolumes = () => callJson("GET", "/v1/volumes").then((j) => j.volumes);
export const getVolume = (id) => callJson("GET", `/v1/volumes/${encodeURIComponent(id)}`);
export const listMeshes = () => callJson("GET", "/v1/meshes").then((j) => j.meshes);

// `file`: a Blob (File); `params`: analysis parameters of the query (name, grain, levels, ...).
export const uploadExemplar = (file, params) =>
  callJson("POST", "/v1/exemplars", { params, body: file, contentType: file.type || "application/octet-stream" });

export const createVolume = (spec) => callJson("POST", "/v1/volumes", { json: spec });
export const deleteVolume = (id) => callJson("DELETE", `/v1/volumes/${encodeURIComponent(id)}`);
export const createField = (sketch) => callJson("POST", "/v1/fields", { json: sketch });
export const deleteField = (id) => callJson("DELETE", `/v1/fields/${encodeURIComponent(id)}`);
// `revision` (optional): the field revision the page shows; when the field has moved on (another
// client's curve, or an undo already done) the server answers 409 (ApiError with field
// "revision", its message saying the current revision) and changes nothing.
export const addCurve = (fieldId, curve, revision) =>
  callJson("POST", `/v1/fields/${encodeURIComponent(fieldId)}/curves`, { params: { revision }, json: curve });
export const removeLastCurve = (fieldId, revision) =>
  callJson("DELETE", `/v1/fields/${encodeURIComponent(fieldId)}/curves/last`, { params: { revision } });

let deadline = null;

// The longest deadline this server grants, in seconds (its --max-deadline: the served contract
// states it as the maximum of every `timeout` parameter); undefined when unknown (the server's
// default deadline applies). Cuts and surfaces ask for it: a new cut of a sketched field can
// take minutes on a small machine, and the app cancels whatever it stops showing anyway.
export function maxDeadline() {
  if (!deadline)
    deadline = callJson("GET", "/v1/openapi.json")
      .then((doc) => doc.paths["/v1/volumes/{id}/slice"].get.parameters.find((p) => p.name === "timeout").schema.maximum)
      .catch(() => undefined);
  return deadline;
}

// A cut as raw sRGB8: {width, height, rgb (Uint8Array, row-major RGB), voxels (synthesized by
// this request)}. `request`: {kind: "slice", axis, at, origin, size} or {kind: "cut", origin, u, v,
// size}, in the voxels of dataset `scale`.
export async function cutPixels(volumeId, request, scale, signal) {
  const base = `/v1/volumes/${encodeURIComponent(volumeId)}`;
  const accept = "application/octet-stream";
  const timeout = await maxDeadline();
  const response =
    request.kind === "slice"
      ? await call("GET", base + "/slice", {
          params: { axis: request.axis, at: request.at, origin: request.origin, size: request.size, scale: scale || undefined, timeout },
          accept,
          signal,
        })
      : await call("POST", base + "/cut", {
          params: { scale: scale || undefined, timeout },
          json: { origin: request.origin, u: request.u, v: request.v, size: request.size },
          accept,
          signal,
        });
  const [height, width] = (response.headers.get("X-Shape") || "").split(",").map(Number);
  const rgb = new Uint8Array(await response.arrayBuffer());
  if (!(width > 0 && height > 0) || rgb.length !== width * height * 3)
    throw new ApiError(response.status, "bad_answer", `a ${width}x${height} cut cannot have ${rgb.length} bytes`, "X-Shape");
  return { width, height, rgb, voxels: Number(response.headers.get("X-Voxels-Synthesized") || 0) };
}

// A stored mesh coloured by a volume: the PLY bytes (ArrayBuffer) and the voxels synthesized.
export async function surfacePly(volumeId, meshId, resolution, signal) {
  const response = await call("POST", `/v1/volumes/${encodeURIComponent(volumeId)}/surface`, {
    params: { timeout: await maxDeadline() },
    json: { mesh: meshId, placement: { resolution }, format: "ply" },
    signal,
  });
  return {
    bytes: await response.arrayBuffer(),
    voxels: Number(response.headers.get("X-Voxels-Synthesized") || 0),
    targetVoxels: Number(response.headers.get("X-Target-Voxels") || 0),
  };
}
