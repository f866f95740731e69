#include "synthesis/voxel_sampling.h"

#include <array>
#include <vector>

#include "analysis/table.h"
#include "core/image.h"
#include "synthesis/correction.h"

namespace solidtex {
namespace {

// One level of the pyramid: w x h pixels, 3 channels, row-major.
struct Level {
  int w = 0, h = 0;
  std::vector<double> v;
};

Level half(const Level& in) {  // 2 x 2 means of the even crop
  Level out{in.w / 2, in.h / 2, {}};
  out.v.resize(size_t(out.w) * out.h * 3);
  for (int y = 0; y < out.h; ++y)
    for (int x = 0; x < out.w; ++x)
      for (int c = 0; c < 3; ++c) {
        auto at = [&](int dx, int dy) { return in.v[(size_t(2 * y + dy) * in.w + (2 * x + dx)) * 3 + c]; };
        out.v[(size_t(y) * out.w + x) * 3 + c] = 0.25 * (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1));
      }
  return out;
}

// Sum of squares and count of fine - upsampled(coarse) over the crop both cover.
std::array<double, 2> band_energy(const Level& fine, const Level& coarse) {
  double sum = 0;
  const int w = coarse.w * 2, h = coarse.h * 2;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        const double d = fine.v[(size_t(y) * fine.w + x) * 3 + c] - coarse.v[(size_t(y / 2) * coarse.w + x / 2) * 3 + c];
        sum += d * d;
      }
  return {sum, double(w) * h * 3};
}

// Mean squares of bands 0 and 1.
std::array<double, 2> band_energies(const ImageF& image) {
  if (image.width < 4 || image.height < 4 || image.channels < 3) return {0, 0};
  Level g0{image.width, image.height, {}};
  g0.v.resize(size_t(image.width) * image.height * 3);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) g0.v[(size_t(y) * image.width + x) * 3 + c] = linear_to_srgb(image.at(x, y)[c]);
  const Level g1 = half(g0), g2 = half(g1);
  const auto e0 = band_energy(g0, g1), e1 = band_energy(g1, g2);
  return {e0[0] / e0[1], e1[0] / e1[1]};
}

double share(double e0, double e1) { return e0 + e1 > 0 ? e0 / (e0 + e1) : 0.0; }

}  // namespace

Result<std::optional<VoxelSampling>> parse_voxel_sampling(const std::string& name, const std::string& field) {
  if (name == "auto") return std::optional<VoxelSampling>();
  if (name == "nearest") return std::optional<VoxelSampling>(VoxelSampling::kNearest);
  if (name == "cubic") return std::optional<VoxelSampling>(VoxelSampling::kCubic);
  return Status(StatusCode::kInvalidArgument, "must be auto, nearest or cubic", field);
}

const char* voxel_sampling_name(VoxelSampling s) { return s == VoxelSampling::kCubic ? "cubic" : "nearest"; }

double fine_detail_share(const ImageF& linear_rgb) {
  const auto e = band_energies(linear_rgb);
  return share(e[0], e[1]);
}

double fine_detail_share(const Table& table) {
  const ExemplarSet& ex = table.exemplars();
  if (ex.shared()) return fine_detail_share(ex.plane(Plane::kXY));
  const auto& w = table.params().suggested_plane_weights;
  double e0 = 0, e1 = 0;
  for (int k = 0; k < 3; ++k) {
    const auto e = band_energies(ex.plane(Plane(k)));
    e0 += double(w[size_t(k)]) * e[0];
    e1 += double(w[size_t(k)]) * e[1];
  }
  return share(e0, e1);
}

VoxelSampling preferred_voxel_sampling(const Table& table, ColorRule color) {
  const double threshold =
      resolved_color_rule(color) == ColorRule::kVote ? kCubicMaxFineDetailShareVote : kCubicMaxFineDetailShare;
  return fine_detail_share(table) < threshold ? VoxelSampling::kCubic : VoxelSampling::kNearest;
}

VoxelSampling preferred_voxel_sampling(const std::vector<std::shared_ptr<const Table>>& tables, ColorRule color) {
  for (const auto& t : tables)
    if (preferred_voxel_sampling(*t, color) == VoxelSampling::kNearest) return VoxelSampling::kNearest;
  return tables.empty() ? VoxelSampling::kNearest : VoxelSampling::kCubic;
}

}  // namespace solidtex
