#include "analysis/analysis_params.h"

#include <cstdint>
#include <string>

namespace solidtex {
namespace {
Status range(int v, int lo, int hi, const char* field) {
  if (v < lo || v > hi)
    return Status(StatusCode::kInvalidArgument,
                  "is " + std::to_string(v) + "; must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]",
                  field);
  return Status::ok();
}
}  // namespace

int auto_levels(int shorter_side, int neighborhood) {
  int levels = 1;
  while (levels < 8 && (int64_t(neighborhood) << levels) * 2 <= int64_t(shorter_side)) ++levels;
  return levels;
}

Status AnalysisParams::validate() const {
  if (levels != kAutoLevels) SOLIDTEX_RETURN_IF_ERROR(range(levels, 1, 8, "levels"));
  SOLIDTEX_RETURN_IF_ERROR(range(neighborhood, 3, 15, "neighborhood"));
  if (neighborhood % 2 == 0)
    return Status(StatusCode::kInvalidArgument, "is " + std::to_string(neighborhood) + "; must be odd", "neighborhood");
  SOLIDTEX_RETURN_IF_ERROR(range(candidates, 1, 32, "candidates"));
  SOLIDTEX_RETURN_IF_ERROR(range(pca_dims, 1, 64, "pca_dims"));
  SOLIDTEX_RETURN_IF_ERROR(range(search_k, candidates / 2 + 1, 64, "search_k"));
  SOLIDTEX_RETURN_IF_ERROR(range(knn_checks, 16, 100000, "knn_checks"));
  float total = 0.f;
  for (float w : suggested_plane_weights) {
    if (!(w >= 0.f && w <= 1.f))
      return Status(StatusCode::kInvalidArgument, "each must be in [0, 1]", "suggested_plane_weights");
    total += w;
  }
  if (!(total > 0.f)) return Status(StatusCode::kInvalidArgument, "must not all be zero", "suggested_plane_weights");
  return Status::ok();
}

}  // namespace solidtex
