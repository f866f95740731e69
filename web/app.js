// The solidtex browser app (issue #15), served by `solidtex serve` at / from web/: upload and
// analyse exemplars, create volumes, browse cuts coarse to fine, sketch the grain, orbit a
// textured mesh. This module wires the panels to the API; the view itself lives in the URL's
// hash (#volume=…&axis=z&…) so that a reload or a shared link shows the same cut.
//
// Sketching adds curves to a stored field and shows a new volume made with its new revision
// (volumes copy their field, so the one shown before stays as it was). Undo goes back to that
// volume, removes the curve from the field (DELETE /v1/fields/{id}/curves/last) and deletes
// what the stroke created (its volume, and the field when the stroke started it).

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
  levels: new Map(),  // exemplar id -> pyramid levels
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
  for (const e of exemplars) if (e.params && e.params.levels) state.levels.set(e.id, e.params.levels);
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

async function levelsOf(volume) {
  if (volume.label) return 1;  // region volumes serve their finest voxels only
  const id = volume.exemplars[0];
  if (!state.levels.has(id)) state.levels.set(id, (await api.getExemplar(id)).params.levels);
  return state.levels.get(id);
}

// Shows volume `id`; a volume chosen by hand starts a new undo history.
async function showVolume(id, { keepUndo = false } = {}) {
  const volume = await api.getVolume(id);
  const levels = await levelsOf(volume);
  state.volume = volume;
  if (!keepUndo) state.undo = [];
  $("volume-select").value = id;
  updateSketchStatus();
  writeHash();
  syncCutControls();
  await cutView.show(id, levels, state.view);
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

function updateSketchStatus() {
  const v = state.volume;
  const f = v ? v.field : null;
  const field = !f ? "" : f.kind === "stored" ? `field ${f.id} revision ${f.revision}` : `constant field (${v.field_description})`;
  $("sketch-status").textContent = v ? `${v.id}: ${field}` + (f && f.kind !== "stored" ? "; a curve starts a sketch field" : "") : "";
  $("sketch-status").dataset.field = f && f.kind === "stored" ? f.id : "";
  $("sketch-status").dataset.revision = f && f.kind === "stored" ? String(f.revision) : "";
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
      field = await api.addCurve(from.field.id, curve);
    } else {
      const domain = { ...sketchDomain(state.view), shortest_side_cells: SKETCH_FIELD_CELLS };
      field = await api.createField({ domain, curves: [curve] });
      createdField = true;
    }
    const base = (from.name || from.id).replace(/ · sketch r\d+$/, "").slice(0, 150);
    let volume;
    try {
      volume = await api.createVolume({
        name: `${base} · sketch r${field.revision}`,
        exemplar: from.exemplars[0],
        field: { id: field.id },
        seed: from.seed,
        params: from.params,
      });
    } catch (e) {
      // The stroke did not make a volume: take it back out of the field.
      await (createdField ? api.deleteField(field.id) : api.removeLastCurve(field.id)).catch(() => {});
      throw e;
    }
    state.undo.push({ from: from.id, to: volume.id, fieldId: field.id, createdField, curve });
    say(`curve added: field ${field.id} revision ${field.revision} (${plural(field.curves, "curve")}, solved in ${Number(field.seconds || 0).toFixed(2)} s)`, true);
    refreshVolumes().catch(() => {});
    refreshFields().catch(() => {});
    state.sketchBusy = false;
    await showVolume(volume.id, { keepUndo: true });
  } finally {
    state.sketchBusy = false;
    updateSketchStatus();
  }
}

async function undoStroke() {
  const last = state.undo.pop();
  if (!last || state.sketchBusy) return;
  state.sketchBusy = true;
  try {
    const shown = showVolume(last.from, { keepUndo: true });
    const field = last.createdField ? await api.deleteField(last.fieldId) : await api.removeLastCurve(last.fieldId);
    await api.deleteVolume(last.to);
    say(last.createdField ? `undone: deleted the sketch field ${last.fieldId}` : `undone: field ${field.id} revision ${field.revision} (${plural(field.curves, "curve")})`, true);
    refreshVolumes().catch(() => {});
    refreshFields().catch(() => {});
    await shown;
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
