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

// Catmull-Rom weights of the taps at floor(p) - 1 .. floor(p) + 2 for t = p - floor(p) in [0, 1):
// (0, 1, 0, 0) exactly at t = 0.
std::array<float, 4> catmull_rom_weights(float t) {
  const float t2 = t * t, t3 = t2 * t;
  return {0.5f * (-t3 + 2.f * t2 - t), 0.5f * (3.f * t3 - 5.f * t2 + 2.f), 0.5f * (-3.f * t3 + 4.f * t2 + t),
          0.5f * (t3 - t2)};
}

// The taps floor - 1 .. floor + 2 per axis with a non-zero product weight, x fastest, and
// their weights: at integer positions (t = 0) the single voxel at floor, weight exactly 1.
template <class F>
void for_each_tap(const Voxel& floor, const std::array<float, 3>& t, F&& f) {
  const std::array<std::array<float, 4>, 3> w{catmull_rom_weights(t[0]), catmull_rom_weights(t[1]),
                                               catmull_rom_weights(t[2])};
  const int first[3] = {floor.x - 1, floor.y - 1, floor.z - 1};
  for (int c = 0; c < 4; ++c) {
    if (w[2][size_t(c)] == 0.f) continue;
    for (int b = 0; b < 4; ++b) {
      if (w[1][size_t(b)] == 0.f) continue;
      for (int a = 0; a < 4; ++a) {
        if (w[0][size_t(a)] == 0.f) continue;
        f(Voxel{first[0] + a, first[1] + b, first[2] + c}, (w[0][size_t(a)] * w[1][size_t(b)]) * w[2][size_t(c)]);
      }
    }
  }
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

namespace {

// A cubic-resampled target: n samples, sample k at position(k) (voxel units), shaped width x
// height. `unit` names the samples in errors ("pixels", "points"), which name `field`.
template <class Position>
Result<TargetSet> resampled(size_t n, int width, int height, Position&& position, const char* unit, const char* field) {
  if (int64_t(n) > kMaxResampledSamples)
    return Status(StatusCode::kTooLarge,
                  std::string("cubic resampling takes at most ") + std::to_string(kMaxResampledSamples) + " " + unit +
                      "; use resample nearest, or fewer",
                  field);
  TargetSet t;
  t.width = width;
  t.height = height;
  t.resample_floor.resize(n);
  t.resample_t.resize(n);
  std::vector<Voxel> nearest(n), needed;
  // Neighbouring samples share most of their 4x4x4 taps: deduplicate as the list grows, so
  // memory stays near the distinct voxels (a slab ~5 voxels thick), not 64 per sample. Sparse
  // samples (cut steps of several voxels, lines, scattered points) share nothing: past
  // kMaxResampledVoxels distinct voxels the target is refused before more memory is spent
  // (transient <= 2x that + 1 Mi voxels).
  size_t distinct = 0;
  auto dedupe = [&] {  // needed[0, distinct) is sorted and distinct: sort the tail and merge
    const auto mid = needed.begin() + std::ptrdiff_t(distinct);
    std::sort(mid, needed.end());
    needed.erase(std::unique(mid, needed.end()), needed.end());
    std::inplace_merge(needed.begin(), needed.begin() + std::ptrdiff_t(distinct), needed.end());
    needed.erase(std::unique(needed.begin(), needed.end()), needed.end());
    distinct = needed.size();
  };
  auto too_many_voxels = [&] {
    return Status(StatusCode::kTooLarge,
                  std::string("cubic resampling of these ") + unit + " needs more than " +
                      std::to_string(kMaxResampledVoxels) + " voxels; use resample nearest, or fewer " + unit +
                      " closer together",
                  field);
  };
  for (size_t k = 0; k < n; ++k) {
    if (needed.size() > 2 * distinct + (size_t(1) << 20)) {
      dedupe();
      if (distinct > size_t(kMaxResampledVoxels)) return too_many_voxels();
    }
    const std::array<double, 3> p = position(k);
    int fl[3];
    for (int a = 0; a < 3; ++a) {
      const double f = std::floor(p[size_t(a)]);
      fl[a] = int(f);
      t.resample_t[k][size_t(a)] = float(p[size_t(a)] - f);
    }
    t.resample_floor[k] = {fl[0], fl[1], fl[2]};
    nearest[k] = {int(std::lround(p[0])), int(std::lround(p[1])), int(std::lround(p[2]))};
    for_each_tap(t.resample_floor[k], t.resample_t[k], [&](const Voxel& q, float) { needed.push_back(q); });
  }
  dedupe();
  if (distinct > size_t(kMaxResampledVoxels)) return too_many_voxels();
  t.voxels = std::move(needed);
  t.sample.resize(n);
  for (size_t k = 0; k < n; ++k)  // the nearest voxel is always a tap with a non-zero weight
    t.sample[k] = uint32_t(std::lower_bound(t.voxels.begin(), t.voxels.end(), nearest[k]) - t.voxels.begin());
  return t;
}

// `resample` as given; auto (nullopt): `preferred`, or nearest where cubic passes its bounds.
template <class Build>
Result<TargetSet> sample_as(std::optional<VoxelSampling> resample, VoxelSampling preferred, Build&& build) {
  if (resample) return build(*resample);
  if (preferred == VoxelSampling::kCubic) {
    auto cubic = build(VoxelSampling::kCubic);
    if (cubic || cubic.status().code() != StatusCode::kTooLarge) return cubic;
  }
  return build(VoxelSampling::kNearest);
}

}  // namespace

Result<TargetSet> TargetSet::plane_cut(const WorldPoint& o, const WorldPoint& u, const WorldPoint& v, int width, int height,
                                       VoxelSampling sampling) {
  SOLIDTEX_RETURN_IF_ERROR(check_size(width, height));
  SOLIDTEX_RETURN_IF_ERROR(check_point(o, "origin"));
  SOLIDTEX_RETURN_IF_ERROR(check_point(u, "u"));
  SOLIDTEX_RETURN_IF_ERROR(check_point(v, "v"));
  const WorldPoint far{o.x + u.x * width + v.x * height, o.y + u.y * width + v.y * height, o.z + u.z * width + v.z * height};
  SOLIDTEX_RETURN_IF_ERROR(check_point(far, "size"));
  auto position = [&](size_t k) {
    const int i = int(k % size_t(width)), j = int(k / size_t(width));
    return std::array<double, 3>{o.x + i * u.x + j * v.x, o.y + i * u.y + j * v.y, o.z + i * u.z + j * v.z};
  };
  const size_t n = size_t(width) * height;
  if (sampling == VoxelSampling::kCubic) return resampled(n, width, height, position, "pixels", "size");
  std::vector<Voxel> s(n);
  for (size_t k = 0; k < n; ++k) {
    const auto p = position(k);
    s[k] = {int(std::lround(p[0])), int(std::lround(p[1])), int(std::lround(p[2]))};
  }
  return from_voxels(s, width, height);
}

Result<TargetSet> TargetSet::plane_cut(const WorldPoint& o, const WorldPoint& u, const WorldPoint& v, int width, int height,
                                       std::optional<VoxelSampling> resample, VoxelSampling preferred) {
  return sample_as(resample, preferred, [&](VoxelSampling s) { return plane_cut(o, u, v, width, height, s); });
}

std::vector<std::array<float, 3>> TargetSet::resolve(const std::vector<std::array<float, 3>>& voxel_rgb) const {
  std::vector<std::array<float, 3>> out(sample.size());
  if (resample_floor.empty()) {
    for (size_t s = 0; s < sample.size(); ++s) out[s] = voxel_rgb[sample[s]];
    return out;
  }
  for (size_t s = 0; s < sample.size(); ++s) {
    std::array<float, 3> sum{0.f, 0.f, 0.f};
    std::array<float, 3> lo = voxel_rgb[sample[s]], hi = lo;
    for_each_tap(resample_floor[s], resample_t[s], [&](const Voxel& q, float w) {
      const auto& c = voxel_rgb[size_t(std::lower_bound(voxels.begin(), voxels.end(), q) - voxels.begin())];
      for (size_t ch = 0; ch < 3; ++ch) {
        sum[ch] += w * c[ch];
        lo[ch] = std::min(lo[ch], c[ch]);
        hi[ch] = std::max(hi[ch], c[ch]);
      }
    });
    for (size_t ch = 0; ch < 3; ++ch) out[s][ch] = std::clamp(sum[ch], lo[ch], hi[ch]);
  }
  return out;
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

Result<TargetSet> TargetSet::points(const std::vector<WorldPoint>& pts, VoxelSampling sampling) {
  if (pts.empty()) return Status(StatusCode::kInvalidArgument, "no points given", "points");
  if (int64_t(pts.size()) > kMaxTargetSamples) return Status(StatusCode::kTooLarge, "too many points", "points");
  for (const WorldPoint& p : pts) SOLIDTEX_RETURN_IF_ERROR(check_point(p, "points"));
  auto position = [&](size_t k) { return std::array<double, 3>{pts[k].x, pts[k].y, pts[k].z}; };
  if (sampling == VoxelSampling::kCubic) return resampled(pts.size(), int(pts.size()), 1, position, "points", "points");
  std::vector<Voxel> s;
  s.reserve(pts.size());
  for (const WorldPoint& p : pts) s.push_back({int(std::lround(p.x)), int(std::lround(p.y)), int(std::lround(p.z))});
  return from_voxels(s, int(pts.size()), 1);
}

Result<TargetSet> TargetSet::points(const std::vector<WorldPoint>& pts, std::optional<VoxelSampling> resample,
                                    VoxelSampling preferred) {
  return sample_as(resample, preferred, [&](VoxelSampling s) { return points(pts, s); });
}

}  // namespace solidtex
