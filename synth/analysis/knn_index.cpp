#include "analysis/knn_index.h"

#include <flann/flann.hpp>

#include <algorithm>
#include <mutex>
#include <numeric>

namespace solidtex {

struct KnnIndex::Impl {
  flann::Matrix<float> dataset;
  std::unique_ptr<flann::Index<flann::L2<float>>> index;
  int checks = 0;
};

KnnIndex::KnnIndex(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
KnnIndex::KnnIndex(KnnIndex&&) noexcept = default;
KnnIndex& KnnIndex::operator=(KnnIndex&&) noexcept = default;
KnnIndex::~KnnIndex() = default;

Result<KnnIndex> KnnIndex::build(const float* data, int count, int dims, const KnnParams& p) {
  if (count < 1 || dims < 1) return Status(StatusCode::kInvalidArgument, "k-NN index needs data");
  static std::mutex rand_lock;  // std::rand is process-global state
  auto impl = std::make_unique<Impl>();
  impl->dataset = flann::Matrix<float>(const_cast<float*>(data), size_t(count), size_t(dims));
  impl->checks = p.checks;
  try {
    std::lock_guard<std::mutex> guard(rand_lock);
    flann::seed_random(p.seed);
    impl->index = std::make_unique<flann::Index<flann::L2<float>>>(
        impl->dataset, flann::KMeansIndexParams(p.branching, p.iterations, flann::FLANN_CENTERS_KMEANSPP));
    impl->index->buildIndex();
  } catch (const std::exception& e) {
    return Status(StatusCode::kInternal, std::string("FLANN index build failed: ") + e.what());
  }
  return KnnIndex(std::move(impl));
}

void KnnIndex::search(const float* query, int k, std::vector<int>& indices, std::vector<float>& sq_dists) const {
  const int n = std::min<int>(k, int(impl_->dataset.rows));
  indices.assign(size_t(n), -1);
  sq_dists.assign(size_t(n), 0.f);
  flann::Matrix<float> q(const_cast<float*>(query), 1, impl_->dataset.cols);
  flann::Matrix<int> idx(indices.data(), 1, size_t(n));
  flann::Matrix<float> dst(sq_dists.data(), 1, size_t(n));
  flann::SearchParams sp(impl_->checks);
  sp.cores = 1;
  sp.sorted = true;
  impl_->index->knnSearch(q, idx, dst, size_t(n), sp);
  // Drop unfilled slots (fewer reachable points than k) and make tie order explicit.
  std::vector<std::pair<float, int>> pairs;
  for (int i = 0; i < n; ++i)
    if (indices[i] >= 0) pairs.emplace_back(sq_dists[i], indices[i]);
  std::sort(pairs.begin(), pairs.end());
  indices.resize(pairs.size());
  sq_dists.resize(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    sq_dists[i] = pairs[i].first;
    indices[i] = pairs[i].second;
  }
}

int KnnIndex::count() const { return int(impl_->dataset.rows); }
int KnnIndex::dims() const { return int(impl_->dataset.cols); }

void exact_knn(const float* data, int count, int dims, const float* query, int k,
               std::vector<int>& indices, std::vector<float>& sq_dists) {
  std::vector<std::pair<float, int>> all(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    const float* row = data + size_t(i) * dims;
    float s = 0;
    for (int d = 0; d < dims; ++d) {
      float t = row[d] - query[d];
      s += t * t;
    }
    all[i] = {s, i};
  }
  const int n = std::min(k, count);
  std::partial_sort(all.begin(), all.begin() + n, all.end());
  indices.resize(n);
  sq_dists.resize(n);
  for (int i = 0; i < n; ++i) {
    sq_dists[i] = all[i].first;
    indices[i] = all[i].second;
  }
}

}  // namespace solidtex
