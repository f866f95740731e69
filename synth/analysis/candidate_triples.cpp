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
    for (uint8_t c : *pc.counts) count += c;
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

PlaneLayout plane_layout(const std::array<const ImageF*, 3>& images) {
  PlaneLayout layout = kDistinctLayout;
  const ImageF& e = *images[0];
  std::optional<ImageF> et;
  for (int k = 1; k < 3; ++k) {
    const ImageF& img = *images[size_t(k)];
    if (&img == &e || (img.width == e.width && img.height == e.height && img.channels == e.channels &&
                       img.pixels == e.pixels)) {
      layout[size_t(k)] = {0, false};
      continue;
    }
    if (!et) et = transposed(e);
    if (img.width == et->width && img.height == et->height && img.channels == et->channels && img.pixels == et->pixels)
      layout[size_t(k)] = {0, true};
  }
  return layout;
}

Result<CrossbarSearch> prepare_crossbar_search(const PlaneStacks& stacks, const PlaneLayout& layout, int spacing,
                                               const CandidateParams& params, uint32_t seed) {
  CrossbarSearch search;
  search.stacks = stacks;
  search.layout = layout;
  search.spacing = spacing;
  // Indices: first-axis lines and second-axis lines of each base image.
  for (int b = 0; b < 3; ++b) {
    bool is_base = false;
    for (const PlaneSource& src : layout) is_base = is_base || src.base == b;
    if (!is_base) continue;
    search.lines[size_t(b)] = build_lines(*stacks[size_t(b)], params.neighborhood, spacing);
    const CrossbarSearch::Lines& lines = search.lines[size_t(b)];
    KnnParams kp = params.knn;
    // Same seed for every image: identical images then get identical indices (symmetry).
    kp.seed = params.knn.seed ^ (seed * 7919u + uint32_t(spacing));
    const int count = lines.width * lines.height;
    SOLIDTEX_ASSIGN_OR_RETURN(auto fi, KnnIndex::build(lines.first.data(), count, lines.dims, kp));
    SOLIDTEX_ASSIGN_OR_RETURN(auto si, KnnIndex::build(lines.second.data(), count, lines.dims, kp));
    search.first_index[size_t(b)].emplace(std::move(fi));
    search.second_index[size_t(b)].emplace(std::move(si));
  }
  return search;
}

Result<LevelCandidates> compute_level_candidates(const PlaneStacks& stacks, const PlaneLayout& layout, int spacing,
                                                 const CandidateParams& params, uint32_t seed,
                                                 const std::function<bool(double)>& progress) {
  SOLIDTEX_ASSIGN_OR_RETURN(CrossbarSearch search, prepare_crossbar_search(stacks, layout, spacing, params, seed));
  return compute_level_candidates(search, params, progress);
}

Result<LevelCandidates> compute_level_candidates(const PlaneStacks& stacks, bool shared, int spacing,
                                                 const CandidateParams& params, uint32_t seed,
                                                 const std::function<bool(double)>& progress) {
  return compute_level_candidates(stacks, shared ? kSharedLayout : kDistinctLayout, spacing, params, seed, progress);
}

namespace {

// A line kind of a base image: its first-axis (row) or second-axis (column) lines. A plane's
// first-axis lines are its base's rows, or its columns when the plane is transposed.
enum LineKind { kRows = 0, kColumns = 1 };
LineKind first_kind(const PlaneSource& s) { return s.transposed ? kColumns : kRows; }
LineKind second_kind(const PlaneSource& s) { return s.transposed ? kRows : kColumns; }

const float* line_at(const CrossbarSearch& search, int base, LineKind kind, size_t pixel) {
  const CrossbarSearch::Lines& l = search.lines[size_t(base)];
  return (kind == kRows ? l.first : l.second).data() + pixel * size_t(l.dims);
}

// The k-NN of every line of one kind of one base image among the lines of one kind of another
// (or the same) base image: the search_k nearest, nearest first, per query pixel.
struct Neighbours {
  int k = 0;
  std::vector<int> index;      // base pixel indices of the target image, k per query
  std::vector<float> sq_dist;  // their squared distances
  std::vector<uint8_t> count;  // found per query (<= k)
};

// The pixel of plane `src` whose lines are base pixel `index` of its base image.
ExemplarPixel plane_pixel(const CrossbarSearch& search, const PlaneSource& src, int index) {
  const int w = search.lines[size_t(src.base)].width;
  const ExemplarPixel p{index % w, index / w};
  return src.transposed ? ExemplarPixel{p.y, p.x} : p;
}

}  // namespace

Result<LevelCandidates> compute_level_candidates(const CrossbarSearch& search, const CandidateParams& params,
                                                 const std::function<bool(double)>& progress) {
  const PlaneStacks& stacks = search.stacks;
  const PlaneLayout& layout = search.layout;
  const bool shared = search.shared();
  const int spacing = search.spacing;
  const int nt = params.candidates;
  const int keep = 2 * nt;
  const int dims = search.lines[0].dims;
  const int planes_to_search = shared ? 1 : 3;
  for (int k = 0; k < 3; ++k)
    if (stacks[size_t(k)]->width > PackedTriple::kMaxSide || stacks[size_t(k)]->height > PackedTriple::kMaxSide)
      return Status(StatusCode::kInvalidArgument,
                    "exemplar sides above " + std::to_string(PackedTriple::kMaxSide) + " pixels cannot be analysed", "exemplar");

  // The searches each plane needs: its second-axis lines among plane k+1's first-axis lines,
  // its first-axis lines among plane k+2's second-axis lines. Keyed by (query base, kind,
  // target base, kind); planes sharing lines share the searches.
  auto key_of = [](int qb, LineKind qk, int tb, LineKind tk) { return ((qb * 2 + qk) * 3 + tb) * 2 + tk; };
  struct Need {
    int qb, tb;
    LineKind qk, tk;
  };
  std::array<std::optional<Need>, 36> needs;
  std::array<std::array<int, 2>, 3> plane_keys{};
  for (int k = 0; k < planes_to_search; ++k) {
    const PlaneSource& own = layout[size_t(k)];
    const PlaneSource& next = layout[size_t((k + 1) % 3)];
    const PlaneSource& prev = layout[size_t((k + 2) % 3)];
    const Need a{own.base, next.base, second_kind(own), first_kind(next)};
    const Need b{own.base, prev.base, first_kind(own), second_kind(prev)};
    plane_keys[size_t(k)] = {key_of(a.qb, a.qk, a.tb, a.tk), key_of(b.qb, b.qk, b.tb, b.tk)};
    needs[size_t(plane_keys[size_t(k)][0])] = a;
    needs[size_t(plane_keys[size_t(k)][1])] = b;
  }
  int64_t total_rows = 0;
  for (const auto& n : needs)
    if (n) total_rows += search.lines[size_t(n->qb)].height;
  for (int k = 0; k < planes_to_search; ++k) total_rows += stacks[size_t(k)]->height;
  std::atomic<int64_t> rows_done{0};
  std::atomic<bool> cancelled{false};
  auto row_done = [&] {
    const int64_t done = rows_done.fetch_add(1) + 1;
    if (progress && progress(double(done) / double(total_rows))) cancelled = true;
  };

  std::array<Neighbours, 36> found;
  for (int key = 0; key < 36; ++key) {
    if (!needs[size_t(key)]) continue;
    const Need& n = *needs[size_t(key)];
    const CrossbarSearch::Lines& q = search.lines[size_t(n.qb)];
    const KnnIndex& index = n.tk == kRows ? *search.first_index[size_t(n.tb)] : *search.second_index[size_t(n.tb)];
    Neighbours& out = found[size_t(key)];
    out.k = params.search_k;
    const size_t count = size_t(q.width) * q.height;
    out.index.assign(count * out.k, 0);
    out.sq_dist.assign(count * out.k, 0.f);
    out.count.assign(count, 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, q.height), [&](const tbb::blocked_range<int>& rows) {
      std::vector<int> qi;
      std::vector<float> qd;
      for (int y = rows.begin(); y != rows.end(); ++y) {
        if (cancelled.load(std::memory_order_relaxed)) return;
        for (int x = 0; x < q.width; ++x) {
          const size_t i = size_t(y) * q.width + x;
          index.search(line_at(search, n.qb, n.qk, i), out.k, qi, qd);
          std::copy(qi.begin(), qi.end(), out.index.begin() + i * out.k);
          std::copy(qd.begin(), qd.end(), out.sq_dist.begin() + i * out.k);
          out.count[i] = uint8_t(qi.size());
        }
        row_done();
      }
    });
    if (cancelled) return Status(StatusCode::kCancelled, "analysis cancelled");
  }

  // Raw best `keep` triples per pixel per plane.
  std::array<std::vector<Scored>, 3> raw;
  std::array<std::vector<uint8_t>, 3> raw_count;
  for (int k = 0; k < planes_to_search; ++k) {
    const ImageF& img = *stacks[size_t(k)];
    const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    const PlaneSource& own = layout[size_t(k)];
    const PlaneSource& next = layout[size_t(k1)];
    const PlaneSource& prev = layout[size_t(k2)];
    const Neighbours& along_second = found[size_t(plane_keys[size_t(k)][0])];  // in plane k1
    const Neighbours& along_first = found[size_t(plane_keys[size_t(k)][1])];   // in plane k2
    const int own_width = search.lines[size_t(own.base)].width;
    raw[k].resize(size_t(img.pixel_count()) * keep);
    raw_count[k].assign(size_t(img.pixel_count()), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, img.height), [&](const tbb::blocked_range<int>& rows) {
      std::vector<Scored> pairs;
      for (int y = rows.begin(); y != rows.end(); ++y) {
        if (cancelled.load(std::memory_order_relaxed)) return;
        for (int x = 0; x < img.width; ++x) {
          const size_t p = size_t(y) * img.width + x;
          const size_t base_pixel = own.transposed ? size_t(x) * own_width + y : p;
          const int* qi = &along_second.index[base_pixel * along_second.k];
          const float* qd = &along_second.sq_dist[base_pixel * along_second.k];
          const int qn = along_second.count[base_pixel];
          const int* ri = &along_first.index[base_pixel * along_first.k];
          const float* rd = &along_first.sq_dist[base_pixel * along_first.k];
          const int rn = along_first.count[base_pixel];
          // The best `keep` pairs by (error, triple), kept in a max-heap. k-NN distances come
          // nearest first, and error = (qd[a] + rd[b]) + crossbar term >= qd[a] + rd[b] in
          // floats, so once that bound exceeds the heap's worst, the rest of the row (and,
          // at b = 0, every later row) cannot enter: the kept set is exactly the one a full
          // sort of all search_k^2 pairs gives (a strict order: the pairs' triples differ).
          pairs.clear();
          for (int a = 0; a < qn; ++a) {
            // Plane k1's second-axis line at its pixel, and plane k2's first-axis line below.
            const float* q_second = line_at(search, next.base, second_kind(next), size_t(qi[a]));
            for (int b = 0; b < rn; ++b) {
              const float bound = qd[a] + rd[b];
              if (pairs.size() == size_t(keep) && bound > pairs.front().error) {
                if (b == 0) a = qn;  // every later row starts higher
                break;
              }
              Scored s;
              s.error = bound + sq_dist(q_second, line_at(search, prev.base, first_kind(prev), size_t(ri[b])), dims);
              s.t.at[k] = {x, y};
              s.t.at[k1] = plane_pixel(search, next, qi[a]);
              s.t.at[k2] = plane_pixel(search, prev, ri[b]);
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
          std::copy(pairs.begin(), pairs.end(), raw[k].begin() + p * keep);
          raw_count[k][p] = uint8_t(pairs.size());
        }
        row_done();
      }
    });
    if (cancelled) return Status(StatusCode::kCancelled, "analysis cancelled");
  }

  // Coherence selection.
  LevelCandidates level;
  std::atomic<int64_t> coherent_kept{0}, kept{0};
  for (int k = 0; k < planes_to_search; ++k) {
    const ImageF& img = *stacks[k];
    std::vector<PackedTriple> triples(size_t(img.pixel_count()) * nt);
    std::vector<uint8_t> counts(size_t(img.pixel_count()), 0);
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
          for (size_t i = 0; i < chosen.size(); ++i) triples[p * nt + i] = PackedTriple::pack(chosen[i].t);
          counts[p] = uint8_t(chosen.size());
        }
    });
    level.planes[k] = PlaneCandidates::make(img.width, img.height, nt, std::move(triples), std::move(counts));
  }
  level.coherent_fraction = kept ? double(coherent_kept) / double(kept) : 0.0;
  if (shared)
    for (int k = 1; k < 3; ++k) level.planes[k] = level.planes[0].rotated(k);
  return level;
}

}  // namespace solidtex
