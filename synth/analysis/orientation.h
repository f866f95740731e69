// Dominant stripe orientation of an exemplar, from the structure tensor of its luminance.
//
// The tensor J = sum over interior pixels of g g^T (g: central-difference luminance
// gradient) gives the gradient's dominant direction; stripes run perpendicular to it.
// Coherence (l1 - l2) / (l1 + l2) of J's eigenvalues is 0 for isotropic images and 1 for
// perfect stripes. Measured on the shared exemplars: stripes_dunes 0.86; every other one
// <= 0.43 (wood_planks 0.43, wood_grain 0.34, pebbles 0.32, gravel 0.06). Pure function of
// the pixels; thread-safe.
#pragma once

#include "core/image.h"

namespace solidtex {

struct StripeOrientation {
  double degrees = 0.0;    // stripes' direction in (-90, 90]: 0 = along x, 90 = along y
  double coherence = 0.0;  // [0, 1]; 0 when the image has no gradient at all
};

StripeOrientation estimate_stripe_orientation(const ImageF& image);

// The grain layout `grain=auto` picks (exemplar.h: apply_grain_layout): "x" for stripes
// within kAutoGrainMaxDegrees of x, "y" likewise for y, both only at coherence >=
// kAutoGrainMinCoherence; "" (isotropic) otherwise. The threshold sits between the shared
// exemplars' 0.86 (strong stripes) and 0.43 (the most oriented of the rest).
inline constexpr double kAutoGrainMinCoherence = 0.6;
inline constexpr double kAutoGrainMaxDegrees = 20.0;
const char* auto_grain_layout(const StripeOrientation& o);

}  // namespace solidtex
