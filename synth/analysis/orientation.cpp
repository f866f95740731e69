#include "analysis/orientation.h"

#include <cmath>

namespace solidtex {

StripeOrientation estimate_stripe_orientation(const ImageF& img) {
  auto lum = [&](int x, int y) {
    const float* p = img.at(x, y);
    return img.channels >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : double(p[0]);
  };
  double jxx = 0, jyy = 0, jxy = 0;
  for (int y = 1; y + 1 < img.height; ++y)
    for (int x = 1; x + 1 < img.width; ++x) {
      const double gx = 0.5 * (lum(x + 1, y) - lum(x - 1, y));
      const double gy = 0.5 * (lum(x, y + 1) - lum(x, y - 1));
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

const char* auto_grain_layout(const StripeOrientation& o) {
  if (o.coherence < kAutoGrainMinCoherence) return "";
  if (std::abs(o.degrees) <= kAutoGrainMaxDegrees) return "x";
  if (std::abs(std::abs(o.degrees) - 90.0) <= kAutoGrainMaxDegrees) return "y";
  return "";
}

}  // namespace solidtex
