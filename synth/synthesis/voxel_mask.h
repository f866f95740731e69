// Sparse voxel sets for dependency analysis: 8^3-voxel bit bricks, allocated on first use,
// indexed by a dense brick table over a fixed bounding box (brick_index.h). Insert/contains are O(1) with no
// hashing; iteration is in a fixed (brick, then bit) order whatever the insertion order, so
// anything derived from a mask is deterministic. insert() is thread-safe (atomic bit-or, brick
// allocation under a lock); contains()/to_vector() must not race with inserts.
// Whole-brick access (bits/or_bits) serves the brick-level dependency path: or_bits() calls
// on distinct bricks may run concurrently; on one brick, or together with insert(), they may not.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "synthesis/brick_index.h"

namespace solidtex {

class VoxelMask {
 public:
  VoxelMask() = default;
  explicit VoxelMask(const VoxelBox& box);
  VoxelMask(VoxelMask&&) noexcept;
  VoxelMask& operator=(VoxelMask&&) noexcept;

  const VoxelBox& box() const { return box_; }
  // Returns true when p was not yet in the set. p must lie inside box().
  bool insert(const Voxel& p);
  bool contains(const Voxel& p) const;
  int64_t count() const { return count_.load(std::memory_order_relaxed); }
  int64_t bricks() const { return bricks_; }  // allocated bricks (not thread-safe with inserts)
  std::vector<Voxel> to_vector() const;

  // 512 bits of one brick, bit x + 8y + 64z relative to the brick origin (brick_index.h).
  using Bits = std::array<uint64_t, 8>;
  const BrickIndex& index() const { return index_; }
  // The bits of brick number b (< index().size()); false (and zeros) when it was never allocated.
  bool bits(size_t b, Bits& out) const;
  // ORs `add` into brick b, allocating it only when `add` has a bit set (so bricks() stays the
  // count of non-empty bricks, as with insert()).
  void or_bits(size_t b, const Bits& add);

 private:
  using Brick = std::array<std::atomic<uint64_t>, 8>;  // 512 bits: bit (x + 8y + 64z)
  static constexpr int kChunk = 1024;                  // bricks per pool chunk (stable addresses)
  Brick* brick_at(int32_t index) const { return &(*pool_[size_t(index / kChunk)])[size_t(index % kChunk)]; }
  int32_t allocate_brick(size_t b);

  VoxelBox box_;
  BrickIndex index_;
  std::unique_ptr<std::atomic<int32_t>[]> table_;  // brick -> pool index, or -1
  size_t table_size_ = 0;
  std::vector<std::unique_ptr<std::array<Brick, kChunk>>> pool_;
  int32_t bricks_ = 0;
  std::mutex alloc_;
  std::atomic<int64_t> count_{0};
};

}  // namespace solidtex
