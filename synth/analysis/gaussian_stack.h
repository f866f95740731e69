// Gaussian image stack (Lefebvre & Hoppe 2005; Zhang §4.2.1): every level keeps the full
// exemplar resolution, blurred as much as the matching pyramid level would be, with toroidal
// borders. Stack index 0 is the original; index s is comparable to a pyramid level of
// spacing 2^s. Deterministic: a fixed sequence of float operations per pixel.
#pragma once

#include <vector>

#include "core/image.h"

namespace solidtex {

// Returns `count` images; image s is image s-1 filtered by the binomial kernel
// [1 4 6 4 1]/16 with taps 2^(s-1) pixels apart (a trous), separably along x then y.
std::vector<ImageF> build_gaussian_stack(const ImageF& image, int count);

}  // namespace solidtex
