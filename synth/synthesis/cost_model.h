// What a synthesis request will cost, known before any work starts, so that a service can
// refuse it instead of discovering its size by allocating (issue 11).
//
// A level's version-0 set is the voxels it must serve at its final version, dilated by how far
// the level's correction steps spread dependencies. That spread is far below steps x stencil
// reach (subpasses update one voxel class per step; grid barriers stop reads at cell borders),
// so measure_spread() measures it once per synthesizer with the real dependency analysis of
// a few single-voxel probes. estimate_cost() then bounds, per level,
//   voxels <= min(volume of the served box dilated by the spread, targets x (2 radius + 1)^3)
// where radius (in the level's voxels) is the spread plus half the finer level's radius, plus one
// and bytes: the dense brick tables over the level's dependency box (one per version), mask
// bricks, and store bricks (512 voxels x slots x VoxelState each). It touches no voxel, so a
// service can refuse a request before allocating; the synthesizer checks the exact store size
// again after dependency analysis (store_bytes()). Fields whose reach varies in space may
// spread further than the probes saw: that is what the exact check is for.
// Thread-safe: pure functions.
#pragma once

#include <cstdint>
#include <vector>

#include "synthesis/dependency.h"

namespace solidtex {

struct LevelCost {
  int level = 0;
  int64_t voxels = 0;  // upper bound of the level's version-0 set
  int64_t bytes = 0;   // upper bound of what the level allocates
};

struct RequestCost {
  std::vector<LevelCost> levels;  // coarsest first
  int64_t voxels = 0;
  int64_t bytes = 0;      // the peak: dependency masks of every level, plus two level stores
};

// Per level (index = level), how many of its own voxels its sets reach beyond what it serves.
// Takes about a second at the default parameters; cancelled through `interrupter`.
Result<std::vector<int>> measure_spread(const std::vector<LevelSchedule>& schedules, const FrameStencils& stencils,
                                        LatchedInterrupter& interrupter);

// `support_reach`: the target level's sets must also serve every voxel within this many voxels
// (per axis) of a target voxel (the patch vote's support, patch_vote.h), without listing them.
RequestCost estimate_cost(const std::vector<LevelSchedule>& schedules, const FrameStencils& stencils,
                          const std::vector<int>& spread, const TargetSet& target, int support_reach = 0);

// Exact bytes of the level stores the forward pass will allocate for computed sets (the peak
// of two consecutive levels: a level and its parent are alive together).
int64_t store_bytes(const std::vector<LevelSchedule>& schedules, const std::vector<LevelDependencies>& deps);

// Splits a target into pieces whose voxels are close (26-connected cells of `cell` finest
// voxels), so a scattered target (points far apart, a sparse mesh) never needs one brick
// table over the box around all of it. Each piece lists indices into target.voxels, in
// ascending order; pieces are ordered by their first voxel. A compact target is one piece.
std::vector<std::vector<uint32_t>> split_target(const TargetSet& target, int cell);

}  // namespace solidtex
