// The sparse voxel cache: final coordinate triples of every pyramid level, kept across
// requests in OpenVDB Vec3i grids (one grid per level; each int32 packs one plane's 16-bit
// exemplar x and y), so storage comes in 8^3 leaf bricks. Only final versions are cached;
// by the purity invariant a cached value equals what any request would compute.
//
// Budget: when the grids' leaf bytes exceed `budget_bytes`, least-recently-used leaves are
// dropped until usage is under 90% of the budget. Thread-safe: one mutex; callers batch.
// Only voxel_cache.cpp includes OpenVDB.
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
  int64_t lookup(PyramidLevel level, const std::vector<Voxel>& voxels, std::vector<CoordinateTriple>& out,
                 std::vector<uint8_t>& found);
  void insert(PyramidLevel level, const std::vector<Voxel>& voxels, const std::vector<CoordinateTriple>& triples);
  void clear();
  Counters counters() const;
  int64_t budget_bytes() const { return budget_.load(); }
  // Changes the budget; takes effect (evicting if needed) at the next insert.
  void set_budget_bytes(int64_t bytes) { budget_.store(bytes); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<int64_t> budget_;
};

}  // namespace solidtex
