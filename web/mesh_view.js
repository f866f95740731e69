// The mesh panel: a coloured triangle mesh (vertex colours from the surface endpoint) drawn
// with WebGL 2 (written by hand: no library), lit by a head light (Lambert, both faces), and
// orbited by dragging (azimuth, elevation) with the wheel for distance. Draws on demand.

const VERTEX_SHADER = `#version 300 es
in vec3 position;
in vec3 normal;
in vec3 color;
uniform mat4 viewProjection;
uniform mat3 viewRotation;
out vec3 vColor;
out vec3 vNormal;
void main() {
  vColor = color;
  vNormal = viewRotation * normal;
  gl_Position = viewProjection * vec4(position, 1.0);
}`;

const FRAGMENT_SHADER = `#version 300 es
precision highp float;
in vec3 vColor;
in vec3 vNormal;
out vec4 outColor;
void main() {
  // Head light along the view axis; abs() lights back faces too (meshes may be open).
  float lambert = abs(normalize(vNormal).z);
  outColor = vec4(vColor * (0.35 + 0.65 * lambert), 1.0);
}`;

export const BACKGROUND = [0.11, 0.12, 0.14];

function compile(gl, type, source) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error("shader: " + gl.getShaderInfoLog(shader));
  return shader;
}

// Area-weighted vertex normals.
export function vertexNormals(positions, indices) {
  const normals = new Float32Array(positions.length);
  for (let t = 0; t < indices.length; t += 3) {
    const [a, b, c] = [indices[t] * 3, indices[t + 1] * 3, indices[t + 2] * 3];
    const e1 = [0, 1, 2].map((k) => positions[b + k] - positions[a + k]);
    const e2 = [0, 1, 2].map((k) => positions[c + k] - positions[a + k]);
    const n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
    for (const v of [a, b, c]) for (let k = 0; k < 3; ++k) normals[v + k] += n[k];
  }
  for (let v = 0; v < normals.length; v += 3) {
    const l = Math.hypot(normals[v], normals[v + 1], normals[v + 2]) || 1;
    for (let k = 0; k < 3; ++k) normals[v + k] /= l;
  }
  return normals;
}

function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
}

function multiply(a, b) {  // column-major 4x4: a * b
  const out = new Array(16).fill(0);
  for (let c = 0; c < 4; ++c) for (let r = 0; r < 4; ++r) for (let k = 0; k < 4; ++k) out[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return out;
}

export class MeshView {
  constructor(canvas) {
    this.canvas = canvas;
    this.gl = canvas.getContext("webgl2", { antialias: true, preserveDrawingBuffer: true });
    if (!this.gl) throw new Error("WebGL 2 is not available in this browser");
    const gl = this.gl;
    this.program = gl.createProgram();
    gl.attachShader(this.program, compile(gl, gl.VERTEX_SHADER, VERTEX_SHADER));
    gl.attachShader(this.program, compile(gl, gl.FRAGMENT_SHADER, FRAGMENT_SHADER));
    gl.linkProgram(this.program);
    if (!gl.getProgramParameter(this.program, gl.LINK_STATUS)) throw new Error("program: " + gl.getProgramInfoLog(this.program));
    this.mesh = null;
    this.azimuth = 0.6;
    this.elevation = 0.35;
    this.distance = 2.6;
    this.frame = 0;
    this.installPointer();
    this.requestDraw();
  }

  // mesh: parsePly's result. Vertices without colours are drawn light grey.
  setMesh(mesh) {
    const gl = this.gl;
    if (this.vao) gl.deleteVertexArray(this.vao);
    for (const b of this.buffers || []) gl.deleteBuffer(b);
    const { positions, indices } = mesh;
    const colors = new Float32Array(positions.length);
    for (let i = 0; i < colors.length; ++i) colors[i] = mesh.colors ? mesh.colors[i] / 255 : 0.8;
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let v = 0; v < positions.length; v += 3)
      for (let k = 0; k < 3; ++k) {
        lo[k] = Math.min(lo[k], positions[v + k]);
        hi[k] = Math.max(hi[k], positions[v + k]);
      }
    this.center = lo.map((l, k) => (l + hi[k]) / 2);
    this.radius = Math.max(1e-9, Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2);
    this.vao = gl.createVertexArray();
    gl.bindVertexArray(this.vao);
    this.buffers = [];
    const attribute = (name, data) => {
      const buffer = gl.createBuffer();
      this.buffers.push(buffer);
      gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      const location = gl.getAttribLocation(this.program, name);
      gl.enableVertexAttribArray(location);
      gl.vertexAttribPointer(location, 3, gl.FLOAT, false, 0, 0);
    };
    attribute("position", positions);
    attribute("normal", vertexNormals(positions, indices));
    attribute("color", colors);
    const elements = gl.createBuffer();
    this.buffers.push(elements);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, elements);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    this.count = indices.length;
    this.mesh = mesh;
    this.requestDraw();
  }

  requestDraw() {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.draw();
    });
  }

  draw() {
    const gl = this.gl, canvas = this.canvas;
    const ratio = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(canvas.clientWidth * ratio)), h = Math.max(1, Math.round(canvas.clientHeight * ratio));
    if (canvas.width !== w || canvas.height !== h) {
      canvas.width = w;
      canvas.height = h;
    }
    gl.viewport(0, 0, w, h);
    gl.clearColor(...BACKGROUND, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    if (!this.mesh) return;
    // Camera on a sphere around the mesh's centre; z is up.
    const ca = Math.cos(this.azimuth), sa = Math.sin(this.azimuth), ce = Math.cos(this.elevation), se = Math.sin(this.elevation);
    const back = [ce * ca, ce * sa, se];        // from the centre towards the eye
    const right = [-sa, ca, 0];
    const up = [-se * ca, -se * sa, ce];
    const eyeDistance = this.distance * this.radius;
    const eye = this.center.map((c, k) => c + eyeDistance * back[k]);
    const dotEye = (a) => -(a[0] * eye[0] + a[1] * eye[1] + a[2] * eye[2]);
    const view = [right[0], up[0], back[0], 0, right[1], up[1], back[1], 0, right[2], up[2], back[2], 0,
                  dotEye(right), dotEye(up), dotEye(back), 1];
    const near = Math.max(eyeDistance - 2 * this.radius, eyeDistance * 0.01), far = eyeDistance + 2 * this.radius;
    const viewProjection = multiply(perspective(Math.PI / 5, w / h, near, far), view);
    gl.useProgram(this.program);
    gl.uniformMatrix4fv(gl.getUniformLocation(this.program, "viewProjection"), false, new Float32Array(viewProjection));
    gl.uniformMatrix3fv(gl.getUniformLocation(this.program, "viewRotation"), false,
                        new Float32Array([right[0], up[0], back[0], right[1], up[1], back[1], right[2], up[2], back[2]]));
    gl.enable(gl.DEPTH_TEST);
    gl.bindVertexArray(this.vao);
    gl.drawElements(gl.TRIANGLES, this.count, gl.UNSIGNED_INT, 0);
    gl.bindVertexArray(null);
  }

  installPointer() {
    const canvas = this.canvas;
    let drag = null;
    canvas.addEventListener("pointerdown", (e) => {
      drag = { x: e.clientX, y: e.clientY, id: e.pointerId };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener("pointermove", (e) => {
      if (!drag || e.pointerId !== drag.id) return;
      this.azimuth -= (e.clientX - drag.x) * 0.01;
      this.elevation = Math.max(-1.5, Math.min(1.5, this.elevation + (e.clientY - drag.y) * 0.01));
      drag.x = e.clientX;
      drag.y = e.clientY;
      this.requestDraw();
    });
    const end = (e) => {
      if (drag && e.pointerId === drag.id) drag = null;
    };
    canvas.addEventListener("pointerup", end);
    canvas.addEventListener("pointercancel", end);
    canvas.addEventListener(
      "wheel",
      (e) => {
        e.preventDefault();
        this.distance = Math.max(1.2, Math.min(20, this.distance * (e.deltaY < 0 ? 0.9 : 1.1)));
        this.requestDraw();
      },
      { passive: false },
    );
  }
}
