#include "synthesis/voxel_mask.h"

namespace solidtex {

VoxelMask::VoxelMask(const VoxelBox& box) : box_(box), index_(box) {
  if (box.empty()) return;
  table_size_ = index_.size();
  table_ = std::make_unique<std::atomic<int32_t>[]>(table_size_);
  for (size_t i = 0; i < table_size_; ++i) table_[i].store(-1, std::memory_order_relaxed);
  // Readers index pool_ without the lock: it must never reallocate.
  pool_.reserve(table_size_ / kChunk + 1);
}

VoxelMask::VoxelMask(VoxelMask&& o) noexcept
    : box_(o.box_), index_(o.index_), table_(std::move(o.table_)), table_size_(o.table_size_),
      pool_(std::move(o.pool_)), bricks_(o.bricks_), count_(o.count_.load()) {}

VoxelMask& VoxelMask::operator=(VoxelMask&& o) noexcept {
  box_ = o.box_;
  index_ = o.index_;
  table_ = std::move(o.table_);
  table_size_ = o.table_size_;
  pool_ = std::move(o.pool_);
  bricks_ = o.bricks_;
  count_.store(o.count_.load());
  return *this;
}

int32_t VoxelMask::allocate_brick(size_t b) {
  std::lock_guard<std::mutex> g(alloc_);
  int32_t idx = table_[size_t(b)].load(std::memory_order_acquire);
  if (idx >= 0) return idx;
  if (bricks_ % kChunk == 0) {
    auto chunk = std::make_unique<std::array<Brick, kChunk>>();
    for (auto& br : *chunk)
      for (auto& w : br) w.store(0, std::memory_order_relaxed);
    pool_.push_back(std::move(chunk));
  }
  idx = bricks_++;
  table_[size_t(b)].store(idx, std::memory_order_release);
  return idx;
}

bool VoxelMask::insert(const Voxel& p) {
  const size_t b = index_.brick_of(p);
  int32_t idx = table_[b].load(std::memory_order_acquire);
  if (idx < 0) idx = allocate_brick(b);
  const int bit = BrickIndex::voxel_in_brick(p);
  std::atomic<uint64_t>& word = (*brick_at(idx))[size_t(bit >> 6)];
  const uint64_t m = uint64_t(1) << (bit & 63);
  if (word.load(std::memory_order_relaxed) & m) return false;
  if (word.fetch_or(m, std::memory_order_relaxed) & m) return false;
  count_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

bool VoxelMask::contains(const Voxel& p) const {
  if (!box_.contains(p)) return false;
  const int32_t idx = table_[index_.brick_of(p)].load(std::memory_order_acquire);
  if (idx < 0) return false;
  const int bit = BrickIndex::voxel_in_brick(p);
  return ((*brick_at(idx))[size_t(bit >> 6)].load(std::memory_order_relaxed) >> (bit & 63)) & 1;
}

bool VoxelMask::bits(size_t b, Bits& out) const {
  const int32_t idx = table_size_ ? table_[b].load(std::memory_order_acquire) : -1;
  if (idx < 0) {
    out.fill(0);
    return false;
  }
  const Brick& br = *brick_at(idx);
  for (size_t w = 0; w < 8; ++w) out[w] = br[w].load(std::memory_order_relaxed);
  return true;
}

void VoxelMask::or_bits(size_t b, const Bits& add) {
  uint64_t any = 0;
  for (uint64_t w : add) any |= w;
  if (!any) return;
  int32_t idx = table_[b].load(std::memory_order_acquire);
  if (idx < 0) idx = allocate_brick(b);
  Brick& br = *brick_at(idx);
  int64_t added = 0;
  for (size_t w = 0; w < 8; ++w) {
    const uint64_t old = br[w].load(std::memory_order_relaxed);
    br[w].store(old | add[w], std::memory_order_relaxed);  // one writer per brick: no read-modify-write
    added += __builtin_popcountll(add[w] & ~old);
  }
  count_.fetch_add(added, std::memory_order_relaxed);
}

std::vector<Voxel> VoxelMask::to_vector() const {
  std::vector<Voxel> out;
  out.reserve(size_t(count()));
  for (size_t b = 0; b < table_size_; ++b) {
    const int32_t idx = table_[b].load(std::memory_order_acquire);
    if (idx < 0) continue;
    const Voxel origin = index_.brick_origin(b);
    const Brick& bits = *brick_at(idx);
    for (int w = 0; w < 8; ++w) {
      uint64_t word = bits[size_t(w)].load(std::memory_order_relaxed);
      while (word) {
        const int bit = w * 64 + __builtin_ctzll(word);
        word &= word - 1;
        out.push_back(BrickIndex::voxel_at(origin, bit));
      }
    }
  }
  return out;
}

}  // namespace solidtex
