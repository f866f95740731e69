// Unsigned distance from world points to a placed mesh's surface, for "within distance d of the
// surface" region labels (Zhang Fig. 15: bark near the surface, wood inside). Built once with
// OpenVDB's mesh-to-volume conversion as a narrow band of `band` voxels around the surface (one
// voxel = one world unit); farther points report a distance above `band`. Immutable and
// thread-safe; deterministic for the same mesh and placement. Only mesh_distance.cpp includes
// OpenVDB.
#pragma once

#include <memory>

#include "mesh/mesh.h"
#include "core/status.h"
#include "core/types.h"

namespace solidtex {

class SurfaceDistance {
 public:
  // `max_bytes` (0 = none): refuse with kUnprocessable, before building, when estimate_bytes()
  // exceeds it.
  static Result<std::shared_ptr<const SurfaceDistance>> create(const Mesh& mesh, const Placement& placement, double band,
                                                               int64_t max_bytes = 0);
  // The narrow band's memory: placed surface area x (2 band + one leaf of padding) voxels, at
  // 5 bytes each (float value plus OpenVDB tree overhead). An upper bound for meshes whose
  // triangles do not overlap.
  static int64_t estimate_bytes(const Mesh& mesh, const Placement& placement, double band);
  ~SurfaceDistance();
  // Distance in world units from p to the surface; > band() when farther than the band.
  double at(const WorldPoint& p) const;
  double band() const { return band_; }
  // Memory the band holds (its OpenVDB tree, exactly as OpenVDB counts it, plus this object).
  int64_t resident_bytes() const;

 private:
  SurfaceDistance() = default;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double band_ = 0;
};

}  // namespace solidtex
