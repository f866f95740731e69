// The solidtex browser app (issue #15), served by `solidtex serve` at / from web/: upload and
// analyse exemplars, create volumes, browse cuts coarse to fine, sketch the grain, orbit a
// textured mesh. This module wires the panels to the API; the view itself lives in the URL's
// hash (#volume=…&axis=z&…) so that a reload or a shared link shows the same cut.
//
// Sketching adds curves to a stored field and shows a new volume made with its new revision
// (volumes copy their field, so the one shown before stays as it was). Undo removes the curve
// from the field (DELETE /v1/fields/{id}/curves/last), deletes what the stroke created (its
// volume, and the field when the stroke started it) and goes back to the volume shown before.
// Both name the field revision the page shows (?revision=): when the field has moved on (another
// page's curve, an undo done elsewhere) the server changes nothing and the page says why.

import * as api from "./api.js";
import { CutView, MAX_SIZE, MIN_SIZE } from "./cut_view.js";
import { depth, sketchDomain, withDepth } from "./cut_geometry.js";
import { MeshView } from "./mesh_view.js";
import { parsePly } from "./ply.js";
import { SketchTool } from "./sketch.js";

const $ = (id) => document.getElementById(id);
const plural = (n, word) => `${n} ${word}${n === 1 ? "" : "s"}`;
const JOB_POLL_MS = 200;
const RENDER_DELAY_MS = 80;
// Cells along a new sketch field's shortest side: coarse enough to solve at once, smooth anyway.
const SKETCH_FIELD_CELLS = 16;

const state = {
  volume: null,       // GET /v1/volumes/{id} of the volume shown
  view: { mode: "axis", axis: "z", center: [128, 128, 0], size: 256, yaw: 30, pitch: 20 },
  undo: [],           // {from, to, fieldId, createdField, curve} per stroke, newest last
  sketchBusy: false,
  levels: new Map(),  // volume id -> datasets of its pyramid (levelsOf)
  revisions: new Map(),  // volume id -> the revision of its stored field known to hold its curves
};

function say(text, ok = false) {
  const m = $("message");
  m.textContent = text;
  m.classList.toggle("ok", ok);
}

// Runs an async UI action, reporting failures in the page (never as unhandled rejections).
function guard(action) {
  return async (...args) => {
    try {
      await action(...args);
    } catch (e) {
      if (e.name !== "AbortError") say(e.message);
    }
  };
}

// ---- the URL hash ------------------------------------------------------------------------

function readHash() {
  const h = new URLSearchParams(location.hash.slice(1));
  const num = (k, fallback) => (h.has(k) && Number.isFinite(Number(h.get(k))) ? Number(h.get(k)) : fallback);
  const v = state.view;
  const size = Math.min(MAX_SIZE, Math.max(MIN_SIZE, Math.round(num("size", v.size))));
  state.view = {
    mode: h.get("mode") === "oblique" ? "oblique" : "axis",
    axis: ["x", "y", "z"].includes(h.get("axis")) ? h.get("axis") : v.axis,
    center: [num("cx", size / 2), num("cy", size / 2), num("cz", 0)],
    size,
    yaw: num("yaw", v.yaw),
    pitch: num("pitch", v.pitch),
  };
  return h.get("volume");
}

function writeHash() {
  const v = state.view;
  const h = new URLSearchParams();
  if (state.volume) h.set("volume", state.volume.id);
  h.set("mode", v.mode);
  h.set("axis", v.axis);
  v.center.forEach((c, k) => h.set(["cx", "cy", "cz"][k], String(Math.round(c * 100) / 100)));
  h.set("size", String(v.size));
  if (v.mode === "oblique") {
    h.set("yaw", String(v.yaw));
    h.set("pitch", String(v.pitch));
  }
  history.replaceState(null, "", "#" + h.toString());
}

// ---- lists -------------------------------------------------------------------------------

function fillSelect(select, items, keep = true) {
  const previous = select.value;
  select.textContent = "";
  for (const [value, label] of items) {
    const o = document.createElement("option");
    o.value = value;
    o.textContent = label;
    select.appendChild(o);
  }
  if (keep && items.some(([v]) => v === previous)) select.value = previous;
}

async function refreshExemplars() {
  const exemplars = await api.listExemplars();
  fillSelect($("volume-exemplar"), exemplars.filter((e) => e.state === "ready").map((e) => [e.id, `${e.name || e.id} (${e.width}×${e.height})`]));
}

async function refreshFields() {
  const fields = await api.listFields();
  fillSelect($("volume-field"), [
    ["identity", "identity"],
    ["spec", "constant (spec)"],
    ...fields.map((f) => [f.id, `${f.id} r${f.revision}, ${plural(f.curves, "curve")}`]),
  ]);
  $("volume-spec-row").hidden = $("volume-field").value !== "spec";
}

async function refreshVolumes() {
  const volumes = await api.listVolumes();
  fillSelect($("volume-select"), volumes.map((v) => [v.id, v.name ? `${v.name} (${v.id})` : v.id]));
  if (state.volume) $("volume-select").value = state.volume.id;
  return volumes;
}

async function refreshMeshes() {
  const meshes = await api.listMeshes();
  fillSelect($("mesh-select"), meshes.map((m) => [m.id, `${m.name || m.id} (${m.vertices} vertices)`]));
}

const refreshAll = () => Promise.all([refreshExemplars(), refreshFields(), refreshVolumes(), refreshMeshes()]);

// ---- the cut -----------------------------------------------------------------------------

const cutView = new CutView(
  { panel: $("cut-panel"), stage: $("cut-stage"), canvas: $("cut-canvas"), status: $("cut-status"), levels: $("cut-levels") },
  (view) => {
    state.view = view;
    syncCutControls();
    writeHash();
  },
);

// The datasets of volume `id`'s pyramid, the scales its cuts accept: the volume's own OME-Zarr
// group (attributes.ome.multiscales[0].datasets: one per synthesis level; region volumes serve
// dataset 0 only). Neither the volume's JSON (proto/openapi.json Volume) nor anything but its
// exemplar's analysis states them, and the volume is all the page may have: it asks no exemplar.
// Volumes never change, so the answer is kept. (Fetched here rather than in api.js, which has no
// call for the Zarr documents.)
async function levelsOf(id) {
  if (!state.levels.has(id)) {
    const response = await fetch(`/v1/volumes/${encodeURIComponent(id)}/zarr/zarr.json`);
    let doc = null;
    try {
      doc = await response.json();
    } catch (_) {
      // not JSON: reported below
    }
    if (!response.ok) {
      const e = doc && doc.error ? doc.error : { code: "http_" + response.status, message: response.statusText || "request failed", field: "" };
      throw new api.ApiError(response.status, e.code, e.message, e.field);
    }
    const datasets = doc && doc.attributes && doc.attributes.ome && doc.attributes.ome.multiscales && doc.attributes.ome.multiscales[0].datasets;
    if (!Array.isArray(datasets) || datasets.length === 0)
      throw new api.ApiError(response.status, "bad_answer", `volume ${id}: its zarr.json lists no datasets`, "");
    state.levels.set(id, datasets.length);
  }
  return state.levels.get(id);
}

// Everything showing volume `id` needs from the server: its JSON and its pyramid's datasets.
async function loadVolume(id) {
  const [volume, levels] = await Promise.all([api.getVolume(id), levelsOf(id)]);
  return { volume, levels };
}

// Shows a loaded volume at once (nothing here can fail) and returns its cut's render, a promise
// settled when the finest cut is drawn or has failed; a volume chosen by hand starts a new undo
// history.
function presentVolume({ volume, levels }, { keepUndo = false } = {}) {
  state.volume = volume;
  if (!keepUndo) state.undo = [];
  $("volume-select").value = volume.id;
  updateSketchStatus();
  writeHash();
  syncCutControls();
  return cutView.show(volume.id, levels, state.view);
}

// Shows volume `id`; settles when its finest cut is drawn.
async function showVolume(id, options) {
  await presentVolume(await loadVolume(id), options);
}

let renderTimer = 0;
function setView(view) {
  state.view = view;
  syncCutControls();
  writeHash();
  clearTimeout(renderTimer);
  if (state.volume) renderTimer = setTimeout(() => cutView.setView(state.view), RENDER_DELAY_MS);
}

function syncCutControls() {
  const v = state.view;
  document.querySelector(`input[name="cut-mode"][value="${v.mode}"]`).checked = true;
  $("cut-axis").value = v.axis;
  $("cut-axis").disabled = v.mode !== "axis";
  $("oblique-controls").hidden = v.mode !== "oblique";
  $("cut-yaw").value = v.yaw;
  $("cut-pitch").value = v.pitch;
  const d = Math.round(depth(v) * 100) / 100;
  const where = v.mode === "axis" ? `${v.axis} = ${d}` : `oblique, yaw ${v.yaw}°, pitch ${v.pitch}°, depth ${d}`;
  $("cut-title").textContent = state.volume ? `${state.volume.name || state.volume.id}: ${where}` : "Cut";
  $("cut-depth").value = d;
  $("cut-depth-value").value = d;
  $("cut-size").textContent = `${v.size}×${v.size} voxels`;
}

for (const radio of document.querySelectorAll('input[name="cut-mode"]'))
  radio.addEventListener("change", () => setView({ ...state.view, mode: radio.value }));
$("cut-axis").addEventListener("change", () => setView({ ...state.view, axis: $("cut-axis").value }));
for (const id of ["cut-depth", "cut-depth-value"])
  $(id).addEventListener("input", () => {
    const value = Number($(id).value);
    if (Number.isFinite(value)) setView(withDepth(state.view, value));
  });
$("cut-yaw").addEventListener("input", () => setView({ ...state.view, yaw: Number($("cut-yaw").value) }));
$("cut-pitch").addEventListener("input", () => setView({ ...state.view, pitch: Number($("cut-pitch").value) }));
$("cut-every-level").addEventListener("change", () => {
  cutView.everyLevel = $("cut-every-level").checked;
  if (state.volume) cutView.render();
});
$("zoom-in").addEventListener("click", () => cutView.zoom(2));
$("zoom-out").addEventListener("click", () => cutView.zoom(0.5));
$("volume-select").addEventListener("change", guard(() => showVolume($("volume-select").value)));

// ---- exemplars and volumes ---------------------------------------------------------------

$("exemplar-upload").addEventListener(
  "click",
  guard(async () => {
    const file = $("exemplar-file").files[0];
    if (!file) throw new Error("choose an image file first");
    const params = {
      name: file.name.slice(0, 200),
      grain: $("exemplar-grain").value,
      levels: $("analysis-levels").value,
      neighborhood: $("analysis-neighborhood").value,
      candidates: $("analysis-candidates").value,
      pca_dims: $("analysis-pca-dims").value,
    };
    const progress = $("analysis-progress"), status = $("analysis-status");
    $("exemplar-upload").disabled = true;
    try {
      const created = await api.uploadExemplar(file, params);
      progress.hidden = false;
      for (;;) {
        const job = await api.getJob(created.job.id);
        progress.value = job.percent;
        status.textContent = `analysing ${file.name}: ${job.state}, ${Math.round(job.percent)}%`;
        if (job.state === "failed") throw new Error(`analysis failed: ${job.error ? job.error.message : "unknown"}`);
        if (job.state === "succeeded") break;
        await new Promise((r) => setTimeout(r, JOB_POLL_MS));
      }
      const exemplar = await api.getExemplar(created.exemplar.id);
      status.textContent = `${exemplar.id} ready: ${exemplar.width}×${exemplar.height}, grain '${exemplar.grain || "none"}', ` +
        `analysed in ${Number(exemplar.seconds || 0).toFixed(1)} s`;
      await refreshExemplars();
      $("volume-exemplar").value = exemplar.id;
    } finally {
      $("exemplar-upload").disabled = false;
    }
  }),
);

$("volume-field").addEventListener("change", () => ($("volume-spec-row").hidden = $("volume-field").value !== "spec"));

$("volume-create").addEventListener(
  "click",
  guard(async () => {
    const exemplar = $("volume-exemplar").value;
    if (!exemplar) throw new Error("no ready exemplar: upload one first");
    const choice = $("volume-field").value;
    const spec = { exemplar, seed: Number($("volume-seed").value) };
    // No field is the identity field.
    if (choice === "spec") spec.field = { spec: $("volume-spec").value.trim() };
    else if (choice !== "identity") spec.field = { id: choice };
    const volume = await api.createVolume(spec);
    await refreshVolumes();
    say(`created ${volume.id} (${volume.field_description})`, true);
    await showVolume(volume.id);
  }),
);

// ---- sketching ---------------------------------------------------------------------------

// The revision of volume `v`'s stored field that a stroke on it (or the undo of the stroke that
// made it) names: the one the volume copied, or, once an undo brought the field back to its
// curves, the revision that undo made (the same curves, bit for bit).
const shownRevision = (v) => (state.revisions.has(v.id) ? state.revisions.get(v.id) : v.field.revision);

function updateSketchStatus() {
  const v = state.volume;
  const f = v ? v.field : null;
  const stored = f && f.kind === "stored";
  const revision = stored ? shownRevision(v) : null;
  const field = !f ? "" : stored
    ? `field ${f.id} revision ${revision}` + (revision !== f.revision ? ` (the curves of revision ${f.revision}, which this volume copied)` : "")
    : `constant field (${v.field_description})`;
  $("sketch-status").textContent = v ? `${v.id}: ${field}` + (f && !stored ? "; a curve starts a sketch field" : "") : "";
  $("sketch-status").dataset.field = stored ? f.id : "";
  $("sketch-status").dataset.revision = stored ? String(revision) : "";
  $("sketch-undo").disabled = state.undo.length === 0 || state.sketchBusy;
  sketch.setStrokes(state.undo.map((u) => u.curve));
}

async function addStroke(curve) {
  const from = state.volume;
  if (!from || state.sketchBusy) return;
  if (from.label) throw new Error("sketching needs a volume of one exemplar (this one has regions)");
  state.sketchBusy = true;
  $("sketch-undo").disabled = true;
  try {
    $("sketch-status").textContent = "solving the field…";
    let field, createdField = false;
    if (from.field.kind === "stored") {
      field = await api.addCurve(from.field.id, curve, shownRevision(from));
    } else {
      const domain = { ...sketchDomain(state.view), shortest_side_cells: SKETCH_FIELD_CELLS };
      field = await api.createField({ domain, curves: [curve] });
      createdField = true;
    }
    const base = (from.name || from.id).replace(/ · sketch r\d+$/, "").slice(0, 150);
    let volume, levels;
    try {
      volume = await api.createVolume({
        name: `${base} · sketch r${field.revision}`,
        exemplar: from.exemplars[0],
        field: { id: field.id },
        seed: from.seed,
        params: from.params,
      });
      levels = await levelsOf(volume.id);
    } catch (e) {
      // The stroke made no volume the page can show: take it back out of the field (unless the
      // field has moved on meanwhile: then the curve last is not this one).
      if (volume) await api.deleteVolume(volume.id).catch(() => {});
      await (createdField ? api.deleteField(field.id) : api.removeLastCurve(field.id, field.revision)).catch(() => {});
      throw e;
    }
    // The new volume is shown (and its entry is on the undo stack) before the page takes the next
    // stroke or undo; its cut may take a while, so they need not wait for that.
    state.undo.push({ from: from.id, to: volume.id, fieldId: field.id, createdField, curve });
    state.revisions.set(volume.id, field.revision);
    say(`curve added: field ${field.id} revision ${field.revision} (${plural(field.curves, "curve")}, solved in ${Number(field.seconds || 0).toFixed(2)} s)`, true);
    refreshVolumes().catch(() => {});
    refreshFields().catch(() => {});
    const drawn = presentVolume({ volume, levels }, { keepUndo: true });
    drawn.catch(() => {});  // awaited below; never an unhandled rejection meanwhile
    state.sketchBusy = false;
    updateSketchStatus();
    await drawn;
  } finally {
    state.sketchBusy = false;
    updateSketchStatus();
  }
}

// Undoes the newest stroke. Its entry stays on the stack, and its volume shown, until the field
// has lost the curve: a failed request changes nothing (the page says why, and undo can be tried
// again). The earlier volume is fetched first, so that once the field has changed nothing can
// keep the page from showing it.
async function undoStroke() {
  const last = state.undo[state.undo.length - 1];
  if (state.sketchBusy || !last) return;
  state.sketchBusy = true;
  updateSketchStatus();
  try {
    const earlier = await loadVolume(last.from);
    // The stroke's volume is the one shown: the curve goes from the revision it holds.
    const field = last.createdField
      ? await api.deleteField(last.fieldId)
      : await api.removeLastCurve(last.fieldId, state.revisions.get(last.to));
    if (!last.createdField) state.revisions.set(last.from, field.revision);
    // Undone. The stroke's volume goes too, unless it is shown outside the undo history (a volume
    // chosen by hand meanwhile starts a new one); a failure to delete it is only reported.
    const inHistory = state.undo.includes(last);
    let kept = "";
    if (inHistory || !state.volume || state.volume.id !== last.to)
      await api.deleteVolume(last.to).then(
        () => (state.levels.delete(last.to), state.revisions.delete(last.to)),
        (e) => (kept = `; its volume ${last.to} was not deleted: ${e.message}`),
      );
    const what = last.createdField ? `deleted the sketch field ${last.fieldId}` : `field ${field.id} revision ${field.revision} (${plural(field.curves, "curve")})`;
    say(`undone: ${what}${kept}`, !kept);
    refreshVolumes().catch(() => {});
    refreshFields().catch(() => {});
    if (!inHistory) return;
    state.undo.splice(state.undo.lastIndexOf(last), 1);
    const drawn = presentVolume(earlier, { keepUndo: true });
    drawn.catch(() => {});  // awaited below; never an unhandled rejection meanwhile
    state.sketchBusy = false;
    updateSketchStatus();
    await drawn;
  } finally {
    state.sketchBusy = false;
    updateSketchStatus();
  }
}

const sketch = new SketchTool(
  { stage: $("cut-stage"), overlay: $("sketch-overlay") },
  cutView,
  () => $("sketch-axis").value,
  guard(addStroke),
);
$("sketch-mode").addEventListener("change", () => sketch.setEnabled($("sketch-mode").checked));
$("sketch-undo").addEventListener("click", guard(undoStroke));

// ---- the mesh ----------------------------------------------------------------------------

let meshView = null;
$("mesh-show").addEventListener(
  "click",
  guard(async () => {
    const meshId = $("mesh-select").value, status = $("mesh-status"), panel = $("mesh-panel");
    if (!meshId) throw new Error("no stored mesh: upload one (POST /v1/meshes)");
    if (!state.volume) throw new Error("no volume shown");
    if (!meshView) meshView = new MeshView($("mesh-canvas"));
    panel.dataset.state = "synthesizing";
    status.textContent = `synthesizing the colours of ${meshId}…`;
    const t0 = performance.now();
    try {
      const answer = await api.surfacePly(state.volume.id, meshId, Number($("mesh-resolution").value));
      const mesh = parsePly(answer.bytes);
      meshView.setMesh(mesh);
      $("mesh-title").textContent = `${$("mesh-select").selectedOptions[0].textContent.replace(/ \(.*/, "")} textured by ${state.volume.name || state.volume.id}`;
      status.textContent = `${mesh.indices.length / 3} triangles, ${answer.targetVoxels.toLocaleString("en")} vertex voxels, ` +
        `${answer.voxels.toLocaleString("en")} voxels synthesized, ${Math.round(performance.now() - t0)} ms`;
      panel.dataset.state = "done";
    } catch (e) {
      panel.dataset.state = "error";
      status.textContent = e.message;
      throw e;
    }
  }),
);

// ---- start -------------------------------------------------------------------------------

async function start() {
  api.maxDeadline();  // fetched while the rest loads: every cut asks for it
  const wanted = readHash();
  syncCutControls();
  const lists = refreshAll().catch((e) => say(e.message));
  if (wanted) {
    await showVolume(wanted);
  } else {
    await lists;
    const first = $("volume-select").value;
    if (first) await showVolume(first);
    else {
      $("volume-new").open = true;
      say("no volume yet: upload an exemplar and create one", true);
    }
  }
  await lists;
}

guard(start)();
