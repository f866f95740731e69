#include "analysis/typicality.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace solidtex {

std::vector<float> typicality_penalty(const std::vector<float>& projected, int dims) {
  const size_t d = size_t(std::max(dims, 1));
  const size_t pixels = projected.size() / d;
  std::vector<float> out(pixels, 0.f);
  if (pixels == 0 || dims < 1) return out;
  std::vector<double> mean(d, 0.0), var(d, 0.0);
  for (size_t p = 0; p < pixels; ++p)
    for (size_t r = 0; r < d; ++r) mean[r] += projected[p * d + r];
  for (double& m : mean) m /= double(pixels);
  for (size_t p = 0; p < pixels; ++p)
    for (size_t r = 0; r < d; ++r) {
      const double x = projected[p * d + r] - mean[r];
      var[r] += x * x;
    }
  double mean_var = 0;
  for (double& v : var) {
    v /= double(pixels);
    mean_var += v;
  }
  mean_var /= double(d);
  std::vector<double> weight(d, 0.0);
  // A coefficient with no spread over the image says nothing about typicality.
  for (size_t r = 0; r < d; ++r) weight[r] = var[r] > 1e-12 * mean_var ? std::sqrt(mean_var / var[r]) : 0.0;
  std::vector<double> e(pixels, 0.0);
  double largest = 0;
  for (size_t p = 0; p < pixels; ++p) {
    double s = 0;
    for (size_t r = 0; r < d; ++r) {
      const double x = projected[p * d + r] - mean[r];
      s += weight[r] * x * x;
    }
    e[p] = s;
    largest = std::max(largest, s);
  }
  for (size_t p = 0; p < pixels; ++p) out[p] = float(largest - e[p]);
  return out;
}

}  // namespace solidtex
