#include "synthesis/target.h"

#include <algorithm>
#include <cmath>

namespace solidtex {
namespace {

Status check_size(int width, int height) {
  if (width < 1 || height < 1) return Status(StatusCode::kInvalidArgument, "must be at least 1x1", "size");
  if (int64_t(width) * height > kMaxTargetSamples)
    return Status(StatusCode::kTooLarge, "asks for " + std::to_string(int64_t(width) * height) +
                                             " samples; the limit is " + std::to_string(kMaxTargetSamples),
                  "size");
  return Status::ok();
}

constexpr double kMaxCoordinate = 1 << 28;  // keeps every level's lattice inside int32

Status check_point(const WorldPoint& p, const char* field) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || std::abs(p.x) > kMaxCoordinate ||
      std::abs(p.y) > kMaxCoordinate || std::abs(p.z) > kMaxCoordinate)
    return Status(StatusCode::kInvalidArgument, "coordinates must be finite and within +-2^28 voxels", field);
  return Status::ok();
}

}  // namespace

VoxelBox TargetSet::bounds() const {
  VoxelBox b;
  for (const Voxel& v : voxels) b.include(v);
  return b;
}

TargetSet TargetSet::from_voxels(const std::vector<Voxel>& samples, int width, int height) {
  TargetSet t;
  t.width = width;
  t.height = height;
  t.voxels = samples;
  std::sort(t.voxels.begin(), t.voxels.end());
  t.voxels.erase(std::unique(t.voxels.begin(), t.voxels.end()), t.voxels.end());
  t.sample.resize(samples.size());
  for (size_t i = 0; i < samples.size(); ++i)
    t.sample[i] = uint32_t(std::lower_bound(t.voxels.begin(), t.voxels.end(), samples[i]) - t.voxels.begin());
  return t;
}

Result<TargetSet> TargetSet::axis_cut(char axis, int at, int u0, int v0, int width, int height) {
  SOLIDTEX_RETURN_IF_ERROR(check_size(width, height));
  if (axis != 'x' && axis != 'y' && axis != 'z')
    return Status(StatusCode::kInvalidArgument, "must be x, y or z", "axis");
  SOLIDTEX_RETURN_IF_ERROR(check_point({double(at), double(u0) + width, double(v0) + height}, "at"));
  SOLIDTEX_RETURN_IF_ERROR(check_point({double(at), double(u0), double(v0)}, "origin"));
  std::vector<Voxel> s;
  s.reserve(size_t(width) * height);
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) {
      if (axis == 'z') s.push_back({u0 + i, v0 + j, at});
      else if (axis == 'x') s.push_back({at, u0 + i, v0 + j});
      else s.push_back({u0 + i, at, v0 + j});
    }
  return from_voxels(s, width, height);
}

Result<TargetSet> TargetSet::plane_cut(const WorldPoint& o, const WorldPoint& u, const WorldPoint& v, int width, int height) {
  SOLIDTEX_RETURN_IF_ERROR(check_size(width, height));
  SOLIDTEX_RETURN_IF_ERROR(check_point(o, "origin"));
  SOLIDTEX_RETURN_IF_ERROR(check_point(u, "u"));
  SOLIDTEX_RETURN_IF_ERROR(check_point(v, "v"));
  const WorldPoint far{o.x + u.x * width + v.x * height, o.y + u.y * width + v.y * height, o.z + u.z * width + v.z * height};
  SOLIDTEX_RETURN_IF_ERROR(check_point(far, "size"));
  std::vector<Voxel> s;
  s.reserve(size_t(width) * height);
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i)
      s.push_back({int(std::lround(o.x + i * u.x + j * v.x)), int(std::lround(o.y + i * u.y + j * v.y)),
                   int(std::lround(o.z + i * u.z + j * v.z))});
  return from_voxels(s, width, height);
}

Result<TargetSet> TargetSet::box(const Voxel& min, int sx, int sy, int sz) {
  if (sx < 1 || sy < 1 || sz < 1) return Status(StatusCode::kInvalidArgument, "must be at least 1 on every axis", "size");
  if (int64_t(sx) * sy * sz > kMaxTargetSamples)
    return Status(StatusCode::kTooLarge, "box has too many voxels", "size");
  SOLIDTEX_RETURN_IF_ERROR(check_point({double(min.x), double(min.y), double(min.z)}, "min"));
  std::vector<Voxel> s;
  s.reserve(size_t(sx) * sy * sz);
  for (int z = 0; z < sz; ++z)
    for (int y = 0; y < sy; ++y)
      for (int x = 0; x < sx; ++x) s.push_back({min.x + x, min.y + y, min.z + z});
  return from_voxels(s, sx, sy * sz);
}

Result<TargetSet> TargetSet::points(const std::vector<WorldPoint>& pts) {
  if (pts.empty()) return Status(StatusCode::kInvalidArgument, "no points given", "points");
  if (int64_t(pts.size()) > kMaxTargetSamples) return Status(StatusCode::kTooLarge, "too many points", "points");
  std::vector<Voxel> s;
  s.reserve(pts.size());
  for (const WorldPoint& p : pts) {
    SOLIDTEX_RETURN_IF_ERROR(check_point(p, "points"));
    s.push_back({int(std::lround(p.x)), int(std::lround(p.y)), int(std::lround(p.z))});
  }
  return from_voxels(s, int(pts.size()), 1);
}

}  // namespace solidtex
