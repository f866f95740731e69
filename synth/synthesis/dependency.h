// Dependency analysis (Zhang §5.2; ../shared/design/lazy-synthesis.md): the (voxel, version)
// pairs of every pyramid level that a request's target voxels depend on, computed backwards
// from the finest level's final version:
//   - a level's final-version set is the target (finest) or the parents the finer level's
//     version-0 set upsamples from, minus what the voxel cache holds;
//   - step v's updated voxels in set v read their stencil neighbours at the versions the
//     step's history window names (into sets < v); voxels the step does not update carry
//     set membership down to v - 1 unchanged;
//   - version 0 of level l needs the parents floor(p / 2) at level l - 1's final version.
// Soundness (every read lies in a set) and tightness (every member is read) are checked by the
// synthesizer's instrumented mode. The sets never depend on thread count or order: set union
// is order-independent and VoxelMask iterates in a fixed order.
// Two paths compute the same sets: when the field is constant (one stencil per level,
// FrameStencils::constant()), each step dilates the set brick by brick (512-bit shifts per
// stencil offset, split by the history window's versions, each destination brick written by one
// task); otherwise each member voxel inserts its own stencil. Both give bit-identical sets and
// counts (dependency_test.cpp).
// Bounds: level l's sets lie in `box`, the final-version box dilated by the schedule's steps
// times the stencil reach; a read outside it is an internal error (stencil reach too small).
#pragma once

#include <cstdint>
#include <vector>

#include "core/interrupter.h"
#include "core/status.h"
#include "synthesis/frame_stencils.h"
#include "synthesis/history_window.h"
#include "synthesis/target.h"
#include "synthesis/voxel_cache.h"
#include "synthesis/voxel_mask.h"

namespace solidtex {

struct LevelDependencies {
  VoxelBox box;                                // every set of the level lies inside
  std::vector<VoxelMask> needed;               // [version 0..V]: voxels whose value there is read
  std::vector<Voxel> cache_hits;               // final-version voxels the cache holds (not in needed[V])
  std::vector<CoordinateTriple> cached;        // their triples, same order
  int64_t needed_final = 0;                    // final-version voxels asked for (hits included)
  int64_t corrections = 0;                     // voxel updates the forward pass will run
};

struct DependencyInputs {
  const std::vector<LevelSchedule>* schedules = nullptr;  // per level
  const FrameStencils* stencils = nullptr;
  VoxelCache* cache = nullptr;  // null: consult no cache
  bool per_voxel = false;       // force the per-voxel path (the reference, for tests/benchmarks)
};

// The per-level sets for `target`, whose voxels are final voxels of level `top` (index =
// level, coarsest first; levels finer than `top` stay empty). Cancelled through `interrupter`
// between steps.
Result<std::vector<LevelDependencies>> analyze_dependencies(const DependencyInputs& in, const TargetSet& target,
                                                            PyramidLevel top, LatchedInterrupter& interrupter);

// The box every set of each level up to `top` lies in (index = level), from the bounds of a
// target on level `top`.
std::vector<VoxelBox> dependency_boxes(const std::vector<LevelSchedule>& schedules, const FrameStencils& stencils,
                                       const VoxelBox& target_bounds, PyramidLevel top);

// The parent (one level coarser) of voxel p.
inline Voxel parent_of(const Voxel& p) { return {floor_div(p.x, 2), floor_div(p.y, 2), floor_div(p.z, 2)}; }

}  // namespace solidtex
