// Readers for decode_mesh (mesh.h): PLY, OFF, OBJ, then one cleaning pass for all formats.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <string_view>
#include <unordered_map>

#include "mesh/mesh.h"

namespace solidtex {
namespace {

Status corrupt(const std::string& what, const std::string& msg) { return Status(StatusCode::kUnprocessable, msg, what); }

// Raw faces before cleaning: polygon vertex lists.
struct RawMesh {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::vector<int64_t>> faces;
};

// Splits text into whitespace-separated tokens line by line.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}
  // Next non-empty line without comments starting with '#' (when `hash_comments`).
  bool next(std::vector<std::string_view>& tokens, bool hash_comments = true) {
    while (pos_ < text_.size()) {
      size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      std::string_view line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_no_;
      if (hash_comments) line = line.substr(0, line.find('#'));
      tokens.clear();
      size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        size_t j = i;
        while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
        if (j > i) tokens.push_back(line.substr(i, j - i));
        i = j;
      }
      if (!tokens.empty()) return true;
    }
    return false;
  }
  int line() const { return line_no_; }
  size_t position() const { return pos_; }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  int line_no_ = 0;
};

bool to_double(std::string_view s, double& v) {
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}
// A count or index read as a floating-point PLY value: integral, finite and within [0, 2^62].
bool as_count(double x, int64_t& out) {
  if (!(x >= 0 && x <= 4.6e18) || x != std::floor(x)) return false;
  out = int64_t(x);
  return true;
}

bool to_int(std::string_view s, int64_t& v) {
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

Status check_vertex(const std::array<double, 3>& v, const std::string& where) {
  for (double c : v)
    if (!std::isfinite(c)) return corrupt(where, "has a non-finite coordinate");
  return Status::ok();
}

// ---- OFF --------------------------------------------------------------------------------
Result<RawMesh> read_off(std::string_view text, const MeshLimits& limits) {
  LineReader in(text);
  std::vector<std::string_view> t;
  if (!in.next(t)) return corrupt("mesh", "OFF: empty");
  // "OFF" may share its line with the counts.
  size_t first = 1;
  if (t[0].size() > 3 && t[0].substr(t[0].size() - 3) == "OFF") first = 1;
  if (t.size() <= first) {
    if (!in.next(t)) return corrupt("mesh", "OFF: missing the counts line");
    first = 0;
  }
  int64_t nv = 0, nf = 0;
  if (t.size() < first + 2 || !to_int(t[first], nv) || !to_int(t[first + 1], nf) || nv < 0 || nf < 0)
    return corrupt("mesh", "OFF: the counts line must be 'vertices faces edges'");
  if (nv > limits.max_vertices) return corrupt("mesh.vertices", "OFF declares " + std::to_string(nv) + " vertices; the limit is " + std::to_string(limits.max_vertices));
  if (nf > limits.max_faces) return corrupt("mesh.faces", "OFF declares " + std::to_string(nf) + " faces; the limit is " + std::to_string(limits.max_faces));
  if (nv + nf > int64_t(text.size())) return corrupt("mesh", "OFF declares more elements than the file can hold (truncated?)");
  RawMesh m;
  m.vertices.reserve(size_t(nv));
  for (int64_t i = 0; i < nv; ++i) {
    const std::string where = "vertex " + std::to_string(i);
    if (!in.next(t)) return corrupt(where, "OFF ends before all vertices (truncated)");
    std::array<double, 3> v{};
    if (t.size() < 3 || !to_double(t[0], v[0]) || !to_double(t[1], v[1]) || !to_double(t[2], v[2]))
      return corrupt(where, "line " + std::to_string(in.line()) + ": expected x y z");
    SOLIDTEX_RETURN_IF_ERROR(check_vertex(v, where));
    m.vertices.push_back(v);
  }
  m.faces.reserve(size_t(nf));
  for (int64_t i = 0; i < nf; ++i) {
    const std::string where = "face " + std::to_string(i);
    if (!in.next(t)) return corrupt(where, "OFF ends before all faces (truncated)");
    int64_t k = 0;
    if (!to_int(t[0], k) || k < 3 || k > int64_t(t.size()) - 1)
      return corrupt(where, "line " + std::to_string(in.line()) + ": expected a count >= 3 and that many indices");
    std::vector<int64_t> f(static_cast<size_t>(k));
    for (int64_t j = 0; j < k; ++j)
      if (!to_int(t[size_t(j + 1)], f[size_t(j)])) return corrupt(where, "line " + std::to_string(in.line()) + ": bad index");
    m.faces.push_back(std::move(f));
  }
  return m;
}

// ---- OBJ --------------------------------------------------------------------------------
Result<RawMesh> read_obj(std::string_view text, const MeshLimits& limits) {
  LineReader in(text);
  std::vector<std::string_view> t;
  RawMesh m;
  while (in.next(t)) {
    if (t[0] == "v") {
      const std::string where = "vertex " + std::to_string(m.vertices.size());
      std::array<double, 3> v{};
      if (t.size() < 4 || !to_double(t[1], v[0]) || !to_double(t[2], v[1]) || !to_double(t[3], v[2]))
        return corrupt(where, "line " + std::to_string(in.line()) + ": expected 'v x y z'");
      SOLIDTEX_RETURN_IF_ERROR(check_vertex(v, where));
      if (int64_t(m.vertices.size()) >= limits.max_vertices)
        return corrupt("mesh.vertices", "more than " + std::to_string(limits.max_vertices) + " vertices");
      m.vertices.push_back(v);
    } else if (t[0] == "f") {
      const std::string where = "face " + std::to_string(m.faces.size());
      if (t.size() < 4) return corrupt(where, "line " + std::to_string(in.line()) + ": a face needs at least 3 vertices");
      std::vector<int64_t> f;
      for (size_t j = 1; j < t.size(); ++j) {
        int64_t idx = 0;
        if (!to_int(t[j].substr(0, t[j].find('/')), idx) || idx == 0)
          return corrupt(where, "line " + std::to_string(in.line()) + ": bad vertex reference '" + std::string(t[j]) + "'");
        // OBJ indices are 1-based; negative ones count back from the last vertex read.
        f.push_back(idx > 0 ? idx - 1 : int64_t(m.vertices.size()) + idx);
      }
      if (int64_t(m.faces.size()) >= limits.max_faces)
        return corrupt("mesh.faces", "more than " + std::to_string(limits.max_faces) + " faces");
      m.faces.push_back(std::move(f));
    }
    // vt, vn, g, o, s, usemtl, mtllib: not needed.
  }
  return m;
}

// ---- PLY --------------------------------------------------------------------------------
enum class PlyType { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64, kNone };

PlyType ply_type(std::string_view s) {
  if (s == "char" || s == "int8") return PlyType::kI8;
  if (s == "uchar" || s == "uint8") return PlyType::kU8;
  if (s == "short" || s == "int16") return PlyType::kI16;
  if (s == "ushort" || s == "uint16") return PlyType::kU16;
  if (s == "int" || s == "int32") return PlyType::kI32;
  if (s == "uint" || s == "uint32") return PlyType::kU32;
  if (s == "float" || s == "float32") return PlyType::kF32;
  if (s == "double" || s == "float64") return PlyType::kF64;
  return PlyType::kNone;
}
size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::kI8: case PlyType::kU8: return 1;
    case PlyType::kI16: case PlyType::kU16: return 2;
    case PlyType::kI32: case PlyType::kU32: case PlyType::kF32: return 4;
    case PlyType::kF64: return 8;
    case PlyType::kNone: return 0;
  }
  return 0;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kNone;
  PlyType count_type = PlyType::kNone;  // lists only
  bool list = false;
};
struct PlyElement {
  std::string name;
  int64_t count = 0;
  std::vector<PlyProperty> props;
};

class BinaryCursor {
 public:
  BinaryCursor(std::span<const uint8_t> d, size_t pos, bool big) : d_(d), pos_(pos), big_(big) {}
  bool read(PlyType t, double& out) {
    const size_t n = ply_size(t);
    if (pos_ + n > d_.size()) return false;
    uint8_t b[8];
    for (size_t i = 0; i < n; ++i) b[i] = d_[pos_ + (big_ ? n - 1 - i : i)];
    pos_ += n;
    switch (t) {
      case PlyType::kI8: out = int8_t(b[0]); break;
      case PlyType::kU8: out = b[0]; break;
      case PlyType::kI16: { int16_t v; std::memcpy(&v, b, 2); out = v; break; }
      case PlyType::kU16: { uint16_t v; std::memcpy(&v, b, 2); out = v; break; }
      case PlyType::kI32: { int32_t v; std::memcpy(&v, b, 4); out = v; break; }
      case PlyType::kU32: { uint32_t v; std::memcpy(&v, b, 4); out = v; break; }
      case PlyType::kF32: { float v; std::memcpy(&v, b, 4); out = v; break; }
      case PlyType::kF64: { double v; std::memcpy(&v, b, 8); out = v; break; }
      case PlyType::kNone: return false;
    }
    return true;
  }
  size_t remaining() const { return d_.size() - pos_; }

 private:
  std::span<const uint8_t> d_;
  size_t pos_;
  bool big_;
};

Result<RawMesh> read_ply(std::span<const uint8_t> bytes, const MeshLimits& limits) {
  const std::string_view all(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const size_t header_end = all.find("end_header");
  if (header_end == std::string_view::npos) return corrupt("mesh", "PLY: no end_header");
  size_t body = all.find('\n', header_end);
  if (body == std::string_view::npos) return corrupt("mesh", "PLY: nothing after end_header");
  ++body;
  LineReader header(all.substr(0, header_end));
  std::vector<std::string_view> t;
  std::string format;
  std::vector<PlyElement> elements;
  while (header.next(t, false)) {
    if (t[0] == "format" && t.size() >= 2) format = std::string(t[1]);
    else if (t[0] == "element" && t.size() >= 3) {
      PlyElement e;
      e.name = std::string(t[1]);
      if (!to_int(t[2], e.count) || e.count < 0) return corrupt("mesh", "PLY: bad element count '" + std::string(t[2]) + "'");
      elements.push_back(e);
    } else if (t[0] == "property" && t.size() >= 3) {
      if (elements.empty()) return corrupt("mesh", "PLY: a property before any element");
      PlyProperty p;
      if (t[1] == "list" && t.size() >= 5) {
        p.list = true;
        p.count_type = ply_type(t[2]);
        p.type = ply_type(t[3]);
        p.name = std::string(t[4]);
      } else {
        p.type = ply_type(t[1]);
        p.name = std::string(t[2]);
      }
      if (p.type == PlyType::kNone || (p.list && p.count_type == PlyType::kNone))
        return corrupt("mesh", "PLY: unknown property type in '" + std::string(t[1]) + "'");
      elements.back().props.push_back(p);
    }
  }
  const bool ascii = format == "ascii";
  const bool big = format == "binary_big_endian";
  if (!ascii && !big && format != "binary_little_endian") return Status(StatusCode::kUnsupported, "PLY format '" + format + "' is not supported", "mesh");
  RawMesh m;
  bool have_vertices = false, have_faces = false;
  LineReader text(all.substr(body));
  BinaryCursor bin(bytes, body, big);
  for (const PlyElement& e : elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    if (is_vertex && e.count > limits.max_vertices)
      return corrupt("mesh.vertices", "PLY declares " + std::to_string(e.count) + " vertices; the limit is " + std::to_string(limits.max_vertices));
    if (is_face && e.count > limits.max_faces)
      return corrupt("mesh.faces", "PLY declares " + std::to_string(e.count) + " faces; the limit is " + std::to_string(limits.max_faces));
    // Every element needs at least one byte (binary) or one line (ASCII): reject impossible counts before allocating.
    if (e.count > int64_t(bytes.size())) return corrupt("mesh", "PLY declares " + std::to_string(e.count) + " " + e.name + " elements but the file has " + std::to_string(bytes.size()) + " bytes (truncated?)");
    int xyz[3] = {-1, -1, -1}, indices = -1;
    for (size_t k = 0; k < e.props.size(); ++k) {
      const auto& p = e.props[k];
      if (is_vertex && !p.list && (p.name == "x" || p.name == "y" || p.name == "z")) xyz[p.name[0] - 'x'] = int(k);
      if (is_face && p.list && (p.name == "vertex_indices" || p.name == "vertex_index")) indices = int(k);
    }
    if (is_vertex) {
      if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0) return corrupt("mesh", "PLY: vertex element without x, y, z");
      m.vertices.reserve(size_t(e.count));
      have_vertices = true;
    }
    if (is_face) {
      if (indices < 0) return corrupt("mesh", "PLY: face element without vertex_indices");
      m.faces.reserve(size_t(e.count));
      have_faces = true;
    }
    for (int64_t i = 0; i < e.count; ++i) {
      const std::string where = e.name + " " + std::to_string(i);
      std::array<double, 3> v{};
      std::vector<int64_t> f;
      if (ascii) {
        if (!text.next(t, false)) return corrupt(where, "PLY ends early (truncated)");
        size_t tok = 0;
        for (size_t k = 0; k < e.props.size(); ++k) {
          const auto& p = e.props[k];
          double val = 0;
          if (tok >= t.size() || !to_double(t[tok++], val)) return corrupt(where, "PLY: bad or missing value");
          if (p.list) {
            int64_t n = 0;
            if (!as_count(val, n) || n > int64_t(t.size() - tok)) return corrupt(where, "PLY: bad list length");
            for (int64_t j = 0; j < n; ++j) {
              double x = 0;
              if (!to_double(t[tok++], x)) return corrupt(where, "PLY: bad list value");
              int64_t index = 0;
              if (int(k) == indices) {
                if (!as_count(x, index)) return corrupt(where, "PLY: a vertex index is not a non-negative integer");
                f.push_back(index);
              }
            }
          } else if (is_vertex) {
            for (int a = 0; a < 3; ++a)
              if (int(k) == xyz[a]) v[size_t(a)] = val;
          }
        }
      } else {
        for (size_t k = 0; k < e.props.size(); ++k) {
          const auto& p = e.props[k];
          double val = 0;
          if (!bin.read(p.list ? p.count_type : p.type, val)) return corrupt(where, "PLY ends early (truncated)");
          if (p.list) {
            int64_t n = 0;
            if (!as_count(val, n) || n > int64_t(bin.remaining() / ply_size(p.type)))
              return corrupt(where, "PLY: bad list length (truncated?)");
            for (int64_t j = 0; j < n; ++j) {
              double x = 0;
              bin.read(p.type, x);
              int64_t index = 0;
              if (int(k) == indices) {
                if (!as_count(x, index)) return corrupt(where, "PLY: a vertex index is not a non-negative integer");
                f.push_back(index);
              }
            }
          } else if (is_vertex) {
            for (int a = 0; a < 3; ++a)
              if (int(k) == xyz[a]) v[size_t(a)] = val;
          }
        }
      }
      if (is_vertex) {
        SOLIDTEX_RETURN_IF_ERROR(check_vertex(v, where));
        m.vertices.push_back(v);
      }
      if (is_face) {
        if (f.size() < 3) return corrupt(where, "a face needs at least 3 vertices");
        m.faces.push_back(std::move(f));
      }
    }
  }
  if (!have_vertices) return corrupt("mesh", "PLY without a vertex element");
  if (!have_faces) return corrupt("mesh", "PLY without a face element (point clouds are not meshes)");
  return m;
}

// ---- cleaning ---------------------------------------------------------------------------
Result<Mesh> clean(RawMesh raw, std::string format) {
  Mesh m;
  m.format = std::move(format);
  const int64_t nv = int64_t(raw.vertices.size());
  if (nv == 0) return corrupt("mesh", "has no vertices");
  if (raw.faces.empty()) return corrupt("mesh", "has no faces");
  std::vector<std::array<int32_t, 3>> keys;
  std::map<std::array<int32_t, 3>, int> seen;
  for (size_t i = 0; i < raw.faces.size(); ++i) {
    const auto& f = raw.faces[i];
    for (int64_t idx : f)
      if (idx < 0 || idx >= nv)
        return corrupt("face " + std::to_string(i), "refers to vertex " + std::to_string(idx) + " but the mesh has " + std::to_string(nv) + " vertices");
    if (f.size() > 3) ++m.defects.polygons_triangulated;
    for (size_t j = 1; j + 1 < f.size(); ++j) {
      const std::array<int32_t, 3> tri{int32_t(f[0]), int32_t(f[j]), int32_t(f[j + 1])};
      if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
        ++m.defects.degenerate_faces;
        continue;
      }
      std::array<int32_t, 3> key = tri;
      std::sort(key.begin(), key.end());
      if (!seen.emplace(key, 1).second) {
        ++m.defects.duplicate_faces;
        continue;
      }
      m.triangles.push_back(tri);
    }
  }
  if (m.triangles.empty()) return corrupt("mesh", "has no usable triangle (all degenerate)");
  m.vertices = std::move(raw.vertices);
  // Edges: boundary (1 triangle) and non-manifold (3+).
  std::unordered_map<uint64_t, int> edge_count;
  edge_count.reserve(m.triangles.size() * 3);
  std::vector<int32_t> parent(static_cast<size_t>(nv));
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int32_t x) {
    while (parent[size_t(x)] != x) x = parent[size_t(x)] = parent[size_t(parent[size_t(x)])];
    return x;
  };
  std::vector<char> used(static_cast<size_t>(nv), 0);
  for (const auto& t : m.triangles) {
    for (int c = 0; c < 3; ++c) {
      const int32_t a = t[size_t(c)], b = t[size_t((c + 1) % 3)];
      ++edge_count[(uint64_t(uint32_t(std::min(a, b))) << 32) | uint32_t(std::max(a, b))];
      used[size_t(a)] = 1;
      parent[size_t(find(a))] = find(b);
    }
  }
  for (const auto& [e, n] : edge_count) {
    m.defects.boundary_edges += n == 1;
    m.defects.non_manifold_edges += n >= 3;
  }
  for (int32_t v = 0; v < int32_t(nv); ++v) {
    if (!used[size_t(v)]) ++m.defects.unreferenced_vertices;
    else if (find(v) == v) ++m.defects.components;
  }
  return m;
}

}  // namespace

Result<Mesh> decode_mesh(std::span<const uint8_t> bytes, const MeshLimits& limits) {
  if (bytes.empty()) return Status(StatusCode::kInvalidArgument, "is empty (0 bytes)", "mesh");
  const std::string_view head(reinterpret_cast<const char*>(bytes.data()), std::min<size_t>(bytes.size(), 4096));
  if (head.rfind("ply", 0) == 0) {
    SOLIDTEX_ASSIGN_OR_RETURN(RawMesh raw, read_ply(bytes, limits));
    return clean(std::move(raw), "ply");
  }
  // OFF, COFF, NOFF, CNOFF... first token ends in "OFF".
  size_t s = 0;
  while (s < head.size() && std::isspace(static_cast<unsigned char>(head[s]))) ++s;
  const std::string_view first = head.substr(s, head.find_first_of(" \t\r\n", s) - s);
  if (first.size() >= 3 && first.substr(first.size() - 3) == "OFF") {
    SOLIDTEX_ASSIGN_OR_RETURN(RawMesh raw, read_off(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), limits));
    return clean(std::move(raw), "off");
  }
  // OBJ: text whose lines start with known keywords.
  bool text = true;
  for (char c : head)
    if (c == 0 || (static_cast<unsigned char>(c) < 9)) text = false;
  if (text && (head.find("\nv ") != std::string_view::npos || head.rfind("v ", 0) == 0 || head.find("\nf ") != std::string_view::npos)) {
    SOLIDTEX_ASSIGN_OR_RETURN(RawMesh raw, read_obj(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), limits));
    return clean(std::move(raw), "obj");
  }
  return Status(StatusCode::kUnsupported, "is not a PLY, OFF or OBJ mesh", "mesh");
}

}  // namespace solidtex
