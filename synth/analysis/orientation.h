// Dominant stripe orientation of an exemplar, from the structure tensor of its luminance.
//
// The tensor J = sum over interior pixels of g g^T (g: central-difference luminance
// gradient) gives the gradient's dominant direction; stripes run perpendicular to it.
// Coherence (l1 - l2) / (l1 + l2) of J's eigenvalues is 0 for isotropic images and 1 for
// perfect stripes. Photos carry fine isotropic detail on top of their grain (bark's pores
// on its ridges), so the estimate is taken at the pixel scale and after Gaussian blurs of
// kOrientationBlurSigmas, and the most coherent scale wins. Measured on the shared exemplars
// (max over scales): stripes_dunes 0.86, wood_planks 0.71, tree_bark 0.65 (0.20 unblurred),
// wood_grain 0.49; then pebbles 0.37, marble_pink 0.28, bricks 0.28, weave_burlap 0.23,
// gravel 0.07, leopard 0.03. Pure function of the pixels; thread-safe.
#pragma once

#include <array>

#include "core/image.h"

namespace solidtex {

struct StripeOrientation {
  double degrees = 0.0;    // stripes' direction in (-90, 90]: 0 = along x, 90 = along y
  double coherence = 0.0;  // [0, 1]; 0 when the image has no gradient at all
};

inline constexpr std::array<double, 2> kOrientationBlurSigmas{1.0, 2.0};  // pixels

StripeOrientation estimate_stripe_orientation(const ImageF& image);

// The grain layout `grain=auto` picks (exemplar.h: apply_grain_layout): "x" for stripes
// within kAutoGrainMaxDegrees of x, "y" likewise for y, both only at coherence >=
// kAutoGrainMinCoherence; "" (isotropic) otherwise. The threshold sits between the shared
// exemplars' 0.49 (wood_grain, the least coherent grain) and 0.37 (pebbles, the most
// coherent isotropic one).
inline constexpr double kAutoGrainMinCoherence = 0.43;
inline constexpr double kAutoGrainMaxDegrees = 20.0;
const char* auto_grain_layout(const StripeOrientation& o);

}  // namespace solidtex
