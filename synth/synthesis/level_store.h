// Request-local storage of one pyramid level: every needed voxel's state at each of its
// update slots (LevelSchedule::slot()), in 8^3 bricks allocated before synthesis and indexed
// by a dense brick table over the level's bounding box (brick_index.h). After allocation, reads and writes
// of distinct (voxel, slot) pairs from many threads are safe. Each slot has a flag byte used
// by the instrumented mode (required / read).
#pragma once

#include <array>
#include <atomic>
#include <memory>
#include <vector>

#include "synthesis/correction.h"
#include "synthesis/brick_index.h"

namespace solidtex {

class LevelStore {
  struct Brick;

 public:
  static constexpr uint8_t kRequired = 1;
  static constexpr uint8_t kRead = 2;

  LevelStore(const VoxelBox& box, int slots);
  void allocate(const Voxel& p);  // single-threaded, before synthesis
  bool has(const Voxel& p) const;
  // Null when p lies outside the box or in a brick not allocated.
  const VoxelState* find(const Voxel& p, int slot) const { return has(p) ? &at(p, slot) : nullptr; }
  VoxelState& at(const Voxel& p, int slot) { return brick(p)->states[index(p, slot)]; }
  const VoxelState& at(const Voxel& p, int slot) const { return brick(p)->states[index(p, slot)]; }
  uint8_t flags(const Voxel& p, int slot) const;
  void set_flag(const Voxel& p, int slot, uint8_t f);  // thread-safe (atomic or)
  int slots() const { return slots_; }

  // The 3x3x3 bricks around voxel p, looked up once, so that reads at offsets up to +-kReach
  // cost no table lookups. Missing bricks are null. Callers whose stencils reach further use
  // at() (the synthesizer picks the path per level from the stencil reach).
  class Neighborhood {
   public:
    static constexpr int kReach = 8;
    Neighborhood(const LevelStore& store, const Voxel& p) : p_(p), slots_(store.slots_) {
      for (int z = -1; z <= 1; ++z)
        for (int y = -1; y <= 1; ++y)
          for (int x = -1; x <= 1; ++x) {
            const int64_t b = store.index_.brick_near(p, x, y, z);
            near_[size_t((z + 1) * 9 + (y + 1) * 3 + (x + 1))] = b >= 0 ? store.table_[size_t(b)] : nullptr;
          }
    }
    // |dx|, |dy|, |dz| <= kReach; the brick of p + (dx, dy, dz) must be allocated.
    const VoxelState& at(int dx, int dy, int dz, int slot) const { return *find(dx, dy, dz, slot); }
    // Null when the brick of p + (dx, dy, dz) is not allocated.
    const VoxelState* find(int dx, int dy, int dz, int slot) const {
      const int lx = (p_.x & 7) + dx, ly = (p_.y & 7) + dy, lz = (p_.z & 7) + dz;
      const Brick* b = near_[size_t(((lz >> 3) + 1) * 9 + ((ly >> 3) + 1) * 3 + ((lx >> 3) + 1))];
      return b ? &b->states[size_t(slot) * 512 + size_t((lx & 7) + 8 * (ly & 7) + 64 * (lz & 7))] : nullptr;
    }

   private:
    Voxel p_;
    int slots_;
    std::array<const Brick*, 27> near_{};
  };
  int64_t bytes() const { return int64_t(bricks_.size()) * brick_bytes(); }
  const VoxelBox& box() const { return box_; }

 private:
  struct Brick {
    std::vector<VoxelState> states;  // slots * 512, slot-major
    std::unique_ptr<std::atomic<uint8_t>[]> flags;
  };
  // Slot-major: the voxels a correction reads (one slot, neighbouring positions) share cache lines.
  size_t index(const Voxel& p, int slot) const { return size_t(slot) * 512 + size_t(BrickIndex::voxel_in_brick(p)); }
  Brick* brick(const Voxel& p) const { return table_[index_.brick_of(p)]; }
  int64_t brick_bytes() const { return 512 * slots_ * int64_t(sizeof(VoxelState) + 1); }

  VoxelBox box_;
  int slots_ = 1;
  BrickIndex index_;
  std::vector<Brick*> table_;
  std::vector<std::unique_ptr<Brick>> bricks_;
};

}  // namespace solidtex
