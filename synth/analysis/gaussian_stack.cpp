#include "analysis/gaussian_stack.h"

namespace solidtex {
namespace {

ImageF filter_axis(const ImageF& in, int step, bool along_x) {
  static constexpr float kTaps[5] = {1.f / 16, 4.f / 16, 6.f / 16, 4.f / 16, 1.f / 16};
  ImageF out(in.width, in.height, in.channels);
  for (int y = 0; y < in.height; ++y) {
    for (int x = 0; x < in.width; ++x) {
      float* o = out.at(x, y);
      for (int t = 0; t < 5; ++t) {
        const int d = (t - 2) * step;
        const float* p = along_x ? in.wrapped(x + d, y) : in.wrapped(x, y + d);
        for (int c = 0; c < in.channels; ++c) o[c] += kTaps[t] * p[c];
      }
    }
  }
  return out;
}

}  // namespace

std::vector<ImageF> build_gaussian_stack(const ImageF& image, int count) {
  std::vector<ImageF> stack;
  stack.reserve(count);
  stack.push_back(image);
  for (int s = 1; s < count; ++s) {
    const int step = 1 << (s - 1);
    stack.push_back(filter_axis(filter_axis(stack.back(), step, true), step, false));
  }
  return stack;
}

}  // namespace solidtex
