#include "analysis/orientation.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace solidtex {
namespace {

struct Luminance {
  int width = 0, height = 0;
  std::vector<double> v;
  double at(int x, int y) const { return v[size_t(y) * size_t(width) + size_t(x)]; }
};

Luminance luminance(const ImageF& img) {
  Luminance l{img.width, img.height, std::vector<double>(size_t(img.width) * size_t(img.height))};
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const float* p = img.at(x, y);
      l.v[size_t(y) * size_t(img.width) + size_t(x)] =
          img.channels >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : double(p[0]);
    }
  return l;
}

// Separable Gaussian blur, borders clamped (exemplars need not tile).
Luminance blurred(const Luminance& in, double sigma) {
  const int r = int(std::ceil(3 * sigma));
  std::vector<double> k(size_t(2 * r + 1));
  double sum = 0;
  for (int i = -r; i <= r; ++i) sum += k[size_t(i + r)] = std::exp(-0.5 * i * i / (sigma * sigma));
  for (double& w : k) w /= sum;
  Luminance tmp = in, out = in;
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x) {
      double a = 0;
      for (int i = -r; i <= r; ++i) a += k[size_t(i + r)] * in.at(std::clamp(x + i, 0, in.width - 1), y);
      tmp.v[size_t(y) * size_t(in.width) + size_t(x)] = a;
    }
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x) {
      double a = 0;
      for (int i = -r; i <= r; ++i) a += k[size_t(i + r)] * tmp.at(x, std::clamp(y + i, 0, in.height - 1));
      out.v[size_t(y) * size_t(in.width) + size_t(x)] = a;
    }
  return out;
}

StripeOrientation at_one_scale(const Luminance& l) {
  double jxx = 0, jyy = 0, jxy = 0;
  for (int y = 1; y + 1 < l.height; ++y)
    for (int x = 1; x + 1 < l.width; ++x) {
      const double gx = 0.5 * (l.at(x + 1, y) - l.at(x - 1, y));
      const double gy = 0.5 * (l.at(x, y + 1) - l.at(x, y - 1));
      jxx += gx * gx;
      jyy += gy * gy;
      jxy += gx * gy;
    }
  StripeOrientation o;
  const double trace = jxx + jyy;
  if (!(trace > 0.0) || !std::isfinite(trace)) return o;
  o.coherence = std::sqrt((jxx - jyy) * (jxx - jyy) + 4.0 * jxy * jxy) / trace;
  // Gradient direction, then the stripes run perpendicular to it.
  double stripes = 0.5 * std::atan2(2 * jxy, jxx - jyy) * 180.0 / M_PI + 90.0;
  while (stripes > 90.0) stripes -= 180.0;
  while (stripes <= -90.0) stripes += 180.0;
  o.degrees = stripes;
  return o;
}

}  // namespace

StripeOrientation estimate_stripe_orientation(const ImageF& img) {
  const Luminance l = luminance(img);
  StripeOrientation best = at_one_scale(l);
  for (const double sigma : kOrientationBlurSigmas) {
    const StripeOrientation o = at_one_scale(blurred(l, sigma));
    if (o.coherence > best.coherence) best = o;
  }
  return best;
}

const char* auto_grain_layout(const StripeOrientation& o) {
  if (o.coherence < kAutoGrainMinCoherence) return "";
  if (std::abs(o.degrees) <= kAutoGrainMaxDegrees) return "x";
  if (std::abs(std::abs(o.degrees) - 90.0) <= kAutoGrainMaxDegrees) return "y";
  return "";
}

}  // namespace solidtex
