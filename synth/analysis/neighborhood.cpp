#include "analysis/neighborhood.h"

namespace solidtex {

void gather_neighborhood(const ImageF& stack, ExemplarPixel center, int n, int spacing, float* out) {
  const int half = n / 2;
  const int c = stack.channels;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const float* p = stack.wrapped(center.x + spacing * (i - half), center.y + spacing * (j - half));
      for (int k = 0; k < c; ++k) *out++ = p[k];
    }
  }
}

void gather_line(const ImageF& stack, ExemplarPixel center, LineAxis axis, int n, int spacing, float* out) {
  const int half = n / 2;
  const int c = stack.channels;
  for (int i = 0; i < n; ++i) {
    const int d = spacing * (i - half);
    const float* p = axis == LineAxis::kFirst ? stack.wrapped(center.x + d, center.y)
                                              : stack.wrapped(center.x, center.y + d);
    for (int k = 0; k < c; ++k) *out++ = p[k];
  }
}

}  // namespace solidtex
