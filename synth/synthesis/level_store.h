// Request-local storage of one pyramid level: every needed voxel's state at each of its
// update slots (level_schedule.slot()), in 8^3 bricks allocated before synthesis and indexed
// by a dense brick table over the level's bounding box. After allocation, reads and writes
// of distinct (voxel, slot) pairs from many threads are safe. Each slot has a flag byte used
// by the instrumented mode (required / read).
#pragma once

#include <array>
#include <atomic>
#include <memory>
#include <vector>

#include "synthesis/correction.h"
#include "synthesis/voxel_mask.h"

namespace solidtex {

class LevelStore {
  struct Brick;

 public:
  static constexpr uint8_t kRequired = 1;
  static constexpr uint8_t kRead = 2;
  static constexpr uint8_t kWritten = 4;

  LevelStore(const VoxelBox& box, int slots);
  void allocate(const Voxel& p);  // single-threaded, before synthesis
  bool has(const Voxel& p) const;
  VoxelState& at(const Voxel& p, int slot) { return brick(p)->states[index(p, slot)]; }
  const VoxelState& at(const Voxel& p, int slot) const { return brick(p)->states[index(p, slot)]; }
  uint8_t flags(const Voxel& p, int slot) const;
  void set_flag(const Voxel& p, int slot, uint8_t f);  // thread-safe (atomic or)
  int slots() const { return slots_; }

  // The 3x3x3 bricks around voxel p, looked up once, so that reads at offsets up to +-8
  // cost no table lookups. Missing bricks are null.
  class Neighborhood {
   public:
    Neighborhood(const LevelStore& store, const Voxel& p) : p_(p), slots_(store.slots_) {
      for (int z = -1; z <= 1; ++z)
        for (int y = -1; y <= 1; ++y)
          for (int x = -1; x <= 1; ++x) {
            const int bx = (p.x >> 3) + x - store.b0_[0], by = (p.y >> 3) + y - store.b0_[1],
                      bz = (p.z >> 3) + z - store.b0_[2];
            const bool inside = bx >= 0 && by >= 0 && bz >= 0 && bx < store.bn_[0] && by < store.bn_[1] && bz < store.bn_[2];
            near_[size_t((z + 1) * 9 + (y + 1) * 3 + (x + 1))] =
                inside ? store.table_[(size_t(bz) * store.bn_[1] + by) * store.bn_[0] + bx] : nullptr;
          }
    }
    const VoxelState& at(int dx, int dy, int dz, int slot) const {
      const int lx = (p_.x & 7) + dx, ly = (p_.y & 7) + dy, lz = (p_.z & 7) + dz;
      const Brick* b = near_[size_t(((lz >> 3) + 1) * 9 + ((ly >> 3) + 1) * 3 + ((lx >> 3) + 1))];
      return b->states[size_t((lx & 7) + 8 * (ly & 7) + 64 * (lz & 7)) * slots_ + slot];
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
    std::vector<VoxelState> states;  // 512 * slots
    std::unique_ptr<std::atomic<uint8_t>[]> flags;
  };
  size_t index(const Voxel& p, int slot) const {
    return size_t((p.x & 7) + 8 * (p.y & 7) + 64 * (p.z & 7)) * slots_ + slot;
  }
  int brick_index(const Voxel& p) const {
    return (((p.z >> 3) - b0_[2]) * bn_[1] + ((p.y >> 3) - b0_[1])) * bn_[0] + ((p.x >> 3) - b0_[0]);  // >> floors (C++20)
  }
  Brick* brick(const Voxel& p) const { return table_[size_t(brick_index(p))]; }
  int64_t brick_bytes() const { return 512 * slots_ * int64_t(sizeof(VoxelState) + 1); }

  VoxelBox box_;
  int slots_ = 1;
  std::array<int, 3> b0_{}, bn_{};
  std::vector<Brick*> table_;
  std::vector<std::unique_ptr<Brick>> bricks_;
};

}  // namespace solidtex
