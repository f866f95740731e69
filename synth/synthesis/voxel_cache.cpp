#include "synthesis/voxel_cache.h"

#include <algorithm>
#include <array>
#include <memory>
#include <mutex>
#include <tuple>
#include <unordered_map>
#include <utility>

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

// A brick stores only its present voxels' values, in slot order (a voxel's index is the number
// of present voxels before its slot): a cut fills bricks partly, often one 8^2 layer of 512, and
// dense bricks would cost 96 bytes per cached voxel there instead of ~14.
struct Brick {
  std::array<uint64_t, 8> present{};  // one bit per voxel
  std::unique_ptr<Packed[]> values;   // count() entries, exactly sized
  uint64_t last_use = 0;
  bool has(int s) const { return (present[size_t(s >> 6)] >> (s & 63)) & 1u; }
  int count() const {
    int n = 0;
    for (uint64_t w : present) n += __builtin_popcountll(w);
    return n;
  }
  int index_of(int s) const {
    int n = 0;
    for (int w = 0; w < (s >> 6); ++w) n += __builtin_popcountll(present[size_t(w)]);
    return n + __builtin_popcountll(present[size_t(s >> 6)] & ((uint64_t(1) << (s & 63)) - 1));
  }
};

using BrickMap = std::unordered_map<BrickKey, Brick, BrickKeyHash>;

// What a brick of n voxels costs in memory: the map node (key, brick, next pointer, cached
// hash) and its bucket, plus the value array, each with glibc malloc's 8-byte header rounded up
// to 16 (32 at least). The budget counts this, so --cache-mb bounds what the cache really holds
// (no tree nodes or side tables beside the bricks).
constexpr int64_t malloc_chunk(int64_t bytes) { return std::max<int64_t>(32, (bytes + 8 + 15) / 16 * 16); }
constexpr int64_t kNodeBytes = malloc_chunk(int64_t(sizeof(BrickKey) + sizeof(Brick) + 2 * sizeof(void*))) + int64_t(sizeof(void*));
int64_t brick_cost(int voxels) { return kNodeBytes + (voxels > 0 ? malloc_chunk(int64_t(voxels) * int64_t(sizeof(Packed))) : 0); }

// Writes a run of (slot, value) pairs of one brick: new slots are merged in, slot order kept.
void write_run(Brick& b, const std::vector<std::pair<int, Packed>>& run, int64_t& new_voxels) {
  std::array<uint64_t, 8> present = b.present;
  for (const auto& [s, v] : run) present[size_t(s >> 6)] |= uint64_t(1) << (s & 63);
  int added = 0;
  for (size_t w = 0; w < 8; ++w) added += __builtin_popcountll(present[w] & ~b.present[w]);
  if (added > 0) {
    const int n = b.count() + added;
    auto values = std::make_unique<Packed[]>(size_t(n));
    int from = 0, to = 0;
    for (size_t w = 0; w < 8; ++w)
      for (uint64_t bits = present[w]; bits; bits &= bits - 1) {
        const bool old = (b.present[w] >> __builtin_ctzll(bits)) & 1u;
        values[size_t(to++)] = old ? b.values[size_t(from++)] : Packed{};
      }
    b.values = std::move(values);
    b.present = present;
    new_voxels += added;
  }
  for (const auto& [s, v] : run) b.values[size_t(b.index_of(s))] = v;
}

}  // namespace

struct VoxelCache::Impl {
  std::mutex mutex;
  std::vector<BrickMap> levels;
  uint64_t tick = 0;
  Counters counters;
  int64_t bricks = 0;
  int64_t bytes = 0;  // sum of brick_cost over the bricks

  void evict_to(int64_t target) {
    std::vector<std::tuple<uint64_t, int, BrickKey>> all;
    all.reserve(size_t(bricks));
    for (size_t l = 0; l < levels.size(); ++l)
      for (const auto& [key, b] : levels[l]) all.emplace_back(b.last_use, int(l), key);
    std::sort(all.begin(), all.end());  // least recently used first; ties by level, then brick
    for (const auto& [t, l, key] : all) {
      if (bytes <= target) break;
      auto it = levels[size_t(l)].find(key);
      const int n = it->second.count();
      counters.voxels_per_level[size_t(l)] -= n;
      bytes -= brick_cost(n);
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

int64_t VoxelCache::brick_bytes(int voxels) { return brick_cost(voxels); }

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
    out[i] = unpack(last->values[size_t(last->index_of(s))]);
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
  // Runs of consecutive voxels in one brick (callers pass voxels brick by brick) are merged
  // into it at once; a brick met again later just takes another run.
  std::vector<std::pair<int, Packed>> run;
  for (size_t i = 0; i < voxels.size();) {
    const BrickKey k = key_of(voxels[i]);
    run.clear();
    for (; i < voxels.size() && key_of(voxels[i]) == k; ++i) run.emplace_back(slot_of(voxels[i]), pack(triples[i]));
    auto [it, inserted] = map.try_emplace(k);
    Brick& b = it->second;
    if (inserted) ++impl_->bricks;
    const int before = inserted ? 0 : b.count();
    int64_t added = 0;
    write_run(b, run, added);
    impl_->bytes += brick_cost(before + int(added)) - (inserted ? 0 : brick_cost(before));
    impl_->counters.voxels_per_level[size_t(level.index)] += added;
    impl_->counters.inserted += added;
    b.last_use = now;
  }
  // Evict least-recently-used bricks (over all levels) while over budget, down to 90% of it.
  if (impl_->bytes > budget) impl_->evict_to(budget * 9 / 10);
}

void VoxelCache::set_budget_bytes(int64_t bytes) {
  budget_.store(bytes);
  std::lock_guard<std::mutex> g(impl_->mutex);
  if (impl_->bytes > bytes) impl_->evict_to(std::max<int64_t>(0, bytes) * 9 / 10);
}

void VoxelCache::clear() {
  std::lock_guard<std::mutex> g(impl_->mutex);
  for (auto& m : impl_->levels) BrickMap().swap(m);  // frees the buckets too
  impl_->bricks = 0;
  impl_->bytes = 0;
  std::fill(impl_->counters.voxels_per_level.begin(), impl_->counters.voxels_per_level.end(), 0);
}

VoxelCache::Counters VoxelCache::counters() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  Counters c = impl_->counters;
  c.bricks = impl_->bricks;
  c.bytes = impl_->bytes;
  return c;
}

}  // namespace solidtex
