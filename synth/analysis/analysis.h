// Exemplar analysis: Gaussian stacks, PCA appearance spaces and candidate triples per level.
// Deterministic: identical inputs and parameters give identical tables, bit for bit, whatever
// the thread count (tests/analysis_test.cpp checks this through the encoded .stx bytes).
// Long-running; honours the interrupter (progress in percent, cancellation).
#pragma once

#include <memory>
#include <vector>

#include "analysis/analysis_params.h"
#include "analysis/exemplar.h"
#include "core/interrupter.h"
#include "analysis/table.h"

namespace solidtex {

struct LevelReport {
  int level = 0;                     // 0 = coarsest
  int spacing = 1;                   // exemplar pixels between samples, h
  double mean_crossbar_error = 0;    // stored candidates
  double random_crossbar_error = 0;  // uniformly random triples
  double coherent_fraction = 0;      // stored candidates coherent with a neighbour
};

struct AnalysisResult {
  std::shared_ptr<const Table> table;
  std::vector<LevelReport> levels;
  double seconds = 0;
};

// `params` with kAutoLevels replaced by auto_levels() of the exemplars' shorter side (the
// smallest width or height over the three planes); explicit levels are kept.
AnalysisParams resolve_levels(AnalysisParams params, const ExemplarSet& exemplars);

// Levels kAutoLevels are resolved first (resolve_levels); the table holds the count used.
Result<AnalysisResult> analyze(const ExemplarSet& exemplars, const AnalysisParams& params,
                               Interrupter& interrupter = null_interrupter());

std::vector<LevelReport> level_reports(const Table& table);

// Peak working memory of analyze(exemplars, params) plus usage calibration, bytes, before any
// work, linear in the searched planes' pixels (the service checks it per uploaded image): per
// pixel and level the table's own arrays, plus the search's transients of two levels. Measured
// (bench_analysis, peak RSS less the ~130 MB of a process that analysed a 32^2 exemplar):
// gravel 512^2 626 MB for 713 MB estimated, pebbles 256^2 181 MB for 178 MB.
int64_t estimate_analysis_bytes(const ExemplarSet& exemplars, const AnalysisParams& params);

}  // namespace solidtex
