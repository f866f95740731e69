// The candidate-triple table of one exemplar set: everything synthesis needs, built by
// analyze() (analysis.h) or loaded from a .stx file (table_file.h).
//
// Stored (in .stx): parameters, the matching images, per level and distinct image the PCA
// basis, per level and plane the candidate triples, and per level the analysis statistics.
// Derived on construction (not stored, reproduced bit for bit): Gaussian stacks, every
// pixel's projected neighborhood ("appearance vector") and its typicality penalty.
// Optional and stored: per level and distinct image, a usage penalty per pixel, calibrated
// after analysis (synthesis/usage_balance.h); tables without it synthesize as before.
// Immutable once built; safe to share between threads.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "analysis/analysis_params.h"
#include "analysis/candidate_triples.h"
#include "analysis/exemplar.h"
#include "core/image.h"
#include "analysis/pca.h"
#include "core/types.h"

namespace solidtex {

// One distinct exemplar image at one pyramid level.
struct PlaneAppearance {
  ImageF stack;                   // Gaussian-stack matching image at this level's blur
  PcaBasis pca;                   // fitted on N x N neighborhoods at this level's spacing
  std::vector<float> projected;   // width*height rows of pca.output_dims: appearance vectors
  std::vector<float> typicality;  // width*height penalties, >= 0 (typicality.h)
  std::vector<float> usage;       // width*height penalties >= 0 in match-cost units, or empty (usage_balance.h)

  const float* appearance(ExemplarPixel p) const {
    const size_t i = size_t(ImageF::wrap(p.y, stack.height)) * stack.width + ImageF::wrap(p.x, stack.width);
    return &projected[i * pca.output_dims];
  }
};

struct TableLevel {
  std::array<std::shared_ptr<const PlaneAppearance>, 3> planes;  // same pointer when shared
  // Shared, immutable: tables differing only in usage penalties (Table::with_usage) share it.
  std::shared_ptr<const LevelCandidates> candidates;
};

// Usage penalties of a whole table: [level][distinct image][pixel] (Table::distinct_images()).
using UsagePenalties = std::vector<std::vector<std::vector<float>>>;

class Table {
 public:
  // Builds derived data (stacks, projections) from stored parts; used by analysis and loading.
  static Result<std::shared_ptr<const Table>> assemble(AnalysisParams params, ExemplarSet exemplars,
                                                       std::vector<std::array<PcaBasis, 3>> pca_per_level,
                                                       std::vector<LevelCandidates> candidates);

  const AnalysisParams& params() const { return params_; }
  const ExemplarSet& exemplars() const { return exemplars_; }
  int levels() const { return int(levels_.size()); }
  const TableLevel& level(PyramidLevel l) const { return levels_[size_t(l.index)]; }
  int spacing(PyramidLevel l) const { return stack_spacing(l, levels()); }
  // 1 when the three planes share one image, else 3; planes[k] of a level is image k's.
  int distinct_images() const { return exemplars_.shared() ? 1 : 3; }
  bool has_usage() const;
  UsagePenalties usage() const;  // empty when has_usage() is false
  // A copy of this table with `usage` as its usage penalties (sizes checked, values finite and
  // >= 0); an empty argument removes them.
  Result<std::shared_ptr<const Table>> with_usage(UsagePenalties usage) const;

 private:
  AnalysisParams params_;
  ExemplarSet exemplars_;
  std::vector<TableLevel> levels_;
};

// Projects every pixel's N x N neighborhood of `stack` at `spacing` through `pca`.
std::vector<float> project_all_neighborhoods(const ImageF& stack, const PcaBasis& pca, int n, int spacing);

}  // namespace solidtex
