#include "mesh/mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <unordered_map>

#include "core/byte_io.h"

namespace solidtex {

MeshBounds Mesh::bounds() const {
  MeshBounds b;
  if (vertices.empty()) return b;
  b.min = b.max = vertices[0];
  for (const auto& v : vertices)
    for (int a = 0; a < 3; ++a) {
      b.min[size_t(a)] = std::min(b.min[size_t(a)], v[size_t(a)]);
      b.max[size_t(a)] = std::max(b.max[size_t(a)], v[size_t(a)]);
    }
  return b;
}

namespace {
double longest_side(const MeshBounds& b) {
  return std::max({b.max[0] - b.min[0], b.max[1] - b.min[1], b.max[2] - b.min[2]});
}
}  // namespace

Result<Placement> fit_placement(const MeshBounds& bounds, int resolution, double margin) {
  if (resolution < 8 || resolution > 4096) return Status(StatusCode::kInvalidArgument, "must be in [8, 4096]", "placement.resolution");
  if (!(margin >= 0 && margin <= 1)) return Status(StatusCode::kInvalidArgument, "must be in [0, 1]", "placement.margin");
  const double longest = longest_side(bounds);
  if (!(longest > 0) || !std::isfinite(longest))
    return Status(StatusCode::kUnprocessable, "the mesh has no extent (all vertices coincide)", "mesh");
  Placement p;
  p.scale = resolution / (longest * (1 + 2 * margin));
  for (int a = 0; a < 3; ++a) p.translate[size_t(a)] = -p.scale * (bounds.min[size_t(a)] - margin * longest);
  // A (denormal) extent like 5e-324 overflows the scale; a tiny extent far from the origin,
  // the translation.
  if (!std::isfinite(p.scale) || !std::isfinite(p.translate[0]) || !std::isfinite(p.translate[1]) ||
      !std::isfinite(p.translate[2])) {
    char extent[32];
    std::snprintf(extent, sizeof extent, "%.3g", longest);
    return Status(StatusCode::kUnprocessable,
                  std::string("the mesh's extent (") + extent + " along its longest side) is too small to fit", "mesh");
  }
  return p;
}

MeshBounds placed_box(const MeshBounds& bounds, const Placement& placement, double margin) {
  const double longest = longest_side(bounds);
  MeshBounds out;
  for (int a = 0; a < 3; ++a) {
    const double lo = placement.scale * (bounds.min[size_t(a)] - margin * longest) + placement.translate[size_t(a)];
    const double hi = placement.scale * (bounds.max[size_t(a)] + margin * longest) + placement.translate[size_t(a)];
    out.min[size_t(a)] = std::min(lo, hi);
    out.max[size_t(a)] = std::max(lo, hi);
  }
  return out;
}

int64_t bounding_voxels(const MeshBounds& bounds, const Placement& placement) {
  int64_t n = 1;
  for (int a = 0; a < 3; ++a) {
    const double lo = placement.scale * bounds.min[size_t(a)] + placement.translate[size_t(a)];
    const double hi = placement.scale * bounds.max[size_t(a)] + placement.translate[size_t(a)];
    n *= std::llround(std::max(lo, hi)) - std::llround(std::min(lo, hi)) + 1;
  }
  return n;
}

std::vector<uint8_t> encode_ply(const Mesh& mesh, const std::vector<uint8_t>* srgb8) {
  const bool colors = srgb8 && srgb8->size() == mesh.vertices.size() * 3;
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment solidtex\nelement vertex " +
                       std::to_string(mesh.vertices.size()) +
                       "\nproperty float x\nproperty float y\nproperty float z\n";
  if (colors) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  header += "element face " + std::to_string(mesh.triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  ByteWriter w;
  w.bytes(std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(header.data()), header.size()));
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int a = 0; a < 3; ++a) w.f32(float(mesh.vertices[i][size_t(a)]));
    if (colors)
      for (int c = 0; c < 3; ++c) w.u8((*srgb8)[i * 3 + size_t(c)]);
  }
  for (const auto& t : mesh.triangles) {
    w.u8(3);
    for (int c = 0; c < 3; ++c) w.i32(t[size_t(c)]);
  }
  return std::move(w.buffer());
}

}  // namespace solidtex
