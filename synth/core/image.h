// A plain float image: the in-memory form of exemplars, masks, stacks and slices.
// Pixels are interleaved, row-major, `channels` floats each. Color images hold *linear* RGB.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/types.h"

namespace solidtex {

struct ImageF {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;  // size width*height*channels

  ImageF() = default;
  ImageF(int w, int h, int c) : width(w), height(h), channels(c), pixels(size_t(w) * h * c, 0.f) {}

  bool empty() const { return width == 0 || height == 0; }
  int64_t pixel_count() const { return int64_t(width) * height; }
  float* at(int x, int y) { return &pixels[(size_t(y) * width + x) * channels]; }
  const float* at(int x, int y) const { return &pixels[(size_t(y) * width + x) * channels]; }
  // Toroidal access: any integer coordinate wraps around (exemplars tile).
  const float* wrapped(int x, int y) const { return at(wrap(x, width), wrap(y, height)); }
  static int wrap(int v, int n) {
    int r = v % n;
    return r < 0 ? r + n : r;
  }
  friend bool operator==(const ImageF&, const ImageF&) = default;
};

// Eq. 4 (Zhang §2): moving by a 3D step d moves plane k's pixel by (d[first_k], d[second_k]),
// wrapped on plane k's image (`planes[k]`, toroidal).
CoordinateTriple shift_triple(const CoordinateTriple& t, const int d[3], const std::array<const ImageF*, kNumPlanes>& planes);

// Swaps the axes: out(x, y) = in(y, x).
ImageF transposed(const ImageF& in);

// A 3-channel width x height image of `rgb` samples in row order (synthesis answers: a cut's
// pixels, or a box's voxels with height = H * D).
ImageF rgb_image(const std::vector<std::array<float, 3>>& rgb, int width, int height);

// sRGB transfer curve, per channel value in [0, 1].
float srgb_to_linear(float v);
float linear_to_srgb(float v);

}  // namespace solidtex
