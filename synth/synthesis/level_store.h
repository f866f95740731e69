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
  // Triples and colors are stored apart (structure of arrays, slot-major per brick): a
  // correction reads hundreds of neighbours' colors and only 28 triples, so the colors it
  // reads share cache lines. p's brick must be allocated.
  CoordinateTriple& triple(const Voxel& p, int slot) { return brick(p)->triples[index(p, slot)]; }
  const CoordinateTriple& triple(const Voxel& p, int slot) const { return brick(p)->triples[index(p, slot)]; }
  StateColor& color(const Voxel& p, int slot) { return brick(p)->colors[index(p, slot)]; }
  const StateColor& color(const Voxel& p, int slot) const { return brick(p)->colors[index(p, slot)]; }
  VoxelState state(const Voxel& p, int slot) const { return {triple(p, slot), color(p, slot)}; }
  void set(const Voxel& p, int slot, const VoxelState& s) {
    triple(p, slot) = s.triple;
    color(p, slot) = s.color;
  }
  uint8_t flags(const Voxel& p, int slot) const;
  void set_flag(const Voxel& p, int slot, uint8_t f);  // thread-safe (atomic or)
  int slots() const { return slots_; }

  // The 3x3x3 bricks around voxel p, looked up once, so that reads at offsets up to +-kReach
  // cost no table lookups. Missing bricks are null. Callers whose stencils reach further use
  // the store itself (the synthesizer picks the path per level from the stencil reach).
  class Neighborhood {
   public:
    static constexpr int kReach = 8;
    Neighborhood(const LevelStore& store, const Voxel& p) : p_(p) {
      for (int z = -1; z <= 1; ++z)
        for (int y = -1; y <= 1; ++y)
          for (int x = -1; x <= 1; ++x) {
            const int64_t b = store.index_.brick_near(p, x, y, z);
            near_[size_t((z + 1) * 9 + (y + 1) * 3 + (x + 1))] = b >= 0 ? store.table_[size_t(b)] : nullptr;
          }
    }
    // |dx|, |dy|, |dz| <= kReach. Null when the brick of p + (dx, dy, dz) is not allocated.
    const StateColor* color(int dx, int dy, int dz, int slot) const {
      size_t i;
      const Brick* b = locate(dx, dy, dz, slot, i);
      return b ? &b->colors[i] : nullptr;
    }
    const CoordinateTriple* triple(int dx, int dy, int dz, int slot) const {
      size_t i;
      const Brick* b = locate(dx, dy, dz, slot, i);
      return b ? &b->triples[i] : nullptr;
    }

   private:
    const Brick* locate(int dx, int dy, int dz, int slot, size_t& i) const {
      const int lx = (p_.x & 7) + dx, ly = (p_.y & 7) + dy, lz = (p_.z & 7) + dz;
      i = size_t(slot) * 512 + size_t((lx & 7) + 8 * (ly & 7) + 64 * (lz & 7));
      return near_[size_t(((lz >> 3) + 1) * 9 + ((ly >> 3) + 1) * 3 + ((lx >> 3) + 1))];
    }
    Voxel p_;
    std::array<const Brick*, 27> near_{};
  };
  int64_t bytes() const { return int64_t(bricks_.size()) * brick_bytes(); }
  const VoxelBox& box() const { return box_; }
  // Bytes one (voxel, slot) costs: triple, color and instrumentation flag.
  static constexpr int64_t kSlotBytes = int64_t(sizeof(CoordinateTriple) + sizeof(StateColor) + 1);

 private:
  struct Brick {
    std::vector<CoordinateTriple> triples;  // slots * 512, slot-major
    std::vector<StateColor> colors;         // the same layout
    std::unique_ptr<std::atomic<uint8_t>[]> flags;
  };
  size_t index(const Voxel& p, int slot) const { return size_t(slot) * 512 + size_t(BrickIndex::voxel_in_brick(p)); }
  Brick* brick(const Voxel& p) const { return table_[index_.brick_of(p)]; }
  int64_t brick_bytes() const { return 512 * slots_ * kSlotBytes; }

  VoxelBox box_;
  int slots_ = 1;
  BrickIndex index_;
  std::vector<Brick*> table_;
  std::vector<std::unique_ptr<Brick>> bricks_;
};

}  // namespace solidtex
