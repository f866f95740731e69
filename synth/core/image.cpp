#include "core/image.h"

#include <cmath>

namespace solidtex {

ImageF rgb_image(const std::vector<std::array<float, 3>>& rgb, int width, int height) {
  ImageF img(width, height, 3);
  for (size_t i = 0; i < rgb.size() && i < img.pixels.size() / 3; ++i)
    for (size_t c = 0; c < 3; ++c) img.pixels[i * 3 + c] = rgb[i][c];
  return img;
}

CoordinateTriple shift_triple(const CoordinateTriple& t, const int d[3], const std::array<const ImageF*, kNumPlanes>& planes) {
  CoordinateTriple out;
  for (int k = 0; k < kNumPlanes; ++k) {
    const ImageF& img = *planes[size_t(k)];
    out.at[size_t(k)] = {ImageF::wrap(t.at[size_t(k)].x + d[kPlaneFirstAxis[size_t(k)]], img.width),
                         ImageF::wrap(t.at[size_t(k)].y + d[kPlaneSecondAxis[size_t(k)]], img.height)};
  }
  return out;
}

ImageF transposed(const ImageF& in) {
  ImageF out(in.height, in.width, in.channels);
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x)
      for (int c = 0; c < in.channels; ++c) out.at(y, x)[c] = in.at(x, y)[c];
  return out;
}

float srgb_to_linear(float v) {
  if (v <= 0.04045f) return v / 12.92f;
  return std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float linear_to_srgb(float v) {
  if (v <= 0.f) return 0.f;
  if (v >= 1.f) return 1.f;
  if (v <= 0.0031308f) return v * 12.92f;
  return 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

}  // namespace solidtex
