// Typicality of exemplar neighborhoods: a per-pixel, non-negative matching-cost penalty that is
// largest for the pixels whose appearance vector lies nearest the exemplar's mean appearance.
//
// Why (issue 12): an L2 neighborhood match regresses to the mean. In solid synthesis no
// candidate fits all three planes exactly, and a smooth, average-looking exemplar patch is the
// least-bad fit for every imperfect neighborhood; once chosen it makes the neighborhoods around
// it smoother still, and slices collapse into flat blobs (pebbles become orange patches).
// Synthesis adds `typicality * penalty(a)` to the cost of each plane's match (correction.h), which
// is the same argmin as  |q - a|^2 - typicality * e(a): a pull away from the mean that a crisp,
// distinctive neighborhood needs to win. Kopf et al. 2007 counter the same pull with histogram
// matching, a global statistic of the volume; this is a fixed function of the table, so
// synthesis stays spatially deterministic.
//
// Definition, per distinct image and level, over its appearance vectors a (PCA coefficients):
//   e(a) = sum_r w_r (a_r - m_r)^2,  m_r, v_r the mean and variance of coefficient r over all
//   pixels, w_r = sqrt(mean_r(v) / v_r) (half-whitened: unweighted, the first coefficient, the
//   patch's brightness, dominates and extremes of brightness win; fully whitened, the
//   low-variance high-frequency coefficients dominate and noise wins);
//   penalty(a) = max over pixels of e - e(a), so penalties are >= 0 and match costs stay
//   non-negative (the correction's early exit needs that).
// Units: squared appearance distance, the match cost's. Deterministic: fixed-order sums in double.
#pragma once

#include <vector>

namespace solidtex {

// `projected` holds one row of `dims` coefficients per pixel; returns one penalty per pixel.
std::vector<float> typicality_penalty(const std::vector<float>& projected, int dims);

}  // namespace solidtex
