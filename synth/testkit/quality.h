// Image measures used by tests and benchmarks to judge synthesized cuts.
#pragma once

#include "core/image.h"

namespace solidtex {

// Dominant orientation of stripes in an image, in degrees in (-90, 90], measured by the
// structure tensor of luminance (0 = stripes running along x, 90 = along y).
double dominant_orientation_degrees(const ImageF& image);

// Dominant period along x in pixels: the peak of the summed power spectra of the rows (mean
// removed), refined by parabolic interpolation between frequency bins (>= 2 cycles).
double dominant_period_x(const ImageF& image);

// Neighborhood-matching energy: the mean, over every N x N neighborhood that fits inside
// `cut` (taken every `stride` pixels), of the squared distance per element to its nearest
// neighborhood of `exemplar` (toroidal). Lower means the cut looks more like the exemplar.
// It rewards blur (a smooth neighborhood always finds a smooth match): judge synthesis with
// coverage() and sharpness_ratio() too, which see blur and missing variety.
double neighborhood_energy(const ImageF& cut, const ImageF& exemplar, int n, int stride = 1);

// The other direction: the mean, over exemplar N x N neighborhoods (every `stride` pixels,
// toroidal), of the squared distance per element to the nearest neighborhood inside `cut`.
// High when the cut misses detail or variety of the exemplar (blur, repetition, blobs).
double coverage(const ImageF& cut, const ImageF& exemplar, int n, int stride = 1);

// Mean gradient magnitude of luminance (forward differences) of `cut` (inside it) over that of
// `exemplar` (toroidal): about 1 when the cut is as crisp as the exemplar, well below when blurred.
double sharpness_ratio(const ImageF& cut, const ImageF& exemplar);

// Test and benchmark references: a w x h window of `img` at (x0, y0), wrapping around its
// edges, and a separable Gaussian blur (toroidal, sigma in pixels).
ImageF toroidal_crop(const ImageF& img, int x0, int y0, int w, int h);
ImageF gaussian_blur(const ImageF& img, double sigma);

}  // namespace solidtex
