// Request-local storage of one pyramid level: every needed voxel's state at each of its
// update slots (level_schedule.slot()), in 8^3 bricks allocated before synthesis and indexed
// by a dense brick table over the level's bounding box. After allocation, reads and writes
// of distinct (voxel, slot) pairs from many threads are safe. Each slot has a flag byte used
// by the instrumented mode (required / read).
#pragma once

#include <atomic>
#include <memory>
#include <vector>

#include "correction.h"
#include "voxel_mask.h"

namespace solidtex {

class LevelStore {
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
