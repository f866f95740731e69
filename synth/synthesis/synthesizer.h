// Lazy, spatially deterministic solid synthesis (Zhang §4-5) over an unbounded voxel lattice.
//
// synthesize() computes only what the target voxels depend on:
//  1. backwards, finest level first: the target (or the parents the finer level needs) at the
//     final version, minus what the cache holds; then, step by step down to version 0, every
//     (voxel, version) a correction reads, as named by the step's history window and the
//     voxel's read stencil (correction.h). Version-0 voxels need their parents one level up.
//  2. forwards, coarsest level first: initialise or upsample version 0, then run each step on
//     exactly the voxels it updates within the sets, in parallel (TBB).
// Purity: the value of (level, voxel, version) depends only on the table, field, parameters
// and seed: never on the request, order, thread count or cache state (tests check bits).
// Fields: the finest level uses the field at each voxel centre; coarser levels a smoothed
// field (mean of 8 samples over the voxel's footprint), as in Zhang §6.
// Thread-safety: synthesize() may run concurrently; requests share only the VoxelCache.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "field/frame_field.h"
#include "synthesis/history_window.h"
#include "core/interrupter.h"
#include "synthesis/synthesis_params.h"
#include "analysis/table.h"
#include "synthesis/target.h"
#include "synthesis/voxel_cache.h"

namespace solidtex {

struct LevelStats {
  int level = 0;
  int64_t voxels = 0;        // distinct voxels synthesized (version 0, incl. upsampled)
  int64_t corrections = 0;   // voxel updates over all steps
  int64_t cache_hits = 0;    // final-version voxels taken from the cache
  int64_t needed_final = 0;  // final-version voxels the finer level (or the target) needed
  double seconds = 0;
};

struct SynthesisStats {
  std::vector<LevelStats> levels;
  int64_t voxels = 0;
  int64_t corrections = 0;
  double seconds = 0;
  double dependency_seconds = 0;
  int64_t store_bytes = 0;        // request-local storage at its peak level
  // Instrumented mode only: reads outside the computed sets, and set members never read.
  int64_t unsound_reads = 0;
  int64_t unread_required = 0;
};

struct SynthesisOptions {
  bool instrument = false;  // check soundness and tightness of the dependency sets
  bool use_cache = true;    // consult and fill the VoxelCache
  // Compute the dependency sets and their sizes only (stats), synthesize nothing; the
  // returned colors are then empty. For measuring schemes at sizes too big to synthesize.
  bool dependencies_only = false;
};

class Synthesizer {
 public:
  static Result<std::shared_ptr<Synthesizer>> create(std::shared_ptr<const Table> table,
                                                     std::shared_ptr<const FrameField> field,
                                                     const SynthesisParams& params, int64_t cache_bytes);

  // Linear RGB of every target sample (target.sample order).
  Result<std::vector<std::array<float, 3>>> synthesize(const TargetSet& target,
                                                       Interrupter& interrupter = null_interrupter(),
                                                       SynthesisStats* stats = nullptr,
                                                       const SynthesisOptions& options = {});

  const Table& table() const { return *table_; }
  const FrameField& field() const { return *field_; }
  const SynthesisParams& params() const { return params_; }
  const LevelSchedule& schedule(PyramidLevel l) const { return schedules_[size_t(l.index)]; }
  VoxelCache& cache() { return *cache_; }

 private:
  Synthesizer() = default;
  struct Impl;
  std::shared_ptr<const Table> table_;
  std::shared_ptr<const FrameField> field_;
  SynthesisParams params_;
  std::vector<LevelSchedule> schedules_;
  std::unique_ptr<VoxelCache> cache_;
  std::shared_ptr<Impl> impl_;
};

}  // namespace solidtex
