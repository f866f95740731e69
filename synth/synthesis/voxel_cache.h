// The sparse voxel cache: final coordinate triples of every pyramid level, kept across
// requests in 8^3 bricks (a hash map of bricks per level; a brick holds a presence bit per
// voxel and the values of its present voxels only, each packing one plane's 16-bit exemplar x
// and y per int32: 12 bytes). Only final versions are cached; by the purity invariant a cached
// value equals what any request would compute.
//
// Budget: `bytes` is everything the cache holds, brick_bytes(n) per brick of n voxels (values,
// presence bits, the map node and its bucket, allocator headers), with no other structure
// beside the bricks, so the budget bounds the cache's real memory: about 12.3 bytes per voxel
// in full bricks, 14.6 in a one-layer (8 x 8) brick. When it exceeds `budget_bytes`, least-recently-used bricks are
// dropped until usage is under 90% of the budget. Thread-safe: one mutex; callers batch.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/types.h"

namespace solidtex {

class VoxelCache {
 public:
  struct Counters {
    int64_t hits = 0;
    int64_t misses = 0;
    int64_t inserted = 0;
    int64_t evicted_bricks = 0;
    int64_t bricks = 0;
    int64_t bytes = 0;
    std::vector<int64_t> voxels_per_level;  // cached voxels per level
  };

  VoxelCache(int levels, int64_t budget_bytes);
  ~VoxelCache();
  VoxelCache(const VoxelCache&) = delete;
  VoxelCache& operator=(const VoxelCache&) = delete;

  // found[i] = 1 and out[i] set where voxels[i] is cached. Returns the number found.
  // Both calls are fastest with voxels grouped brick by brick (VoxelMask order).
  int64_t lookup(PyramidLevel level, const std::vector<Voxel>& voxels, std::vector<CoordinateTriple>& out,
                 std::vector<uint8_t>& found);
  void insert(PyramidLevel level, const std::vector<Voxel>& voxels, const std::vector<CoordinateTriple>& triples);
  void clear();
  Counters counters() const;
  // Memory of one brick holding `voxels` voxels: Counters::bytes is the sum over the bricks.
  static int64_t brick_bytes(int voxels);
  int64_t budget_bytes() const { return budget_.load(); }
  // Changes the budget, evicting at once (least recently used first, down to 90% of it) when
  // the cache holds more, so that lowering every share keeps the sum of the budgets a bound.
  void set_budget_bytes(int64_t bytes);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<int64_t> budget_;
};

}  // namespace solidtex
