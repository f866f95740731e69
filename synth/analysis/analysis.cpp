#include "analysis/analysis.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <future>
#include <cmath>
#include <limits>
#include <mutex>

#include "analysis/gaussian_stack.h"
#include "analysis/neighborhood.h"

namespace solidtex {
namespace {

// Fits a PCA on N x N neighborhoods sampled on a fixed lattice (at most ~4096 of them).
Result<PcaBasis> fit_level_pca(const ImageF& stack, int n, int spacing, int out_dims) {
  const int64_t pixels = stack.pixel_count();
  const int stride = std::max(1, int(std::ceil(std::sqrt(double(pixels) / 4096.0))));
  const int dims = neighborhood_dims(n, stack.channels);
  std::vector<float> samples;
  int count = 0;
  for (int y = 0; y < stack.height; y += stride)
    for (int x = 0; x < stack.width; x += stride) {
      samples.resize(size_t(count + 1) * dims);
      gather_neighborhood(stack, {x, y}, n, spacing, &samples[size_t(count) * dims]);
      ++count;
    }
  return fit_pca(samples, count, dims, out_dims);
}

// Serialises progress from worker threads into the interrupter.
class ProgressSink {
 public:
  explicit ProgressSink(Interrupter& i) : interrupter_(i) {}
  bool report(double fraction) {
    std::lock_guard<std::mutex> g(mutex_);
    int pct = std::clamp(int(fraction * 100.0), 0, 100);
    if (interrupter_.was_interrupted(pct)) cancelled_ = true;
    return cancelled_;
  }
  bool cancelled() const { return cancelled_; }

 private:
  Interrupter& interrupter_;
  std::mutex mutex_;
  bool cancelled_ = false;
};

}  // namespace

std::vector<LevelReport> level_reports(const Table& table) {
  std::vector<LevelReport> out;
  for (int l = 0; l < table.levels(); ++l) {
    const LevelCandidates& c = *table.level(PyramidLevel{l}).candidates;
    out.push_back({l, table.spacing(PyramidLevel{l}), c.mean_crossbar_error, c.random_crossbar_error, c.coherent_fraction});
  }
  return out;
}

AnalysisParams resolve_levels(AnalysisParams params, const ExemplarSet& exemplars) {
  if (params.levels != kAutoLevels) return params;
  int side = std::numeric_limits<int>::max();
  for (int k = 0; k < 3; ++k) {
    const ImageF& img = exemplars.plane(plane_from_index(k));
    side = std::min({side, img.width, img.height});
  }
  params.levels = auto_levels(side, params.neighborhood);
  return params;
}

Result<AnalysisResult> analyze(const ExemplarSet& exemplars, const AnalysisParams& requested, Interrupter& interrupter) {
  SOLIDTEX_RETURN_IF_ERROR(requested.validate());
  const AnalysisParams params = resolve_levels(requested, exemplars);
  const auto t0 = std::chrono::steady_clock::now();
  interrupter.start("analyze");
  ProgressSink sink(interrupter);
  const int L = params.levels;
  const int n = params.neighborhood;
  const int distinct = exemplars.shared() ? 1 : 3;
  // In the crossed layout, yz and zx hold plane xy's image transposed: they share its crossbar
  // lines and searches (candidate_triples.h). The grain layouts could too, but their tables
  // would change in near-ties (lines from E's stack round differently from E^T's own), and the
  // sketched-ring grain test sits at its threshold on seed 1 (9.9 -> 10.5 degrees; over 3 x 5
  // seeds 9.3 -> 9.6, within noise): grain x/y keep their table bits, searched per plane.
  const PlaneLayout layout = exemplars.shared() ? kSharedLayout : exemplars.crossed() ? kCrossedLayout : kDistinctLayout;

  // Stacks of each distinct image, indexed by stack index (0 = original).
  std::array<std::vector<ImageF>, 3> stacks;
  for (int k = 0; k < distinct; ++k) stacks[k] = build_gaussian_stack(exemplars.plane(plane_from_index(k)), L);

  std::vector<std::array<PcaBasis, 3>> pcas(static_cast<size_t>(L));
  std::vector<LevelCandidates> candidates(static_cast<size_t>(L));
  CandidateParams cp;
  cp.neighborhood = n;
  cp.candidates = params.candidates;
  cp.search_k = params.search_k;
  cp.knn.checks = params.knn_checks;
  cp.knn.seed = params.seed;
  auto level_stacks = [&](int l) {
    PlaneStacks out{};
    for (int k = 0; k < 3; ++k) out[k] = &stacks[exemplars.shared() ? 0 : k][size_t(L - 1 - l)];
    return out;
  };
  // A level's serial part (PCA fit, crossbar lines, k-NN index builds) runs on its own thread
  // while the previous level searches on the pool: it has no randomness of its own (FLANN is
  // seeded per build, under its lock), so the table is the same bits as running it in line.
  auto prepare = [&](int l) -> Result<CrossbarSearch> {
    const int spacing = stack_spacing(PyramidLevel{l}, L);
    const PlaneStacks ls = level_stacks(l);
    for (int k = 0; k < distinct; ++k) {
      SOLIDTEX_ASSIGN_OR_RETURN(pcas[size_t(l)][k], fit_level_pca(*ls[k], n, spacing, params.pca_dims));
    }
    if (distinct == 1) pcas[size_t(l)][1] = pcas[size_t(l)][2] = pcas[size_t(l)][0];
    return prepare_crossbar_search(ls, layout, spacing, cp, params.seed);
  };
  std::future<Result<CrossbarSearch>> next = std::async(std::launch::async, prepare, 0);
  for (int l = 0; l < L; ++l) {
    Result<CrossbarSearch> search = next.get();
    if (l + 1 < L) next = std::async(std::launch::async, prepare, l + 1);
    // On an error the next level's preparation is still joined (the future's destructor).
    if (!search.is_ok()) return search.status();
    auto progress = [&](double f) { return sink.report((double(l) + f * 0.9) / double(L)); };
    SOLIDTEX_ASSIGN_OR_RETURN(candidates[size_t(l)], compute_level_candidates(*search, cp, progress));
    measure_level_candidates(level_stacks(l), n, stack_spacing(PyramidLevel{l}, L), params.seed, candidates[size_t(l)]);
    if (sink.report(double(l + 1) / double(L))) return Status(StatusCode::kCancelled, "analysis cancelled");
  }
  SOLIDTEX_ASSIGN_OR_RETURN(auto table, Table::assemble(params, exemplars, std::move(pcas), std::move(candidates)));
  interrupter.end();
  AnalysisResult result;
  result.table = table;
  result.levels = level_reports(*table);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

int64_t estimate_analysis_bytes(const ExemplarSet& exemplars, const AnalysisParams& requested) {
  const AnalysisParams params = resolve_levels(requested, exemplars);
  const int64_t planes = exemplars.shared() ? 1 : 3;
  const int64_t c = exemplars.channels();
  const int64_t n = params.neighborhood, nt = params.candidates;
  // Kept per pixel and level: matching image, appearance vectors, typicality penalties, packed
  // candidate lists with their counts; and usage calibration's copy of the first three plus
  // usage penalties (usage_balance.h: it runs on the finished table, candidate lists shared).
  const int64_t per_pixel_level = 4 * c + 4 * params.pca_dims + 4 + (int64_t(sizeof(PackedTriple)) * nt + 1) +
                                  4 * (c + params.pca_dims + 2);
  // Transient, for the level being searched and the next one being prepared: the 2*N_T best
  // pairs (28 B each), both levels' first- and second-axis crossbar lines, the k-NN results.
  const int64_t per_pixel_search = 28 * 2 * nt + 2 * 2 * 4 * n * c + 16 * params.search_k;
  int64_t pixels = 0;
  for (int k = 0; k < int(planes); ++k) pixels += exemplars.plane(plane_from_index(k)).pixel_count();
  return pixels * (params.levels * per_pixel_level + per_pixel_search);
}

}  // namespace solidtex
