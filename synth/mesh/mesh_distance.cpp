#include "mesh/mesh_distance.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>

#include <mutex>

namespace solidtex {

struct SurfaceDistance::Impl {
  openvdb::FloatGrid::Ptr grid;
};

SurfaceDistance::~SurfaceDistance() = default;

Result<std::shared_ptr<const SurfaceDistance>> SurfaceDistance::create(const Mesh& mesh, const Placement& placement,
                                                                       double band) {
  static std::once_flag init;
  std::call_once(init, [] { openvdb::initialize(); });
  if (!(band >= 0.5 && band <= 256)) return Status(StatusCode::kInvalidArgument, "must be in [0.5, 256] voxels", "distance");
  std::vector<openvdb::Vec3s> points;
  points.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) {
    const WorldPoint w = placement.apply(v);
    points.emplace_back(float(w.x), float(w.y), float(w.z));
  }
  std::vector<openvdb::Vec3I> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.emplace_back(uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2]));
  std::vector<openvdb::Vec4I> quads;
  auto d = std::shared_ptr<SurfaceDistance>(new SurfaceDistance());
  d->impl_ = std::make_unique<Impl>();
  d->band_ = band;
  try {
    const auto xform = openvdb::math::Transform::createLinearTransform(1.0);
    d->impl_->grid = openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(*xform, points, triangles, quads,
                                                                                    float(band + 1.5));
  } catch (const std::exception& e) {
    return Status(StatusCode::kInternal, std::string("distance field: ") + e.what(), "mesh");
  }
  return std::shared_ptr<const SurfaceDistance>(d);
}

double SurfaceDistance::at(const WorldPoint& p) const {
  // Voxel-centred samples: world point (i, j, k) is grid voxel (i, j, k); in between, trilinear.
  const openvdb::Vec3d xyz(p.x, p.y, p.z);
  const float v = openvdb::tools::BoxSampler::sample(impl_->grid->tree(), xyz);
  return double(v);
}

}  // namespace solidtex
