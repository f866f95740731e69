// Parameters of exemplar analysis: a plain struct, validated once by validate(), whose errors
// name the field. Defaults follow Zhang et al. §6.
#pragma once

#include <array>
#include <cstdint>

#include "core/status.h"

namespace solidtex {

// Sentinel of AnalysisParams::levels: the level count follows the exemplar's size (auto_levels).
inline constexpr int kAutoLevels = 0;

// Pyramid levels for an exemplar whose shorter side is `shorter_side` pixels, analysed with
// N x N templates: the most levels whose coarsest template (N * 2^(L-1) pixels wide) spans at
// most half that side, clamped to [1, 8]. 64^2 gets 2, 96^2 and 128^2 3, 256^2 4, 512^2 5 for
// N = 9. A coarsest template wider than that matches the whole exemplar against itself and
// loses its structure; measured on the shared exemplars at 256^2 (docs/quality.md: "Levels").
int auto_levels(int shorter_side, int neighborhood);

struct AnalysisParams {
  // Pyramid levels L, [1, 8], level 0 the coarsest; or kAutoLevels (the default): auto_levels()
  // of the exemplar, resolved before analysis (resolve_levels in analysis.h), so tables and
  // stored records always hold the count used.
  int levels = kAutoLevels;
  int neighborhood = 9;    // N, odd, [3, 15]: template size in exemplar samples per side
  int candidates = 12;     // N_T, candidate triples kept per exemplar pixel, [1, 32]
  int pca_dims = 20;       // appearance-space dimensions per plane, [1, 64]
  int search_k = 24;       // crossbar neighbours per k-NN search, [candidates/2+1, 64]
  int knn_checks = 192;    // FLANN leaves checked per query, [16, 100000]
  uint32_t seed = 1;       // seeds the k-NN trees and the random-triple baseline
  // Plane weights synthesis should use with this table unless told otherwise (see
  // SynthesisParams::plane_weights); stored in the .stx. [0, 1] each, not all zero.
  std::array<float, 3> suggested_plane_weights{1.f, 1.f, 1.f};

  Status validate() const;
  friend bool operator==(const AnalysisParams&, const AnalysisParams&) = default;
};

}  // namespace solidtex
