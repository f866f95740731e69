// The sketch tool: with it on, a drag on the cut draws a stroke; on release the stroke becomes a
// sketch curve (proto/sketch.schema.json) in world units: its points on the cut's plane,
// `plane_normal` the cut's normal, `axis` the frame axis the user chose to follow it. Strokes
// already added are drawn over the cut wherever they lie in the plane shown.

import { basis, pixelToWorld, worldToPixel } from "./cut_geometry.js";

// Stroke points closer than this (finest pixels) are merged; at most MAX_POINTS are sent.
const MIN_STEP = 1.5;
const MAX_POINTS = 200;

const round2 = (x) => Math.round(x * 100) / 100;

// Resamples a polyline (finest pixel coordinates) at equal arc length, at least `step` apart.
export function resample(points, step) {
  if (points.length < 2) return points.slice();
  const lengths = [0];
  for (let k = 1; k < points.length; ++k)
    lengths.push(lengths[k - 1] + Math.hypot(points[k][0] - points[k - 1][0], points[k][1] - points[k - 1][1]));
  const total = lengths[lengths.length - 1];
  if (total < step) return [points[0], points[points.length - 1]];
  const n = Math.min(MAX_POINTS - 1, Math.max(1, Math.round(total / step)));
  const out = [];
  let k = 1;
  for (let s = 0; s <= n; ++s) {
    const target = (total * s) / n;
    while (k < points.length - 1 && lengths[k] < target) ++k;
    const span = lengths[k] - lengths[k - 1] || 1;
    const t = Math.min(1, Math.max(0, (target - lengths[k - 1]) / span));
    out.push([points[k - 1][0] + t * (points[k][0] - points[k - 1][0]), points[k - 1][1] + t * (points[k][1] - points[k - 1][1])]);
  }
  return out;
}

// The sketch curve of a stroke drawn on `view` (its finest request `fine`); null when the
// stroke is too short to name a direction.
export function strokeToCurve(view, fine, pixelPoints, axis) {
  const step = Math.max(MIN_STEP, fine.size[0] / 48);
  const points = [];
  for (const [fi, fj] of resample(pixelPoints, step)) {
    const p = pixelToWorld(view, fine, fi, fj).map(round2);
    const last = points[points.length - 1];
    if (!last || p.some((c, k) => c !== last[k])) points.push(p);
  }
  if (points.length < 2) return null;
  const curve = { points, plane_normal: basis(view).normal.map((c) => round2(c)) };
  if (axis) curve.axis = axis;
  return curve;
}

export class SketchTool {
  // elements: {stage, overlay}; cutView: the CutView drawn on; axisOf(): the chosen frame axis
  // ("x", "y", "z" or "" for the solver's choice); onCurve(curve) receives each finished stroke.
  constructor(elements, cutView, axisOf, onCurve) {
    this.el = elements;
    this.cutView = cutView;
    this.axisOf = axisOf;
    this.onCurve = onCurve;
    this.enabled = false;
    this.strokes = [];  // curves added, drawn when they lie in the plane shown
    this.live = null;   // the stroke being drawn: finest pixel coordinates
    cutView.onDrawn(() => this.redraw());
    this.installPointer();
  }

  setEnabled(on) {
    this.enabled = on;
    this.cutView.panEnabled = !on;
    this.el.stage.classList.toggle("sketching", on);
  }

  setStrokes(curves) {
    this.strokes = curves.slice();
    this.redraw();
  }

  toPixel(e) {
    const rect = this.el.overlay.getBoundingClientRect();
    const fine = this.cutView.fine;
    return [((e.clientX - rect.left) / rect.width) * fine.size[0], ((e.clientY - rect.top) / rect.height) * fine.size[1]];
  }

  installPointer() {
    const { stage } = this.el;
    let id = null;
    stage.addEventListener("pointerdown", (e) => {
      if (!this.enabled || !this.cutView.fine || e.button !== 0) return;
      id = e.pointerId;
      stage.setPointerCapture(id);
      this.live = [this.toPixel(e)];
      this.redraw();
    });
    stage.addEventListener("pointermove", (e) => {
      if (e.pointerId !== id || !this.live) return;
      this.live.push(this.toPixel(e));
      this.redraw();
    });
    const end = (e) => {
      if (e.pointerId !== id || !this.live) return;
      id = null;
      const stroke = this.live;
      this.live = null;
      const curve = strokeToCurve(this.cutView.view, this.cutView.fine, stroke, this.axisOf());
      this.redraw();
      if (curve) this.onCurve(curve);
    };
    stage.addEventListener("pointerup", end);
    stage.addEventListener("pointercancel", end);
  }

  // The overlay: committed strokes within a voxel of the plane, and the live stroke.
  redraw() {
    const { overlay } = this.el;
    const fine = this.cutView.fine;
    const rect = overlay.getBoundingClientRect();
    const ratio = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(rect.width * ratio)), h = Math.max(1, Math.round(rect.height * ratio));
    if (overlay.width !== w || overlay.height !== h) {
      overlay.width = w;
      overlay.height = h;
    }
    const ctx = overlay.getContext("2d");
    ctx.clearRect(0, 0, w, h);
    if (!fine) return;
    const sx = w / fine.size[0], sy = h / fine.size[1];
    const path = (pixels, color) => {
      if (pixels.length < 2) return;
      ctx.strokeStyle = color;
      ctx.lineWidth = 2 * ratio;
      ctx.lineJoin = ctx.lineCap = "round";
      ctx.beginPath();
      pixels.forEach(([fi, fj], k) => (k ? ctx.lineTo(fi * sx, fj * sy) : ctx.moveTo(fi * sx, fj * sy)));
      ctx.stroke();
    };
    for (const curve of this.strokes) {
      const projected = curve.points.map((p) => worldToPixel(this.cutView.view, fine, p));
      if (projected.every((q) => Math.abs(q.depth) <= 1)) path(projected.map((q) => [q.fi, q.fj]), "rgba(255, 214, 64, 0.85)");
    }
    if (this.live) path(this.live, "rgba(64, 200, 255, 0.95)");
  }
}
