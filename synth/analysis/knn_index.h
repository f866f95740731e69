// k-nearest-neighbour search over fixed-length float vectors (squared L2), with FLANN.
//
// Reproducibility: FLANN 1.9's randomized kd-trees shuffle with std::random_device and
// cannot be seeded, so tables built with them differ run to run. We use FLANN's hierarchical
// k-means tree with k-means++ centres instead: it draws only from std::rand, which
// flann::seed_random() seeds; building holds a process-wide lock so the seeded sequence is
// ours alone. Search is read-only and thread-safe; results are independent of thread count.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/status.h"

namespace solidtex {

struct KnnParams {
  int branching = 16;     // k-means tree branching factor, [2, 256]
  int iterations = 7;     // k-means iterations per tree node, [1, 100]
  int checks = 192;       // leaves visited per query: recall versus speed, [1, 100000]
  uint32_t seed = 1;      // seeds centre selection
};

class KnnIndex {
 public:
  // `data` holds `count` rows of `dims` floats and must outlive the index.
  static Result<KnnIndex> build(const float* data, int count, int dims, const KnnParams& params);
  KnnIndex(KnnIndex&&) noexcept;
  KnnIndex& operator=(KnnIndex&&) noexcept;
  ~KnnIndex();

  // Writes min(k, count) neighbours of `query`, nearest first (ties by lower index).
  void search(const float* query, int k, std::vector<int>& indices, std::vector<float>& sq_dists) const;
  int count() const;
  int dims() const;

 private:
  struct Impl;
  explicit KnnIndex(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Exact k nearest neighbours by brute force (reference for recall checks).
void exact_knn(const float* data, int count, int dims, const float* query, int k,
               std::vector<int>& indices, std::vector<float>& sq_dists);

}  // namespace solidtex
