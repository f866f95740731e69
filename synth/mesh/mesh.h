// Triangle meshes as the service receives them: read from OBJ, PLY (ASCII, binary little- or
// big-endian) or OFF bytes (format detected from the content), polygons fan-triangulated, and
// cleaned the same way whatever the format: degenerate faces (a repeated vertex) and duplicate
// faces (the same three vertices) are dropped; other real-world defects (holes, non-manifold
// edges, several components, unreferenced vertices) are kept and counted in MeshDefects.
// Anything malformed (bad index, non-finite coordinate, truncated data, counts beyond the
// limits) is a Status naming the element and its number. Coordinates are the file's own
// ("mesh coordinates"); a Placement maps them to world units (finest voxels).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"
#include "core/types.h"

namespace solidtex {

struct MeshLimits {
  int64_t max_vertices = 5'000'000;
  int64_t max_faces = 10'000'000;
};

struct MeshDefects {
  int64_t duplicate_faces = 0;        // dropped
  int64_t degenerate_faces = 0;       // dropped (a vertex repeated)
  int64_t unreferenced_vertices = 0;  // kept (they still get colors)
  int64_t boundary_edges = 0;         // edges of one triangle: holes
  int64_t non_manifold_edges = 0;     // edges of three or more triangles
  int64_t components = 0;             // connected by shared vertices
  int64_t polygons_triangulated = 0;  // faces with more than three vertices
};

struct MeshBounds {
  std::array<double, 3> min{0, 0, 0};
  std::array<double, 3> max{0, 0, 0};
};

struct Mesh {
  std::string format;  // "ply", "obj" or "off"
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<int32_t, 3>> triangles;
  MeshDefects defects;
  MeshBounds bounds() const;  // over all vertices
};

Result<Mesh> decode_mesh(std::span<const uint8_t> bytes, const MeshLimits& limits = {});

// Binary little-endian PLY: float x, y, z per vertex (plus uchar red, green, blue when `srgb8`
// has 3 bytes per vertex), and the triangles as uchar-count int lists.
std::vector<uint8_t> encode_ply(const Mesh& mesh, const std::vector<uint8_t>* srgb8 = nullptr);

// Mesh coordinates -> world (finest voxels): world = scale * mesh + translate.
struct Placement {
  double scale = 1;
  std::array<double, 3> translate{0, 0, 0};
  WorldPoint apply(const std::array<double, 3>& p) const {
    return {scale * p[0] + translate[0], scale * p[1] + translate[1], scale * p[2] + translate[2]};
  }
};

// Fits the bounding box enlarged by `margin` x its longest side on every side to `resolution`
// voxels along the longest side, the enlarged box's minimum corner at the world origin.
Result<Placement> fit_placement(const MeshBounds& bounds, int resolution, double margin);
// The mesh's bounding box after placement, enlarged by `margin` x its longest side (world units).
MeshBounds placed_box(const MeshBounds& bounds, const Placement& placement, double margin);
// Finest voxels in the placed (not enlarged) bounding box: the "bounding volume" of a surface.
int64_t bounding_voxels(const MeshBounds& bounds, const Placement& placement);

}  // namespace solidtex
