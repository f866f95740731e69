// What a synthesis request will cost, known before any work starts, so that a service can
// refuse it instead of discovering its size by allocating (issue 11).
//
// estimate_cost() bounds, per level, the voxels the dependency sets can hold and the bytes
// dependency analysis and the level store allocate: the sets of level l lie in its box (the
// final-version box dilated by steps x stencil reach, dependency.h) and within that reach of
// the voxels the finer level needs, so a level's set holds at most
//   min(box volume, needed voxels x (2 x steps x reach + 1)^3)
// voxels; bytes count the brick tables over the box (one per version, dense), the mask bricks
// and the store bricks (512 voxels x slots x VoxelState each, a brick per voxel at worst).
// It is an upper bound: cheap (no voxel is touched), and loose for scattered targets, which
// the synthesizer splits into compact pieces first (split_target()).
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

RequestCost estimate_cost(const std::vector<LevelSchedule>& schedules, const FrameStencils& stencils,
                          const TargetSet& target);

// Exact bytes of the level stores the forward pass will allocate for computed sets (the peak
// of two consecutive levels: a level and its parent are alive together).
int64_t store_bytes(const std::vector<LevelSchedule>& schedules, const std::vector<LevelDependencies>& deps);

// Splits a target into pieces whose voxels are close (26-connected cells of `cell` finest
// voxels), so a scattered target (points far apart, a sparse mesh) never needs one brick
// table over the box around all of it. Each piece lists indices into target.voxels, in
// ascending order; pieces are ordered by their first voxel. A compact target is one piece.
std::vector<std::vector<uint32_t>> split_target(const TargetSet& target, int cell);

}  // namespace solidtex
