#include "testkit/quality.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <vector>

#include "analysis/knn_index.h"
#include "analysis/orientation.h"
#include "analysis/neighborhood.h"

namespace solidtex {

double dominant_orientation_degrees(const ImageF& img) { return estimate_stripe_orientation(img).degrees; }

double dominant_period_x(const ImageF& img) {
  const int w = img.width;
  std::vector<double> power(size_t(w / 2 + 1), 0.0);
  std::vector<double> row(static_cast<size_t>(w));
  for (int y = 0; y < img.height; ++y) {
    double mean = 0;
    for (int x = 0; x < w; ++x) {
      const float* p = img.at(x, y);
      row[size_t(x)] = img.channels >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : p[0];
      mean += row[size_t(x)] / w;
    }
    for (int k = 1; k <= w / 2; ++k) {
      double re = 0, im = 0;
      for (int x = 0; x < w; ++x) {
        re += (row[size_t(x)] - mean) * std::cos(2 * M_PI * k * x / w);
        im -= (row[size_t(x)] - mean) * std::sin(2 * M_PI * k * x / w);
      }
      power[size_t(k)] += re * re + im * im;
    }
  }
  int best = 2;
  for (int k = 2; k <= w / 2; ++k)
    if (power[size_t(k)] > power[size_t(best)]) best = k;
  double peak = best;
  if (best > 1 && best < w / 2) {
    const double a = power[size_t(best - 1)], b = power[size_t(best)], c = power[size_t(best + 1)];
    const double denom = a - 2 * b + c;
    if (denom != 0) peak = best + 0.5 * (a - c) / denom;
  }
  return double(w) / peak;
}

double neighborhood_energy(const ImageF& cut, const ImageF& exemplar, int n, int stride) {
  const int dims = neighborhood_dims(n, exemplar.channels);
  std::vector<float> ex(size_t(exemplar.pixel_count()) * dims);
  for (int y = 0; y < exemplar.height; ++y)
    for (int x = 0; x < exemplar.width; ++x)
      gather_neighborhood(exemplar, {x, y}, n, 1, &ex[(size_t(y) * exemplar.width + x) * dims]);
  const int h = n / 2;
  std::vector<std::pair<int, int>> centres;
  for (int y = h; y + h < cut.height; y += stride)
    for (int x = h; x + h < cut.width; x += stride) centres.emplace_back(x, y);
  std::vector<double> best(centres.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, centres.size()), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<float> q(static_cast<size_t>(dims));
    std::vector<int> idx;
    std::vector<float> dist;
    for (size_t i = r.begin(); i != r.end(); ++i) {
      gather_neighborhood(cut, {centres[i].first, centres[i].second}, n, 1, q.data());
      exact_knn(ex.data(), int(exemplar.pixel_count()), dims, q.data(), 1, idx, dist);
      best[i] = dist[0] / dims;
    }
  });
  double sum = 0;
  for (double b : best) sum += b;
  return centres.empty() ? 0.0 : sum / double(centres.size());
}

double coverage(const ImageF& cut, const ImageF& exemplar, int n, int stride) {
  const int dims = neighborhood_dims(n, cut.channels);
  const int h = n / 2;
  std::vector<float> in_cut;
  for (int y = h; y + h < cut.height; ++y)
    for (int x = h; x + h < cut.width; ++x) {
      in_cut.resize(in_cut.size() + size_t(dims));
      gather_neighborhood(cut, {x, y}, n, 1, &in_cut[in_cut.size() - size_t(dims)]);
    }
  const int count = int(in_cut.size() / size_t(dims));
  std::vector<std::pair<int, int>> centres;
  for (int y = 0; y < exemplar.height; y += stride)
    for (int x = 0; x < exemplar.width; x += stride) centres.emplace_back(x, y);
  if (count == 0 || centres.empty()) return 0.0;
  std::vector<double> best(centres.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, centres.size()), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<float> q(static_cast<size_t>(dims));
    std::vector<int> idx;
    std::vector<float> dist;
    for (size_t i = r.begin(); i != r.end(); ++i) {
      gather_neighborhood(exemplar, {centres[i].first, centres[i].second}, n, 1, q.data());
      exact_knn(in_cut.data(), count, dims, q.data(), 1, idx, dist);
      best[i] = dist[0] / dims;
    }
  });
  double sum = 0;
  for (double b : best) sum += b;
  return sum / double(centres.size());
}

namespace {
double luminance(const ImageF& img, int x, int y) {
  const float* p = img.wrapped(x, y);
  return img.channels >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : p[0];
}
double mean_gradient(const ImageF& img, bool toroidal) {
  double sum = 0;
  int64_t count = 0;
  const int w = toroidal ? img.width : img.width - 1, hgt = toroidal ? img.height : img.height - 1;
  for (int y = 0; y < hgt; ++y)
    for (int x = 0; x < w; ++x) {
      const double l = luminance(img, x, y);
      const double gx = luminance(img, x + 1, y) - l, gy = luminance(img, x, y + 1) - l;
      sum += std::sqrt(gx * gx + gy * gy);
      ++count;
    }
  return count ? sum / double(count) : 0.0;
}
}  // namespace

double sharpness_ratio(const ImageF& cut, const ImageF& exemplar) {
  const double e = mean_gradient(exemplar, true);
  return e > 0 ? mean_gradient(cut, false) / e : 0.0;
}

ImageF toroidal_crop(const ImageF& img, int x0, int y0, int w, int h) {
  ImageF out(w, h, img.channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < img.channels; ++c) out.at(x, y)[c] = img.wrapped(x0 + x, y0 + y)[c];
  return out;
}

ImageF gaussian_blur(const ImageF& img, double sigma) {
  const int r = int(std::ceil(3 * sigma));
  std::vector<float> k(size_t(2 * r + 1));
  float total = 0;
  for (int i = -r; i <= r; ++i) total += k[size_t(i + r)] = float(std::exp(-0.5 * i * i / (sigma * sigma)));
  for (float& v : k) v /= total;
  ImageF tmp(img.width, img.height, img.channels), out(img.width, img.height, img.channels);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < img.channels; ++c) {
        float s = 0;
        for (int i = -r; i <= r; ++i) s += k[size_t(i + r)] * img.wrapped(x + i, y)[c];
        tmp.at(x, y)[c] = s;
      }
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < img.channels; ++c) {
        float s = 0;
        for (int i = -r; i <= r; ++i) s += k[size_t(i + r)] * tmp.wrapped(x, y + i)[c];
        out.at(x, y)[c] = s;
      }
  return out;
}

}  // namespace solidtex
