// Reads the PLY files the service writes (GET /v1/meshes/{id}/file, POST .../surface): binary
// little-endian (and ASCII, for hand-made files), a `vertex` element with x, y, z and optional
// red, green, blue, a `face` element with a vertex index list (polygons are fan-triangulated).
// Returns {positions: Float32Array (3 per vertex), colors: Uint8Array (3 per vertex) or null,
// indices: Uint32Array (3 per triangle)}; throws Error naming what is wrong.

const SIZES = {
  char: 1, int8: 1, uchar: 1, uint8: 1, short: 2, int16: 2, ushort: 2, uint16: 2,
  int: 4, int32: 4, uint: 4, uint32: 4, float: 4, float32: 4, double: 8, float64: 8,
};

function reader(view, type) {
  switch (type) {
    case "char": case "int8": return (o) => view.getInt8(o);
    case "uchar": case "uint8": return (o) => view.getUint8(o);
    case "short": case "int16": return (o) => view.getInt16(o, true);
    case "ushort": case "uint16": return (o) => view.getUint16(o, true);
    case "int": case "int32": return (o) => view.getInt32(o, true);
    case "uint": case "uint32": return (o) => view.getUint32(o, true);
    case "float": case "float32": return (o) => view.getFloat32(o, true);
    case "double": case "float64": return (o) => view.getFloat64(o, true);
  }
  throw new Error(`PLY: unknown property type '${type}'`);
}

function parseHeader(bytes) {
  const text = new TextDecoder("latin1").decode(bytes.subarray(0, Math.min(bytes.length, 65536)));
  const end = text.indexOf("end_header");
  if (!text.startsWith("ply") || end < 0) throw new Error("PLY: no 'ply ... end_header' header");
  const bodyStart = text.indexOf("\n", end) + 1;
  let format = null;
  const elements = [];
  for (const line of text.slice(0, end).split(/\r?\n/)) {
    const w = line.trim().split(/\s+/);
    if (w[0] === "format") format = w[1];
    else if (w[0] === "element") elements.push({ name: w[1], count: Number(w[2]), props: [] });
    else if (w[0] === "property") {
      const el = elements[elements.length - 1];
      if (!el) throw new Error("PLY: a property before any element");
      if (w[1] === "list") el.props.push({ name: w[4], list: true, countType: w[2], type: w[3] });
      else el.props.push({ name: w[2], list: false, type: w[1] });
    }
  }
  if (format !== "binary_little_endian" && format !== "ascii") throw new Error(`PLY: unsupported format '${format}'`);
  for (const el of elements)
    for (const p of el.props) {
      if (!(p.type in SIZES) || (p.list && !(p.countType in SIZES))) throw new Error(`PLY: unknown type in property '${p.name}'`);
    }
  return { format, elements, bodyStart };
}

export function parsePly(buffer) {
  const bytes = new Uint8Array(buffer);
  const { format, elements, bodyStart } = parseHeader(bytes);
  const vertexEl = elements.find((e) => e.name === "vertex");
  const faceEl = elements.find((e) => e.name === "face");
  if (!vertexEl || !faceEl) throw new Error("PLY: needs vertex and face elements");
  const nv = vertexEl.count;
  const positions = new Float32Array(nv * 3);
  const hasColor = ["red", "green", "blue"].every((c) => vertexEl.props.some((p) => p.name === c));
  const colors = hasColor ? new Uint8Array(nv * 3) : null;
  const triangles = [];
  const slot = { x: 0, y: 1, z: 2, red: 0, green: 1, blue: 2 };

  // Each element instance as {name: value or array}, read in file order.
  let next;
  if (format === "ascii") {
    const words = new TextDecoder("latin1").decode(bytes.subarray(bodyStart)).split(/\s+/).filter((w) => w.length);
    let k = 0;
    next = (props) => {
      const out = {};
      for (const p of props) {
        if (p.list) {
          const n = Number(words[k++]);
          out[p.name] = words.slice(k, k + n).map(Number);
          k += n;
        } else out[p.name] = Number(words[k++]);
      }
      if (k > words.length) throw new Error("PLY: the body ends early");
      return out;
    };
  } else {
    const view = new DataView(buffer);
    let offset = bodyStart;
    next = (props) => {
      const out = {};
      for (const p of props) {
        if (p.list) {
          const n = reader(view, p.countType)(offset);
          offset += SIZES[p.countType];
          const read = reader(view, p.type), size = SIZES[p.type];
          if (offset + n * size > buffer.byteLength) throw new Error("PLY: the body ends early");
          const values = new Array(n);
          for (let i = 0; i < n; ++i) values[i] = read(offset + i * size);
          offset += n * size;
          out[p.name] = values;
        } else {
          if (offset + SIZES[p.type] > buffer.byteLength) throw new Error("PLY: the body ends early");
          out[p.name] = reader(view, p.type)(offset);
          offset += SIZES[p.type];
        }
      }
      return out;
    };
  }

  for (const el of elements) {
    for (let i = 0; i < el.count; ++i) {
      const v = next(el.props);
      if (el === vertexEl) {
        for (const c of ["x", "y", "z"]) positions[i * 3 + slot[c]] = v[c];
        if (colors) for (const c of ["red", "green", "blue"]) colors[i * 3 + slot[c]] = v[c];
      } else if (el === faceEl) {
        const list = v.vertex_indices || v.vertex_index;
        if (!list) throw new Error("PLY: faces have no vertex_indices");
        for (let k = 1; k + 1 < list.length; ++k) {
          for (const idx of [list[0], list[k], list[k + 1]])
            if (!(idx >= 0 && idx < nv)) throw new Error(`PLY: face ${i} names vertex ${idx} of ${nv}`);
          triangles.push(list[0], list[k], list[k + 1]);
        }
      }
    }
  }
  return { positions, colors, indices: Uint32Array.from(triangles) };
}
