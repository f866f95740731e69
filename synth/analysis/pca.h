// Principal component analysis of neighborhood vectors, to match in a small appearance
// space (Zhang §4.3: about 20 dimensions per plane). Deterministic: samples are taken on a
// fixed pixel lattice, eigenvectors are sign-normalised (largest |component| positive).
#pragma once

#include <vector>

#include "core/status.h"

namespace solidtex {

struct PcaBasis {
  int input_dims = 0;
  int output_dims = 0;
  std::vector<float> mean;   // input_dims
  std::vector<float> basis;  // output_dims rows of input_dims, most significant first
  friend bool operator==(const PcaBasis&, const PcaBasis&) = default;
};

// The one projection into appearance space (analysis and synthesis both use it):
// out[r] = sum over i ascending of basis_r[i] * (in[i] - mean[i]). The basis is kept
// transposed (input-major) so each input feeds output_dims independent accumulators, which
// vectorise; the order per output is fixed, so every build and clone gives the same bits.
// Rows are zero-padded to `stride` (a multiple of 8, at most 64) so the accumulators are a
// compile-time block that stays in registers.
struct PcaProjection {
  int input_dims = 0;
  int output_dims = 0;
  int stride = 0;              // output_dims rounded up to a multiple of 8
  std::vector<float> mean;     // input_dims
  std::vector<float> basis_t;  // input_dims rows of `stride` (columns past output_dims are 0)

  static PcaProjection of(const PcaBasis& b);
  void project(const float* in, float* out) const;
};

// `samples` holds `count` vectors of `dims` floats. output_dims is clamped to dims.
Result<PcaBasis> fit_pca(const std::vector<float>& samples, int count, int dims, int output_dims);

}  // namespace solidtex
