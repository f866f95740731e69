// The cut panel: shows one cut of a volume, its coarsest pyramid dataset first, then the finest
// (exactly the slice or cut endpoint's pixels: the canvas holds one pixel per finest voxel and
// CSS scales it); with everyLevel, every dataset in between too, each replacing the last as it
// arrives. Why not every level by default: a dataset's cut reuses little of the coarser cuts'
// cached voxels (a finer level depends on a wider box of the coarser ones than a coarse cut
// computes), so on 2 cores a new 256² cut of a 3-level volume (a 64² exemplar analysed with
// the tests' small parameters) took 3.9 s alone, ~4.6 s after
// its coarsest preview (0.7 s) and ~7.1 s after every preview. Any change of view cancels the
// requests in flight (the server cancels their synthesis when the connection closes).
// Drag pans (unless a sketch tool takes the pointer), the wheel zooms by powers of two.
//
// State for people and tests: the panel's data-state is "synthesizing", "done" or "error";
// data-scale the dataset shown; the canvas's data-request the finest request (JSON) and
// data-volume its volume once the finest pixels are drawn. Performance marks
// "solidtex:first-cut" (the first pixels of the page's first cut) and "solidtex:cut-done" (each
// finest cut drawn) time what a user waits for.

import { cutPixels } from "./api.js";
import { coverage, finestRequest, panned, scaledRequest } from "./cut_geometry.js";

export const MIN_SIZE = 16;
export const MAX_SIZE = 512;

export class CutView {
  // elements: {panel, stage (the canvas and its overlays: takes the pointer and moves when
  // panned), canvas, status, levels}; onViewChange(view) after pans and zooms.
  constructor(elements, onViewChange) {
    this.el = elements;
    this.onViewChange = onViewChange;
    this.volumeId = null;
    this.scales = 1;
    this.view = null;
    this.fine = null;
    this.controller = null;
    this.generation = 0;
    this.listeners = [];
    this.panEnabled = true;
    this.everyLevel = false;
    this.installPointer();
  }

  // Redraws whenever the finest pixels change (the sketch overlay follows).
  onDrawn(listener) {
    this.listeners.push(listener);
  }

  show(volumeId, scales, view) {
    this.volumeId = volumeId;
    this.scales = Math.max(1, scales);
    this.view = view;
    return this.render();
  }

  setView(view) {
    this.view = view;
    return this.render();
  }

  // Requests the coarsest dataset, then the finest (with everyLevel every one between), drawing
  // each as it arrives.
  async render() {
    if (this.controller) this.controller.abort();
    const controller = new AbortController();
    this.controller = controller;
    const generation = ++this.generation;
    const fine = finestRequest(this.view);
    const { canvas, panel, levels } = this.el;
    if (canvas.width !== fine.size[0] || canvas.height !== fine.size[1]) {
      canvas.width = fine.size[0];
      canvas.height = fine.size[1];
    }
    this.fine = fine;
    canvas.dataset.request = JSON.stringify(fine);
    delete canvas.dataset.volume;
    panel.dataset.state = "synthesizing";
    levels.textContent = "";
    const started = performance.now();
    // The coarsest dataset whose cut is at least 4 pixels a side (smaller shows nothing worth the
    // request), then the finest, or every dataset from the one to the other.
    let coarsest = this.scales - 1;
    while (coarsest > 0 && fine.size[0] / 2 ** coarsest < 4) --coarsest;
    const scales = [];
    for (let s = coarsest; s >= 0; --s) if (s === coarsest || s === 0 || this.everyLevel) scales.push(s);
    let total = 0;
    for (const scale of scales) {
      const request = scaledRequest(fine, scale);
      this.setStatus(`synthesizing… dataset ${scale} (${request.size[0]}×${request.size[1]} voxels, 2^${scale} finest wide)`);
      const t0 = performance.now();
      let answer;
      try {
        answer = await cutPixels(this.volumeId, request, scale, controller.signal);
      } catch (e) {
        if (generation !== this.generation || e.name === "AbortError") return;
        panel.dataset.state = "error";
        this.setStatus(`dataset ${scale}: ${e.message}`);
        return;
      }
      if (generation !== this.generation) return;
      this.draw(fine, request, scale, answer);
      if (performance.getEntriesByName("solidtex:first-cut").length === 0) performance.mark("solidtex:first-cut");
      total += answer.voxels;
      panel.dataset.scale = String(scale);
      const row = document.createElement("li");
      row.textContent =
        `dataset ${scale}: ${answer.width}×${answer.height} px, ` +
        `${answer.voxels.toLocaleString("en")} voxels synthesized, ${Math.round(performance.now() - t0)} ms`;
      levels.appendChild(row);
    }
    canvas.dataset.volume = this.volumeId;
    panel.dataset.state = "done";
    performance.mark("solidtex:cut-done");
    this.setStatus(
      `${fine.size[0]}×${fine.size[1]} cut: ${total.toLocaleString("en")} voxels synthesized in ` +
        `${Math.round(performance.now() - started)} ms` + (total === 0 ? " (all cached)" : ""),
    );
  }

  // The answer of dataset `scale`, each of its pixels covering 2^scale finest pixels a side.
  draw(fine, request, scale, answer) {
    const { canvas } = this.el;
    const ctx = canvas.getContext("2d");
    const w = fine.size[0], h = fine.size[1];
    const image = ctx.createImageData(w, h);
    const cols = scale === 0 ? null : coverage(fine, request, scale, 0);
    const rows = scale === 0 ? null : coverage(fine, request, scale, 1);
    const out = image.data, rgb = answer.rgb, aw = answer.width;
    for (let j = 0; j < h; ++j) {
      const sj = rows ? rows[j] : j;
      for (let i = 0; i < w; ++i) {
        const si = cols ? cols[i] : i;
        const s = (sj * aw + si) * 3, d = (j * w + i) * 4;
        out[d] = rgb[s];
        out[d + 1] = rgb[s + 1];
        out[d + 2] = rgb[s + 2];
        out[d + 3] = 255;
      }
    }
    ctx.putImageData(image, 0, 0);
    for (const listener of this.listeners) listener();
  }

  setStatus(text) {
    this.el.status.textContent = text;
  }

  // Finest pixels per CSS pixel of the canvas as shown.
  pixelsPerCssPixel() {
    return this.fine.size[0] / this.el.canvas.getBoundingClientRect().width;
  }

  zoom(factor) {
    const size = Math.min(MAX_SIZE, Math.max(MIN_SIZE, Math.round(this.view.size / factor)));
    if (size === this.view.size) return;
    this.view = { ...this.view, size };
    this.onViewChange(this.view);
    this.render();
  }

  installPointer() {
    const { stage, canvas } = this.el;
    let drag = null;
    stage.addEventListener("pointerdown", (e) => {
      if (!this.panEnabled || !this.view || e.button !== 0) return;
      drag = { x: e.clientX, y: e.clientY, id: e.pointerId };
      stage.setPointerCapture(e.pointerId);
    });
    stage.addEventListener("pointermove", (e) => {
      if (!drag || e.pointerId !== drag.id) return;
      stage.style.transform = `translate(${e.clientX - drag.x}px, ${e.clientY - drag.y}px)`;
    });
    const end = (e) => {
      if (!drag || e.pointerId !== drag.id) return;
      const scale = this.pixelsPerCssPixel();
      const di = Math.round((drag.x - e.clientX) * scale), dj = Math.round((drag.y - e.clientY) * scale);
      drag = null;
      stage.style.transform = "";
      if (di === 0 && dj === 0) return;
      // Keep the pixels already shown where the pan put them until the new cut arrives.
      const ctx = canvas.getContext("2d");
      const copy = ctx.getImageData(0, 0, canvas.width, canvas.height);
      ctx.fillStyle = "#000";
      ctx.fillRect(0, 0, canvas.width, canvas.height);
      ctx.putImageData(copy, -di, -dj);
      this.view = panned(this.view, di, dj);
      this.onViewChange(this.view);
      this.render();
    };
    stage.addEventListener("pointerup", end);
    stage.addEventListener("pointercancel", end);
    stage.addEventListener(
      "wheel",
      (e) => {
        if (!this.view) return;
        e.preventDefault();
        this.zoom(e.deltaY < 0 ? 2 : 0.5);
      },
      { passive: false },
    );
  }
}
