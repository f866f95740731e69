// decode_mesh (mesh/mesh.h): OBJ, OFF and PLY (ASCII, binary little/big-endian) detection and
// readers, then the common cleaning pass; then what the service does with an uploaded mesh
// (bounds, fit_placement, bounding_voxels, encode_ply for the coloured answer).
// Checked: an accepted mesh has in-range, non-degenerate, distinct triangles and finite
// vertices; the PLY it encodes decodes to the same mesh; a fitted placement maps every vertex
// into [0, resolution].
#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "fuzz_support.h"
#include "mesh/mesh.h"

using namespace solidtex;

namespace {

void check_clean(const Mesh& m, const MeshLimits& limits) {
  FUZZ_CHECK(m.format == "ply" || m.format == "obj" || m.format == "off");
  FUZZ_CHECK(!m.vertices.empty() && !m.triangles.empty());
  FUZZ_CHECK(int64_t(m.vertices.size()) <= limits.max_vertices);
  for (const auto& v : m.vertices)
    for (double c : v) FUZZ_CHECK(std::isfinite(c));
  std::set<std::array<int32_t, 3>> seen;
  for (const auto& t : m.triangles) {
    for (int32_t i : t) FUZZ_CHECK(i >= 0 && size_t(i) < m.vertices.size());
    FUZZ_CHECK(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    std::array<int32_t, 3> key = t;
    std::sort(key.begin(), key.end());
    FUZZ_CHECK(seen.insert(key).second);
  }
  FUZZ_CHECK(m.defects.components >= 1);
}

void check_ply_round_trip(const Mesh& m, const MeshLimits& limits) {
  // encode_ply stores float coordinates; beyond float range they would not survive.
  for (const auto& v : m.vertices)
    for (double c : v)
      if (!(std::fabs(c) < 1e38)) return;
  const std::vector<uint8_t> ply = encode_ply(m);
  Result<Mesh> again = decode_mesh(ply, limits);
  FUZZ_CHECK(again.is_ok());
  FUZZ_CHECK(again->format == "ply");
  FUZZ_CHECK(again->triangles == m.triangles);
  FUZZ_CHECK(again->vertices.size() == m.vertices.size());
  for (size_t i = 0; i < m.vertices.size(); ++i)
    for (int a = 0; a < 3; ++a) FUZZ_CHECK(again->vertices[i][size_t(a)] == double(float(m.vertices[i][size_t(a)])));
  FUZZ_CHECK(again->defects.duplicate_faces == 0 && again->defects.degenerate_faces == 0);
  FUZZ_CHECK(again->defects.boundary_edges == m.defects.boundary_edges);
  FUZZ_CHECK(again->defects.non_manifold_edges == m.defects.non_manifold_edges);
  FUZZ_CHECK(again->defects.components == m.defects.components);
  FUZZ_CHECK(again->defects.unreferenced_vertices == m.defects.unreferenced_vertices);
}

void check_placement(const Mesh& m) {
  const MeshBounds b = m.bounds();
  constexpr int kResolution = 512;
  constexpr double kMargin = 0.25;
  Result<Placement> p = fit_placement(b, kResolution, kMargin);
  if (!p) return;  // no extent: an error value, fine
  FUZZ_CHECK(std::isfinite(p->scale) && p->scale > 0);
  for (double t : p->translate) FUZZ_CHECK(std::isfinite(t));
  double max_abs = 0;
  for (int a = 0; a < 3; ++a) max_abs = std::max({max_abs, std::fabs(b.min[size_t(a)]), std::fabs(b.max[size_t(a)])});
  // scale * v + translate cancels: allow for the rounding of the two large terms.
  const double tol = 1e-6 * kResolution + 1e-12 * p->scale * max_abs;
  for (const auto& v : m.vertices) {
    const WorldPoint w = p->apply(v);
    for (double c : {w.x, w.y, w.z}) FUZZ_CHECK(std::isfinite(c) && c >= -tol && c <= kResolution + tol);
  }
  const MeshBounds box = placed_box(b, *p, kMargin);
  for (int a = 0; a < 3; ++a) FUZZ_CHECK(box.min[size_t(a)] >= -tol && box.max[size_t(a)] <= kResolution + tol);
  const int64_t n = bounding_voxels(b, *p);
  FUZZ_CHECK(n >= 1 && n <= int64_t(kResolution + 2) * (kResolution + 2) * (kResolution + 2));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const MeshLimits limits;  // the service's defaults
  Result<Mesh> m = decode_mesh(fuzz::bytes(data, size), limits);
  if (!m) {
    FUZZ_CHECK(!m.status().message().empty());
    return 0;
  }
  check_clean(*m, limits);
  check_ply_round_trip(*m, limits);
  check_placement(*m);
  return 0;
}
