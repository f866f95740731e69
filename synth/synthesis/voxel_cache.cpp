#include "synthesis/voxel_cache.h"

#include <algorithm>
#include <array>
#include <mutex>
#include <tuple>
#include <unordered_map>

#include "core/hash.h"

namespace solidtex {
namespace {

using Packed = std::array<int32_t, 3>;  // one int32 per plane: 16-bit exemplar x | 16-bit y << 16

Packed pack(const CoordinateTriple& t) {
  auto one = [](const ExemplarPixel& p) { return int32_t(uint32_t(uint16_t(p.x)) | (uint32_t(uint16_t(p.y)) << 16)); };
  return {one(t.at[0]), one(t.at[1]), one(t.at[2])};
}

CoordinateTriple unpack(const Packed& v) {
  CoordinateTriple t;
  for (int k = 0; k < 3; ++k) {
    const uint32_t u = uint32_t(v[size_t(k)]);
    t.at[size_t(k)] = {int32_t(u & 0xffffu), int32_t(u >> 16)};
  }
  return t;
}

// A brick: the 8^3 voxels whose coordinates >> 3 are `key` (arithmetic shift: floor).
struct BrickKey {
  int32_t x = 0, y = 0, z = 0;
  friend bool operator==(const BrickKey&, const BrickKey&) = default;
  friend auto operator<=>(const BrickKey&, const BrickKey&) = default;
};
struct BrickKeyHash {
  size_t operator()(const BrickKey& k) const {
    return size_t(mix64((uint64_t(uint32_t(k.x)) << 32 | uint32_t(k.y)) ^ mix64(uint64_t(uint32_t(k.z)) + 1)));
  }
};
BrickKey key_of(const Voxel& v) { return {v.x >> 3, v.y >> 3, v.z >> 3}; }
int slot_of(const Voxel& v) { return (v.x & 7) | ((v.y & 7) << 3) | ((v.z & 7) << 6); }

struct Brick {
  std::array<Packed, 512> values{};
  std::array<uint64_t, 8> present{};  // one bit per voxel
  uint64_t last_use = 0;
  bool has(int s) const { return (present[size_t(s >> 6)] >> (s & 63)) & 1u; }
};

using BrickMap = std::unordered_map<BrickKey, Brick, BrickKeyHash>;

// What one brick costs in memory: the map node (key, brick, next pointer, cached hash), its
// bucket and the allocator's header and rounding. The budget counts this, so --cache-mb bounds
// what the cache really holds (no tree nodes or side tables beside the bricks).
constexpr int64_t kBrickBytes =
    int64_t((sizeof(BrickKey) + sizeof(Brick) + 2 * sizeof(void*) + 16 + 15) / 16 * 16 + sizeof(void*));

}  // namespace

struct VoxelCache::Impl {
  std::mutex mutex;
  std::vector<BrickMap> levels;
  uint64_t tick = 0;
  Counters counters;
  int64_t bricks = 0;

  void evict_to(int64_t target) {
    std::vector<std::tuple<uint64_t, int, BrickKey>> all;
    all.reserve(size_t(bricks));
    for (size_t l = 0; l < levels.size(); ++l)
      for (const auto& [key, b] : levels[l]) all.emplace_back(b.last_use, int(l), key);
    std::sort(all.begin(), all.end());  // least recently used first; ties by level, then brick
    for (const auto& [t, l, key] : all) {
      if (bricks * kBrickBytes <= target) break;
      auto it = levels[size_t(l)].find(key);
      int64_t n = 0;
      for (uint64_t w : it->second.present) n += __builtin_popcountll(w);
      counters.voxels_per_level[size_t(l)] -= n;
      levels[size_t(l)].erase(it);
      --bricks;
      ++counters.evicted_bricks;
    }
  }
};

VoxelCache::VoxelCache(int levels, int64_t budget_bytes) : impl_(std::make_unique<Impl>()), budget_(budget_bytes) {
  impl_->levels.resize(size_t(levels));
  impl_->counters.voxels_per_level.assign(size_t(levels), 0);
}

VoxelCache::~VoxelCache() = default;

int64_t VoxelCache::brick_bytes() { return kBrickBytes; }

int64_t VoxelCache::lookup(PyramidLevel level, const std::vector<Voxel>& voxels, std::vector<CoordinateTriple>& out,
                           std::vector<uint8_t>& found) {
  out.assign(voxels.size(), CoordinateTriple{});
  found.assign(voxels.size(), 0);
  std::lock_guard<std::mutex> g(impl_->mutex);
  BrickMap& map = impl_->levels[size_t(level.index)];
  const uint64_t now = ++impl_->tick;
  int64_t hits = 0;
  BrickKey last_key{};
  Brick* last = nullptr;
  bool have_last = false;
  for (size_t i = 0; i < voxels.size(); ++i) {
    const BrickKey k = key_of(voxels[i]);
    if (!have_last || !(k == last_key)) {
      auto it = map.find(k);
      last = it == map.end() ? nullptr : &it->second;
      last_key = k;
      have_last = true;
    }
    if (!last) continue;
    const int s = slot_of(voxels[i]);
    if (!last->has(s)) continue;
    out[i] = unpack(last->values[size_t(s)]);
    found[i] = 1;
    ++hits;
    last->last_use = now;
  }
  impl_->counters.hits += hits;
  impl_->counters.misses += int64_t(voxels.size()) - hits;
  return hits;
}

void VoxelCache::insert(PyramidLevel level, const std::vector<Voxel>& voxels, const std::vector<CoordinateTriple>& triples) {
  const int64_t budget = budget_.load();
  if (budget <= 0) return;
  std::lock_guard<std::mutex> g(impl_->mutex);
  BrickMap& map = impl_->levels[size_t(level.index)];
  const uint64_t now = ++impl_->tick;
  BrickKey last_key{};
  Brick* last = nullptr;
  for (size_t i = 0; i < voxels.size(); ++i) {
    const BrickKey k = key_of(voxels[i]);
    if (!last || !(k == last_key)) {
      auto [it, inserted] = map.try_emplace(k);
      if (inserted) ++impl_->bricks;
      last = &it->second;
      last_key = k;
    }
    const int s = slot_of(voxels[i]);
    if (!last->has(s)) {
      last->present[size_t(s >> 6)] |= uint64_t(1) << (s & 63);
      ++impl_->counters.voxels_per_level[size_t(level.index)];
      ++impl_->counters.inserted;
    }
    last->values[size_t(s)] = pack(triples[i]);
    last->last_use = now;
  }
  // Evict least-recently-used bricks (over all levels) while over budget, down to 90% of it.
  if (impl_->bricks * kBrickBytes > budget) impl_->evict_to(budget * 9 / 10);
}

void VoxelCache::set_budget_bytes(int64_t bytes) {
  budget_.store(bytes);
  std::lock_guard<std::mutex> g(impl_->mutex);
  if (impl_->bricks * kBrickBytes > bytes) impl_->evict_to(std::max<int64_t>(0, bytes) * 9 / 10);
}

void VoxelCache::clear() {
  std::lock_guard<std::mutex> g(impl_->mutex);
  for (auto& m : impl_->levels) BrickMap().swap(m);  // frees the buckets too
  impl_->bricks = 0;
  std::fill(impl_->counters.voxels_per_level.begin(), impl_->counters.voxels_per_level.end(), 0);
}

VoxelCache::Counters VoxelCache::counters() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  Counters c = impl_->counters;
  c.bricks = impl_->bricks;
  c.bytes = c.bricks * kBrickBytes;
  return c;
}

}  // namespace solidtex
