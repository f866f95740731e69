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

Result<AnalysisResult> analyze(const ExemplarSet& exemplars, const AnalysisParams& params,
                               Interrupter& interrupter = null_interrupter());

std::vector<LevelReport> level_reports(const Table& table);

// Peak working memory of analyze(exemplars, params), bytes, before any work: per pixel and
// level of every searched plane, the crossbar lines and neighborhoods in FLANN's index, the
// projected appearance vectors and the candidate lists, and usage calibration's copy of the
// appearance (calibrated on 128^2 and 256^2 noise exemplars at the defaults: about 1.3 KB per
// pixel and level, within 10% of measured RSS; gravel 512^2: 1.58 GB estimated, 1.61 GB peak
// RSS of `solidtex analyze`, bench_analysis reports both).
int64_t estimate_analysis_bytes(const ExemplarSet& exemplars, const AnalysisParams& params);

}  // namespace solidtex
