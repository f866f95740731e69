#include "synthesis/voxel_mask.h"

#include <algorithm>

namespace solidtex {

void VoxelBox::include(const Voxel& p) {
  if (empty()) {
    lo = p;
    hi = {p.x + 1, p.y + 1, p.z + 1};
    return;
  }
  lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
  hi = {std::max(hi.x, p.x + 1), std::max(hi.y, p.y + 1), std::max(hi.z, p.z + 1)};
}

VoxelMask::VoxelMask(const VoxelBox& box) : box_(box) {
  if (box.empty()) return;
  b0_ = {floor_div(box.lo.x, 8), floor_div(box.lo.y, 8), floor_div(box.lo.z, 8)};
  bn_ = {floor_div(box.hi.x - 1, 8) - b0_[0] + 1, floor_div(box.hi.y - 1, 8) - b0_[1] + 1,
         floor_div(box.hi.z - 1, 8) - b0_[2] + 1};
  table_size_ = size_t(bn_[0]) * bn_[1] * bn_[2];
  table_ = std::make_unique<std::atomic<int32_t>[]>(table_size_);
  for (size_t i = 0; i < table_size_; ++i) table_[i].store(-1, std::memory_order_relaxed);
  // Readers index pool_ without the lock: it must never reallocate.
  pool_.reserve(table_size_ / kChunk + 1);
}

VoxelMask::VoxelMask(VoxelMask&& o) noexcept
    : box_(o.box_), b0_(o.b0_), bn_(o.bn_), table_(std::move(o.table_)), table_size_(o.table_size_),
      pool_(std::move(o.pool_)), bricks_(o.bricks_), count_(o.count_.load()) {}

VoxelMask& VoxelMask::operator=(VoxelMask&& o) noexcept {
  box_ = o.box_;
  b0_ = o.b0_;
  bn_ = o.bn_;
  table_ = std::move(o.table_);
  table_size_ = o.table_size_;
  pool_ = std::move(o.pool_);
  bricks_ = o.bricks_;
  count_.store(o.count_.load());
  return *this;
}

int32_t VoxelMask::allocate_brick(int b) {
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
  const int b = brick_index(p);
  int32_t idx = table_[size_t(b)].load(std::memory_order_acquire);
  if (idx < 0) idx = allocate_brick(b);
  const int bit = (p.x & 7) + 8 * (p.y & 7) + 64 * (p.z & 7);
  std::atomic<uint64_t>& word = (*brick_at(idx))[size_t(bit >> 6)];
  const uint64_t m = uint64_t(1) << (bit & 63);
  if (word.load(std::memory_order_relaxed) & m) return false;
  if (word.fetch_or(m, std::memory_order_relaxed) & m) return false;
  count_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

bool VoxelMask::contains(const Voxel& p) const {
  if (!box_.contains(p)) return false;
  const int32_t idx = table_[size_t(brick_index(p))].load(std::memory_order_acquire);
  if (idx < 0) return false;
  const int bit = (p.x & 7) + 8 * (p.y & 7) + 64 * (p.z & 7);
  return ((*brick_at(idx))[size_t(bit >> 6)].load(std::memory_order_relaxed) >> (bit & 63)) & 1;
}

std::vector<Voxel> VoxelMask::to_vector() const {
  std::vector<Voxel> out;
  out.reserve(size_t(count()));
  for (int bz = 0; bz < bn_[2]; ++bz)
    for (int by = 0; by < bn_[1]; ++by)
      for (int bx = 0; bx < bn_[0]; ++bx) {
        const int32_t idx = table_[(size_t(bz) * bn_[1] + by) * bn_[0] + bx].load(std::memory_order_acquire);
        if (idx < 0) continue;
        const Brick& bits = *brick_at(idx);
        for (int w = 0; w < 8; ++w) {
          uint64_t word = bits[size_t(w)].load(std::memory_order_relaxed);
          while (word) {
            const int bit = w * 64 + __builtin_ctzll(word);
            word &= word - 1;
            out.push_back({(b0_[0] + bx) * 8 + (bit & 7), (b0_[1] + by) * 8 + ((bit >> 3) & 7),
                           (b0_[2] + bz) * 8 + (bit >> 6)});
          }
        }
      }
  return out;
}

}  // namespace solidtex
