// Lazy, spatially deterministic solid synthesis (Zhang §4-5) over an unbounded voxel lattice.
//
// synthesize() computes only what the target voxels depend on, in named stages:
//  1. dependency analysis (dependency.h), backwards from the finest level: per level and
//     version, the voxels the target depends on, minus what the cache holds;
//  2. per level, coarsest first: a request-local LevelStore of the level's sets; version 0 by
//     initialisation or upsampling (pyramid_init.h); each correction step on exactly the voxels
//     of its set that it updates, in parallel (TBB; correction.h);
//  3. cache write-back of the level's final versions;
//  4. output colors of the finest level's final versions (with ColorRule::kVote, from the
//     final triples around each target voxel: stage 1 starts from that support, patch_vote.h).
// Instrumented mode (SynthesisOptions::instrument) checks the sets' soundness and tightness.
// Purity: the value of (level, voxel, version) depends only on the table, field, parameters
// and seed: never on the request, order, thread count or cache state (tests check bits).
// Fields: frames and stencils per voxel and level come from frame_stencils.h (Zhang §6).
// Thread-safety: synthesize() may run concurrently; requests share only the VoxelCache.
#pragma once

#include <array>
#include <memory>
#include <string>
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
  int64_t estimated_bytes = 0;    // the cost model's bound for the largest piece, when max_bytes > 0
  // Target-level voxels whose final triples the output colors read: the target's, or with
  // ColorRule::kVote its vote support (patch_vote.h); the target level's needed_final.
  int64_t support_voxels = 0;
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
  // Working-memory limit of one request (bytes; 0 = none). A request whose cost estimate
  // (cost_model.h) or whose computed sets need more is refused with kUnprocessable before
  // anything that size is allocated.
  int64_t max_bytes = 0;
  // The request field that refusal names: what sets the target's size ("size" for cuts and
  // boxes, "points", "mesh"...).
  std::string target_field = "size";
  // The pyramid level the target's voxels lie on: -1 (default) is the finest; a coarser level
  // (0 = coarsest) gives that level's final voxels and synthesizes nothing finer. Their colors
  // are output colors of the level's triples (synthesis levels, not box-filtered finest voxels);
  // by purity they equal what any request reaching that level computes.
  int level = -1;
};

struct RequestCost;

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

  // Upper bounds of what synthesize(target) allocates, per level (cost_model.h). Scattered
  // targets are split into compact pieces first; this is the cost of the largest piece.
  // The first call measures the schedule's spread (about a second; memoised per schedule and
  // constant field), cancelled through `interrupter`.
  Result<RequestCost> estimate(const TargetSet& target, Interrupter& interrupter = null_interrupter()) const;

  const Table& table() const { return *table_; }
  const FrameField& field() const { return *field_; }
  const SynthesisParams& params() const { return params_; }
  const LevelSchedule& schedule(PyramidLevel l) const { return schedules_[size_t(l.index)]; }
  VoxelCache& cache() { return *cache_; }

 private:
  Synthesizer() = default;
  Result<std::vector<int>> spread(LatchedInterrupter& interrupter) const;
  // The voxels of level `top` a request must synthesize to colour `target`: the target itself,
  // or with ColorRule::kVote its vote support (patch_vote.h).
  TargetSet color_support(const TargetSet& target, PyramidLevel top) const;
  // How far (voxels per axis) that support reaches beyond the target.
  int support_reach(PyramidLevel top) const;
  // One compact piece of a request: colors per target voxel (target.voxels order).
  Result<std::vector<std::array<float, 3>>> synthesize_piece(const TargetSet& piece, LatchedInterrupter& poller,
                                                             SynthesisStats& stats, const SynthesisOptions& options);
  struct Impl;
  std::shared_ptr<const Table> table_;
  std::shared_ptr<const FrameField> field_;
  SynthesisParams params_;
  std::vector<LevelSchedule> schedules_;
  std::unique_ptr<VoxelCache> cache_;
  std::shared_ptr<Impl> impl_;
};

}  // namespace solidtex
