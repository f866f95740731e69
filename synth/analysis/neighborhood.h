// Sampling exemplar neighborhoods and crossbar lines at a pyramid level's spacing h.
// A neighborhood of size N around pixel p holds, row-major, the pixels
// p + h*(i - N/2, j - N/2) for j, i in [0, N), each with all channels of the image.
// Lines are the 1D pieces along one axis: kFirst varies the first coordinate (x of xy,
// y of yz, z of zx), kSecond varies the second one.
#pragma once

#include "core/image.h"
#include "core/types.h"

namespace solidtex {

enum class LineAxis { kFirst = 0, kSecond = 1 };

inline int neighborhood_dims(int n, int channels) { return n * n * channels; }
inline int line_dims(int n, int channels) { return n * channels; }

void gather_neighborhood(const ImageF& stack, ExemplarPixel center, int n, int spacing, float* out);
void gather_line(const ImageF& stack, ExemplarPixel center, LineAxis axis, int n, int spacing, float* out);

}  // namespace solidtex
