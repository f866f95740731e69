#include "analysis/candidate_triples.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

#include "core/hash.h"
#include "analysis/neighborhood.h"

namespace solidtex {
namespace {

// Axes (0 = x, 1 = y, 2 = z) of each plane's first and second coordinate.

using LineSet = CrossbarSearch::Lines;

LineSet build_lines(const ImageF& img, int n, int spacing) {
  LineSet s;
  s.width = img.width;
  s.height = img.height;
  s.dims = line_dims(n, img.channels);
  s.first.resize(size_t(img.pixel_count()) * s.dims);
  s.second.resize(size_t(img.pixel_count()) * s.dims);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      size_t i = size_t(y) * img.width + x;
      gather_line(img, {x, y}, LineAxis::kFirst, n, spacing, &s.first[i * s.dims]);
      gather_line(img, {x, y}, LineAxis::kSecond, n, spacing, &s.second[i * s.dims]);
    }
  return s;
}

float sq_dist(const float* a, const float* b, int dims) {
  float s = 0;
  for (int i = 0; i < dims; ++i) {
    float d = a[i] - b[i];
    s += d * d;
  }
  return s;
}

ExemplarPixel pixel_of(int index, int width) { return {index % width, index / width}; }


struct Scored {
  float error;
  CoordinateTriple t;
};

bool by_error_then_triple(const Scored& u, const Scored& v) { return u.error < v.error || (u.error == v.error && u.t < v.t); }

}  // namespace

CoordinateTriple rotate_planes(const CoordinateTriple& t, int k) {
  CoordinateTriple out;
  for (int j = 0; j < 3; ++j) out.at[j] = t.at[((j - k) % 3 + 3) % 3];
  return out;
}

double crossbar_error(const PlaneStacks& stacks, const CoordinateTriple& t, int n, int spacing) {
  const int c = stacks[0]->channels;
  float a[16 * 4], b[16 * 4];  // n <= 15, channels <= 4
  double total = 0;
  for (int k = 0; k < 3; ++k) {
    gather_line(*stacks[k], t.at[k], LineAxis::kSecond, n, spacing, a);
    gather_line(*stacks[(k + 1) % 3], t.at[(k + 1) % 3], LineAxis::kFirst, n, spacing, b);
    total += sq_dist(a, b, n * c);
  }
  return total / (3.0 * n * c);
}

void measure_level_candidates(const PlaneStacks& stacks, int n, int spacing, uint32_t seed, LevelCandidates& level) {
  // Per-row partial sums, added in row order: the figure does not depend on thread count.
  // With one image for all planes, planes yz and zx are rotations of xy with equal errors.
  const bool shared = stacks[0] == stacks[1] && stacks[1] == stacks[2];
  double sum = 0;
  int64_t count = 0;
  for (int k = 0; k < (shared ? 1 : 3); ++k) {
    const PlaneCandidates& pc = level.planes[k];
    std::vector<double> row_sum(size_t(pc.height), 0.0);
    tbb::parallel_for(tbb::blocked_range<int>(0, pc.height), [&](const tbb::blocked_range<int>& rows) {
      for (int y = rows.begin(); y != rows.end(); ++y)
        for (int x = 0; x < pc.width; ++x)
          for (const CoordinateTriple& t : pc.at({x, y})) row_sum[y] += crossbar_error(stacks, t, n, spacing);
    });
    for (double r : row_sum) sum += r;
    for (uint8_t c : pc.counts) count += c;
  }
  level.mean_crossbar_error = count ? sum / double(count) : 0;
  // Random baseline: 4096 uniformly random triples from a hash of (index, spacing, seed).
  const int samples = 4096;
  double rsum = 0;
  for (int i = 0; i < samples; ++i) {
    CoordinateTriple t;
    for (int k = 0; k < 3; ++k) {
      uint64_t h = hash_u64(uint64_t(i), uint64_t(spacing), uint64_t(seed) * 3 + k);
      t.at[k] = {int32_t(h % uint64_t(stacks[k]->width)), int32_t((h >> 32) % uint64_t(stacks[k]->height))};
    }
    rsum += crossbar_error(stacks, t, n, spacing);
  }
  level.random_crossbar_error = rsum / samples;
}

Result<CrossbarSearch> prepare_crossbar_search(const PlaneStacks& stacks, bool shared, int spacing,
                                               const CandidateParams& params, uint32_t seed) {
  CrossbarSearch search;
  search.stacks = stacks;
  search.shared = shared;
  search.spacing = spacing;
  const int distinct = shared ? 1 : 3;
  for (int k = 0; k < distinct; ++k) search.lines[k] = build_lines(*stacks[k], params.neighborhood, spacing);
  const int dims = search.lines[0].dims;
  // Indices: first-axis lines and second-axis lines of each distinct image.
  for (int k = 0; k < distinct; ++k) {
    KnnParams kp = params.knn;
    // Same seed for every plane: identical images then get identical indices (symmetry).
    kp.seed = params.knn.seed ^ (seed * 7919u + uint32_t(spacing));
    const int count = stacks[k]->width * stacks[k]->height;
    SOLIDTEX_ASSIGN_OR_RETURN(auto fi, KnnIndex::build(search.lines[k].first.data(), count, dims, kp));
    SOLIDTEX_ASSIGN_OR_RETURN(auto si, KnnIndex::build(search.lines[k].second.data(), count, dims, kp));
    search.first_index.push_back(std::move(fi));
    search.second_index.push_back(std::move(si));
  }
  return search;
}

Result<LevelCandidates> compute_level_candidates(const PlaneStacks& stacks, bool shared, int spacing,
                                                 const CandidateParams& params, uint32_t seed,
                                                 const std::function<bool(double)>& progress) {
  SOLIDTEX_ASSIGN_OR_RETURN(CrossbarSearch search, prepare_crossbar_search(stacks, shared, spacing, params, seed));
  return compute_level_candidates(search, params, progress);
}

Result<LevelCandidates> compute_level_candidates(const CrossbarSearch& search, const CandidateParams& params,
                                                 const std::function<bool(double)>& progress) {
  const PlaneStacks& stacks = search.stacks;
  const bool shared = search.shared;
  const int spacing = search.spacing;
  const int nt = params.candidates;
  const int keep = 2 * nt;
  auto lines_of = [&](int k) -> const LineSet& { return search.lines[shared ? 0 : k]; };
  const int dims = search.lines[0].dims;
  auto index_of_first = [&](int k) -> const KnnIndex& { return search.first_index[shared ? 0 : k]; };
  auto index_of_second = [&](int k) -> const KnnIndex& { return search.second_index[shared ? 0 : k]; };

  const int planes_to_search = shared ? 1 : 3;
  int64_t total_rows = 0;
  for (int k = 0; k < planes_to_search; ++k) total_rows += stacks[k]->height;
  std::atomic<int64_t> rows_done{0};
  std::atomic<bool> cancelled{false};

  // Raw best `keep` triples per pixel per plane.
  std::array<std::vector<Scored>, 3> raw;
  std::array<std::vector<uint8_t>, 3> raw_count;
  for (int k = 0; k < planes_to_search; ++k) {
    const ImageF& img = *stacks[k];
    const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    const LineSet& own = lines_of(k);
    const LineSet& next = lines_of(k1);
    const LineSet& prev = lines_of(k2);
    raw[k].resize(size_t(img.pixel_count()) * keep);
    raw_count[k].assign(size_t(img.pixel_count()), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, img.height), [&](const tbb::blocked_range<int>& rows) {
      std::vector<int> qi, ri;
      std::vector<float> qd, rd;
      std::vector<Scored> pairs;
      for (int y = rows.begin(); y != rows.end(); ++y) {
        if (cancelled.load(std::memory_order_relaxed)) return;
        for (int x = 0; x < img.width; ++x) {
          const size_t p = size_t(y) * img.width + x;
          index_of_first(k1).search(&own.second[p * dims], params.search_k, qi, qd);
          index_of_second(k2).search(&own.first[p * dims], params.search_k, ri, rd);
          // The best `keep` pairs by (error, triple), kept in a max-heap. k-NN distances come
          // nearest first, and error = (qd[a] + rd[b]) + crossbar term >= qd[a] + rd[b] in
          // floats, so once that bound exceeds the heap's worst, the rest of the row (and,
          // at b = 0, every later row) cannot enter: the kept set is exactly the one a full
          // sort of all search_k^2 pairs gives (a strict order: the pairs' triples differ).
          pairs.clear();
          for (size_t a = 0; a < qi.size(); ++a) {
            const float* q_second = &next.second[size_t(qi[a]) * dims];
            for (size_t b = 0; b < ri.size(); ++b) {
              const float bound = qd[a] + rd[b];
              if (pairs.size() == size_t(keep) && bound > pairs.front().error) {
                if (b == 0) a = qi.size() - 1;  // every later row starts higher
                break;
              }
              Scored s;
              s.error = bound + sq_dist(q_second, &prev.first[size_t(ri[b]) * dims], dims);
              s.t.at[k] = {x, y};
              s.t.at[k1] = pixel_of(qi[a], next.width);
              s.t.at[k2] = pixel_of(ri[b], prev.width);
              if (pairs.size() < size_t(keep)) {
                pairs.push_back(s);
                std::push_heap(pairs.begin(), pairs.end(), by_error_then_triple);
              } else if (by_error_then_triple(s, pairs.front())) {
                std::pop_heap(pairs.begin(), pairs.end(), by_error_then_triple);
                pairs.back() = s;
                std::push_heap(pairs.begin(), pairs.end(), by_error_then_triple);
              }
            }
          }
          std::sort_heap(pairs.begin(), pairs.end(), by_error_then_triple);
          const size_t m = pairs.size();
          std::copy(pairs.begin(), pairs.end(), raw[k].begin() + p * keep);
          raw_count[k][p] = uint8_t(m);
        }
        const int64_t done = rows_done.fetch_add(1) + 1;
        if (progress && progress(double(done) / double(total_rows))) cancelled = true;
      }
    });
    if (cancelled) return Status(StatusCode::kCancelled, "analysis cancelled");
  }

  // Coherence selection.
  LevelCandidates level;
  std::atomic<int64_t> coherent_kept{0}, kept{0};
  for (int k = 0; k < planes_to_search; ++k) {
    const ImageF& img = *stacks[k];
    PlaneCandidates& pc = level.planes[k];
    pc.width = img.width;
    pc.height = img.height;
    pc.per_pixel = nt;
    pc.triples.assign(size_t(img.pixel_count()) * nt, CoordinateTriple{});
    pc.counts.assign(size_t(img.pixel_count()), 0);
    const int fa = kPlaneFirstAxis[size_t(k)], sa = kPlaneSecondAxis[size_t(k)];
    tbb::parallel_for(tbb::blocked_range<int>(0, img.height), [&](const tbb::blocked_range<int>& rows) {
      std::vector<Scored> chosen;
      std::vector<char> coherent;
      for (int y = rows.begin(); y != rows.end(); ++y)
        for (int x = 0; x < img.width; ++x) {
          const size_t p = size_t(y) * img.width + x;
          const Scored* mine = &raw[k][p * keep];
          const int cnt = raw_count[k][p];
          coherent.assign(size_t(cnt), 0);
          static constexpr int kDeltas[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
          for (int i = 0; i < cnt; ++i) {
            for (const auto& dl : kDeltas) {
              int d[3] = {0, 0, 0};
              d[fa] = dl[0] * spacing;
              d[sa] = dl[1] * spacing;
              const CoordinateTriple want = shift_triple(mine[i].t, d, stacks);
              const size_t q = size_t(ImageF::wrap(y + dl[1] * spacing, img.height)) * img.width +
                               ImageF::wrap(x + dl[0] * spacing, img.width);
              const Scored* theirs = &raw[k][q * keep];
              for (int j = 0; j < raw_count[k][q] && !coherent[i]; ++j)
                if (theirs[j].t == want) coherent[i] = 1;
              if (coherent[i]) break;
            }
          }
          chosen.clear();
          int64_t coherent_here = 0;
          for (int i = 0; i < cnt && int(chosen.size()) < nt; ++i)
            if (coherent[i]) {
              chosen.push_back(mine[i]);
              ++coherent_here;
            }
          for (int i = 0; i < cnt && int(chosen.size()) < nt; ++i)
            if (!coherent[i]) chosen.push_back(mine[i]);
          coherent_kept += coherent_here;
          kept += int64_t(chosen.size());
          std::sort(chosen.begin(), chosen.end(), [](const Scored& u, const Scored& v) {
            return u.error < v.error || (u.error == v.error && u.t < v.t);
          });
          for (size_t i = 0; i < chosen.size(); ++i) pc.triples[p * nt + i] = chosen[i].t;
          pc.counts[p] = uint8_t(chosen.size());
        }
    });
  }
  level.coherent_fraction = kept ? double(coherent_kept) / double(kept) : 0.0;
  if (shared) {
    for (int k = 1; k < 3; ++k) {
      PlaneCandidates& pc = level.planes[k];
      pc = level.planes[0];
      for (auto& t : pc.triples) t = rotate_planes(t, k);
    }
  }
  return level;
}

}  // namespace solidtex
