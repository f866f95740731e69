// Parameters of exemplar analysis: a plain struct, validated once by validate(), whose errors
// name the field. Defaults follow Zhang et al. §6.
#pragma once

#include <array>
#include <cstdint>

#include "core/status.h"

namespace solidtex {

struct AnalysisParams {
  int levels = 4;          // pyramid levels L, [1, 8]; level 0 is the coarsest
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
