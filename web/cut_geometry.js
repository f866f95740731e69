// Where a view looks, in world units (one unit = one finest voxel): the cut request of each
// pyramid dataset, how a coarse answer covers the finest pixels, and which world point a pixel
// of the view shows. Pure functions of a view:
//   {mode: "axis" | "oblique", axis: "x" | "y" | "z", center: [x, y, z], size: N (finest voxels
//    per side of the square cut), yaw, pitch (degrees, oblique mode)}.
// Axis cuts follow the slice endpoint: pixel (i, j) of axis z is voxel (u0+i, v0+j, at), of axis
// x (at, u0+i, v0+j), of axis y (u0+i, at, v0+j). Oblique cuts follow the cut endpoint: pixel
// (i, j) is the voxel nearest origin + i*u + j*v. Dataset s (the `scale` query parameter) has
// voxels 2^s finest voxels wide: voxel c covers finest voxels [c*2^s, (c+1)*2^s).

const AXES = { x: 0, y: 1, z: 2 };
// The world axes of a cut's pixel columns (u) and rows (v), per cut axis.
const IN_PLANE = { z: [0, 1], x: [1, 2], y: [0, 2] };

export function inPlaneAxes(axis) {
  return IN_PLANE[axis];
}

function unit(i) {
  const e = [0, 0, 0];
  e[i] = 1;
  return e;
}

const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

// The plane's unit normal and in-plane steps u (columns), v (rows).
export function basis(view) {
  if (view.mode === "axis") {
    const [a, b] = IN_PLANE[view.axis];
    return { normal: unit(AXES[view.axis]), u: unit(a), v: unit(b) };
  }
  const yaw = (view.yaw * Math.PI) / 180, pitch = (view.pitch * Math.PI) / 180;
  const normal = [Math.cos(pitch) * Math.cos(yaw), Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch)];
  const u = [-Math.sin(yaw), Math.cos(yaw), 0];
  return { normal, u, v: cross(normal, u) };
}

// The finest cut: an axis slice with integer origin, or an oblique cut centred on view.center.
export function finestRequest(view) {
  const n = view.size;
  if (view.mode === "axis") {
    const [a, b] = IN_PLANE[view.axis];
    const at = Math.round(view.center[AXES[view.axis]]);
    const origin = [Math.round(view.center[a]) - n / 2, Math.round(view.center[b]) - n / 2].map(Math.floor);
    return { kind: "slice", axis: view.axis, at, origin, size: [n, n] };
  }
  const { u, v } = basis(view);
  const origin = [0, 1, 2].map((k) => view.center[k] - (n / 2) * u[k] - (n / 2) * v[k]);
  return { kind: "cut", origin, u, v, size: [n, n] };
}

// The request for dataset `scale` covering the finest request `fine`.
export function scaledRequest(fine, scale) {
  if (scale === 0) return fine;
  const k = 2 ** scale;
  if (fine.kind === "slice") {
    const lo = fine.origin.map((o) => Math.floor(o / k));
    const hi = fine.origin.map((o, i) => Math.floor((o + fine.size[i] - 1) / k));
    return { kind: "slice", axis: fine.axis, at: Math.floor(fine.at / k), origin: lo, size: [hi[0] - lo[0] + 1, hi[1] - lo[1] + 1] };
  }
  return {
    kind: "cut",
    origin: fine.origin.map((o) => o / k),
    u: fine.u,
    v: fine.v,
    size: fine.size.map((s) => Math.ceil(s / k)),
  };
}

// For each finest pixel column (or row) i, the index of the coarse answer's column covering it.
export function coverage(fine, coarse, scale, dim) {
  const k = 2 ** scale, n = fine.size[dim];
  const out = new Int32Array(n);
  for (let i = 0; i < n; ++i) {
    out[i] =
      fine.kind === "slice"
        ? Math.floor((fine.origin[dim] + i) / k) - coarse.origin[dim]
        : Math.min(coarse.size[dim] - 1, Math.round(i / k));
  }
  return out;
}

// The world point shown at continuous pixel coordinates (fi, fj) of the finest cut, where pixel
// (i, j) spans [i, i+1) x [j, j+1) and its voxel's centre is at (i + 0.5, j + 0.5).
export function pixelToWorld(view, fine, fi, fj) {
  const { u, v } = basis(view);
  const base =
    fine.kind === "slice"
      ? (() => {
          const p = [0, 0, 0];
          const [a, b] = IN_PLANE[fine.axis];
          p[AXES[fine.axis]] = fine.at;
          p[a] = fine.origin[0];
          p[b] = fine.origin[1];
          return p;
        })()
      : fine.origin;
  return [0, 1, 2].map((k) => base[k] + (fi - 0.5) * u[k] + (fj - 0.5) * v[k]);
}

// Continuous pixel coordinates of a world point in the finest cut, and its distance from the plane.
export function worldToPixel(view, fine, p) {
  const { normal, u, v } = basis(view);
  const origin = pixelToWorld(view, fine, 0.5, 0.5);
  const d = [0, 1, 2].map((k) => p[k] - origin[k]);
  return { fi: dot(d, u) + 0.5, fj: dot(d, v) + 0.5, depth: dot(d, normal) };
}

// The position along the normal the depth slider shows: the axis coordinate, or centre . normal.
export function depth(view) {
  return view.mode === "axis" ? Math.round(view.center[AXES[view.axis]]) : dot(view.center, basis(view).normal);
}

export function withDepth(view, value) {
  const { normal } = basis(view);
  const shift = value - dot(view.center, normal);
  return { ...view, center: view.center.map((c, k) => c + shift * normal[k]) };
}

// The view moved by (di, dj) finest pixels along u and v.
export function panned(view, di, dj) {
  const { u, v } = basis(view);
  return { ...view, center: view.center.map((c, k) => c + di * u[k] + dj * v[k]) };
}

// A box around the view (world units) for a new sketch field: twice the view across the plane,
// the view's side along the normal, so that strokes drawn near this view stay inside it.
export function sketchDomain(view) {
  const { normal, u, v } = basis(view);
  const n = view.size;
  const half = [0, 1, 2].map((k) => n * (Math.abs(u[k]) + Math.abs(v[k])) + (n / 2) * Math.abs(normal[k]));
  return { min: view.center.map((c, k) => Math.floor(c - half[k])), max: view.center.map((c, k) => Math.ceil(c + half[k])) };
}
