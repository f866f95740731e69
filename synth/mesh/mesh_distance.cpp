#include "mesh/mesh_distance.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>

#include <cmath>
#include <mutex>

namespace solidtex {

struct SurfaceDistance::Impl {
  openvdb::FloatGrid::Ptr grid;
};

SurfaceDistance::~SurfaceDistance() = default;

int64_t SurfaceDistance::estimate_bytes(const Mesh& mesh, const Placement& placement, double band) {
  double area = 0;
  for (const auto& t : mesh.triangles) {
    const auto& a = mesh.vertices[size_t(t[0])];
    const auto& b = mesh.vertices[size_t(t[1])];
    const auto& c = mesh.vertices[size_t(t[2])];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    area += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  const double voxels = area * placement.scale * placement.scale * (2 * band + 8);
  const double bytes = voxels * 5;
  return bytes >= 9e18 || !std::isfinite(bytes) ? int64_t(9e18) : int64_t(bytes);
}

Result<std::shared_ptr<const SurfaceDistance>> SurfaceDistance::create(const Mesh& mesh, const Placement& placement,
                                                                       double band, int64_t max_bytes) {
  static std::once_flag init;
  std::call_once(init, [] { openvdb::initialize(); });
  if (!(band >= 0.5 && band <= 256)) return Status(StatusCode::kInvalidArgument, "must be in [0.5, 256] voxels", "distance");
  if (max_bytes > 0)
    if (const int64_t bytes = estimate_bytes(mesh, placement, band); bytes > max_bytes)
      return Status(StatusCode::kUnprocessable,
                    "the surface distance band needs about " + std::to_string(bytes >> 20) + " MB; the limit is " +
                        std::to_string(max_bytes >> 20) + " MB (a smaller resolution or distance)",
                    "regions.label");
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

int64_t SurfaceDistance::resident_bytes() const {
  int64_t bytes = int64_t(sizeof(SurfaceDistance)) + int64_t(sizeof(Impl));
  if (impl_ && impl_->grid) bytes += int64_t(impl_->grid->memUsage());
  return bytes;
}

double SurfaceDistance::at(const WorldPoint& p) const {
  // Voxel-centred samples: world point (i, j, k) is grid voxel (i, j, k); in between, trilinear.
  const openvdb::Vec3d xyz(p.x, p.y, p.z);
  const float v = openvdb::tools::BoxSampler::sample(impl_->grid->tree(), xyz);
  return double(v);
}

}  // namespace solidtex
