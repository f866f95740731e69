#include "synthesis/voxel_cache.h"

#include <openvdb/openvdb.h>

#include <algorithm>
#include <mutex>
#include <unordered_map>

namespace solidtex {
namespace {

openvdb::Vec3i pack(const CoordinateTriple& t) {
  auto one = [](const ExemplarPixel& p) { return int32_t(uint32_t(uint16_t(p.x)) | (uint32_t(uint16_t(p.y)) << 16)); };
  return {one(t.at[0]), one(t.at[1]), one(t.at[2])};
}

CoordinateTriple unpack(const openvdb::Vec3i& v) {
  CoordinateTriple t;
  for (int k = 0; k < 3; ++k) {
    const uint32_t u = uint32_t(v[k]);
    t.at[size_t(k)] = {int32_t(u & 0xffffu), int32_t(u >> 16)};
  }
  return t;
}

int64_t leaf_key(const openvdb::Coord& c) {
  auto f = [](int v) { return int64_t(uint32_t(v >> 3) & 0x1fffffu); };
  return f(c.x()) | (f(c.y()) << 21) | (f(c.z()) << 42);
}

}  // namespace

struct VoxelCache::Impl {
  std::mutex mutex;
  std::vector<openvdb::Vec3IGrid::Ptr> grids;
  std::vector<std::unordered_map<int64_t, std::pair<uint64_t, openvdb::Coord>>> last_use;  // per level
  uint64_t tick = 0;
  Counters counters;
  int64_t leaf_bytes = 0;
};

VoxelCache::VoxelCache(int levels, int64_t budget_bytes) : impl_(std::make_unique<Impl>()), budget_(budget_bytes) {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  for (int l = 0; l < levels; ++l) impl_->grids.push_back(openvdb::Vec3IGrid::create(openvdb::Vec3i(0, 0, 0)));
  impl_->last_use.resize(size_t(levels));
  impl_->counters.voxels_per_level.assign(size_t(levels), 0);
  openvdb::Vec3IGrid::TreeType::LeafNodeType leaf;
  impl_->leaf_bytes = int64_t(leaf.memUsage());
}

VoxelCache::~VoxelCache() = default;

int64_t VoxelCache::lookup(PyramidLevel level, const std::vector<Voxel>& voxels, std::vector<CoordinateTriple>& out,
                           std::vector<uint8_t>& found) {
  out.assign(voxels.size(), CoordinateTriple{});
  found.assign(voxels.size(), 0);
  std::lock_guard<std::mutex> g(impl_->mutex);
  auto& grid = *impl_->grids[size_t(level.index)];
  auto acc = grid.getConstAccessor();
  auto& uses = impl_->last_use[size_t(level.index)];
  const uint64_t now = ++impl_->tick;
  int64_t hits = 0;
  for (size_t i = 0; i < voxels.size(); ++i) {
    const openvdb::Coord c(voxels[i].x, voxels[i].y, voxels[i].z);
    openvdb::Vec3i v;
    if (acc.probeValue(c, v)) {
      out[i] = unpack(v);
      found[i] = 1;
      ++hits;
      auto it = uses.find(leaf_key(c));
      if (it != uses.end()) it->second.first = now;
    }
  }
  impl_->counters.hits += hits;
  impl_->counters.misses += int64_t(voxels.size()) - hits;
  return hits;
}

void VoxelCache::insert(PyramidLevel level, const std::vector<Voxel>& voxels, const std::vector<CoordinateTriple>& triples) {
  const int64_t budget = budget_.load();
  if (budget <= 0) return;
  std::lock_guard<std::mutex> g(impl_->mutex);
  auto& grid = *impl_->grids[size_t(level.index)];
  auto acc = grid.getAccessor();
  auto& uses = impl_->last_use[size_t(level.index)];
  const uint64_t now = ++impl_->tick;
  for (size_t i = 0; i < voxels.size(); ++i) {
    const openvdb::Coord c(voxels[i].x, voxels[i].y, voxels[i].z);
    if (!acc.isValueOn(c)) {
      ++impl_->counters.voxels_per_level[size_t(level.index)];
      ++impl_->counters.inserted;
    }
    acc.setValueOn(c, pack(triples[i]));
    auto& u = uses[leaf_key(c)];
    u.first = now;
    u.second = openvdb::Coord(c.x() & ~7, c.y() & ~7, c.z() & ~7);
  }
  // Evict least-recently-used leaves (over all levels) while over budget.
  int64_t leaves = 0;
  for (auto& gr : impl_->grids) leaves += gr->tree().leafCount();
  if (leaves * impl_->leaf_bytes <= budget) return;
  std::vector<std::tuple<uint64_t, int, openvdb::Coord, int64_t>> all;
  for (size_t l = 0; l < impl_->last_use.size(); ++l)
    for (auto& [key, u] : impl_->last_use[l]) all.emplace_back(u.first, int(l), u.second, key);
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
    return std::get<0>(a) < std::get<0>(b) || (std::get<0>(a) == std::get<0>(b) && std::get<3>(a) < std::get<3>(b));
  });
  const int64_t target = budget * 9 / 10;
  for (const auto& [t, l, origin, key] : all) {
    if (leaves * impl_->leaf_bytes <= target) break;
    auto& tree = impl_->grids[size_t(l)]->tree();
    if (auto* leaf = tree.probeLeaf(origin)) {
      impl_->counters.voxels_per_level[size_t(l)] -= int64_t(leaf->onVoxelCount());
      delete tree.stealNode<openvdb::Vec3IGrid::TreeType::LeafNodeType>(origin, openvdb::Vec3i(0, 0, 0), false);
      --leaves;
      ++impl_->counters.evicted_bricks;
    }
    impl_->last_use[size_t(l)].erase(key);
  }
}

void VoxelCache::clear() {
  std::lock_guard<std::mutex> g(impl_->mutex);
  for (auto& gr : impl_->grids) gr->clear();
  for (auto& u : impl_->last_use) u.clear();
  std::fill(impl_->counters.voxels_per_level.begin(), impl_->counters.voxels_per_level.end(), 0);
}

VoxelCache::Counters VoxelCache::counters() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  Counters c = impl_->counters;
  c.bricks = 0;
  for (auto& gr : impl_->grids) c.bricks += gr->tree().leafCount();
  c.bytes = c.bricks * impl_->leaf_bytes;
  return c;
}

}  // namespace solidtex
