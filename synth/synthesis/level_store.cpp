#include "synthesis/level_store.h"

namespace solidtex {

LevelStore::LevelStore(const VoxelBox& box, int slots) : box_(box), slots_(slots), index_(box) {
  table_.assign(index_.size(), nullptr);
}

void LevelStore::allocate(const Voxel& p) {
  Brick*& b = table_[index_.brick_of(p)];
  if (b) return;
  auto nb = std::make_unique<Brick>();
  nb->triples.resize(size_t(512) * slots_);
  nb->colors.resize(size_t(512) * slots_);
  nb->flags = std::make_unique<std::atomic<uint8_t>[]>(size_t(512) * slots_);
  for (size_t i = 0; i < size_t(512) * slots_; ++i) nb->flags[i].store(0, std::memory_order_relaxed);
  b = nb.get();
  bricks_.push_back(std::move(nb));
}

bool LevelStore::has(const Voxel& p) const { return box_.contains(p) && brick(p) != nullptr; }

uint8_t LevelStore::flags(const Voxel& p, int slot) const {
  if (!has(p)) return 0;
  return brick(p)->flags[index(p, slot)].load(std::memory_order_relaxed);
}

void LevelStore::set_flag(const Voxel& p, int slot, uint8_t f) {
  brick(p)->flags[index(p, slot)].fetch_or(f, std::memory_order_relaxed);
}

}  // namespace solidtex
