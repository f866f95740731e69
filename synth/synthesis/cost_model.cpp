#include "synthesis/cost_model.h"

#include <algorithm>
#include <map>
#include <numeric>

#include "synthesis/correction.h"
#include "synthesis/level_store.h"

namespace solidtex {
namespace {

constexpr int64_t kMaskTableBytesPerBrick = 4;   // VoxelMask: int32 pool index per brick of the box
constexpr int64_t kMaskBrickBytes = 64;          // 512 bits
constexpr int64_t kStoreTableBytesPerBrick = 8;  // LevelStore: a pointer per brick of the box
constexpr int64_t kStateBytes = LevelStore::kSlotBytes;  // triple + color + instrumentation flag

int64_t sat_mul(int64_t a, int64_t b) {
  if (a == 0 || b == 0) return 0;
  constexpr int64_t kMax = int64_t(1) << 62;
  return a > kMax / b ? kMax : a * b;
}

int64_t box_bricks(const VoxelBox& b) {
  if (b.empty()) return 0;
  // Saturating, unlike BrickIndex::size(): an absurd box must give a huge cost, not overflow.
  const int64_t nx = floor_div(b.hi.x - 1, 8) - floor_div(b.lo.x, 8) + 1;
  const int64_t ny = floor_div(b.hi.y - 1, 8) - floor_div(b.lo.y, 8) + 1;
  const int64_t nz = floor_div(b.hi.z - 1, 8) - floor_div(b.lo.z, 8) + 1;
  return sat_mul(sat_mul(nx, ny), nz);
}

int64_t box_volume(const VoxelBox& b) {
  if (b.empty()) return 0;
  return sat_mul(sat_mul(int64_t(b.hi.x) - b.lo.x, int64_t(b.hi.y) - b.lo.y), int64_t(b.hi.z) - b.lo.z);
}

}  // namespace

Result<std::vector<int>> measure_spread(const std::vector<LevelSchedule>& schedules, const FrameStencils& stencils,
                                        LatchedInterrupter& interrupter) {
  const int L = stencils.levels();
  std::vector<int> spread(size_t(L), 0);
  const DependencyInputs in{&schedules, &stencils, nullptr};
  // Probes at several phases of the cell and subpass lattices, which bound the spread.
  for (const int o : {0, 3, 5, 13}) {
    auto deps = analyze_dependencies(in, TargetSet::from_voxels({{o, o, o}}, 1, 1), PyramidLevel{L - 1}, interrupter);
    if (!deps.is_ok()) return deps.status();
    for (int l = 0; l < L; ++l) {
      const LevelDependencies& d = (*deps)[size_t(l)];
      const int V = int(d.needed.size()) - 1;
      VoxelBox served, all;
      for (const Voxel& p : d.needed[size_t(V)].to_vector()) served.include(p);
      for (const Voxel& p : d.needed[0].to_vector()) all.include(p);
      if (served.empty() || all.empty()) continue;
      const int grow = std::max({served.lo.x - all.lo.x, served.lo.y - all.lo.y, served.lo.z - all.lo.z,
                                 all.hi.x - served.hi.x, all.hi.y - served.hi.y, all.hi.z - served.hi.z});
      spread[size_t(l)] = std::max(spread[size_t(l)], grow);
    }
  }
  return spread;
}

RequestCost estimate_cost(const std::vector<LevelSchedule>& schedules, const FrameStencils& stencils,
                          const std::vector<int>& spread, const TargetSet& target, int support_reach) {
  RequestCost cost;
  const int L = stencils.levels();
  const VoxelBox target_box = target.bounds().dilated(support_reach);
  const std::vector<VoxelBox> boxes = dependency_boxes(schedules, stencils, target_box, PyramidLevel{L - 1});
  cost.levels.resize(size_t(L));
  // Every set voxel of level l lies within `radius` (its own voxels, per axis) of some target
  // voxel's position on that level: the level's spread plus the finer level's radius halved.
  const int64_t targets = int64_t(target.voxels.size());
  int64_t radius = 0;
  VoxelBox served = target_box;
  std::vector<int64_t> store(size_t(L), 0);
  int64_t masks = 0;
  for (int l = L - 1; l >= 0; --l) {
    const LevelSchedule& sch = schedules[size_t(l)];
    const VoxelBox& box = boxes[size_t(l)];
    const VoxelBox set_box = served.dilated(spread[size_t(l)]);
    radius = (l == L - 1 ? support_reach : radius / 2 + 1) + spread[size_t(l)];
    const int64_t side = 2 * radius + 1;
    const int64_t voxels = std::min(box_volume(set_box), sat_mul(targets, sat_mul(side, sat_mul(side, side))));
    const int64_t bricks = std::min(box_bricks(set_box), voxels);
    const int64_t versions = sch.final_version() + 1;
    const int64_t mask_bytes = sat_mul(versions, sat_mul(box_bricks(box), kMaskTableBytesPerBrick) +
                                                     sat_mul(bricks, kMaskBrickBytes));
    store[size_t(l)] = sat_mul(box_bricks(box), kStoreTableBytesPerBrick) +
                       sat_mul(bricks, sat_mul(512 * int64_t(sch.slot_count()), kStateBytes));
    LevelCost& lc = cost.levels[size_t(l)];
    lc.level = l;
    lc.voxels = voxels;
    lc.bytes = mask_bytes + store[size_t(l)];
    cost.voxels = std::min(cost.voxels + voxels, int64_t(1) << 62);
    masks = std::min(masks + mask_bytes, int64_t(1) << 62);
    // The parents the set needs lie in the parents' box.
    served = {parent_of(set_box.lo), {floor_div(set_box.hi.x - 1, 2) + 1, floor_div(set_box.hi.y - 1, 2) + 1,
                                      floor_div(set_box.hi.z - 1, 2) + 1}};
  }
  int64_t peak_stores = 0;
  for (int l = 0; l < L; ++l) peak_stores = std::max(peak_stores, store[size_t(l)] + (l > 0 ? store[size_t(l - 1)] : 0));
  cost.bytes = std::min(masks + peak_stores, int64_t(1) << 62);
  return cost;
}

int64_t store_bytes(const std::vector<LevelSchedule>& schedules, const std::vector<LevelDependencies>& deps) {
  int64_t peak = 0, previous = 0;
  for (size_t l = 0; l < deps.size(); ++l) {
    const LevelDependencies& d = deps[l];
    if (d.needed.empty()) continue;  // finer than a coarse target: nothing to store
    // Cache hits may add bricks the version-0 set does not touch: count their distinct bricks.
    const BrickIndex index(d.box);
    std::vector<size_t> hit_bricks;
    hit_bricks.reserve(d.cache_hits.size());
    for (const Voxel& p : d.cache_hits) hit_bricks.push_back(index.brick_of(p));
    std::sort(hit_bricks.begin(), hit_bricks.end());
    const int64_t distinct_hits = std::unique(hit_bricks.begin(), hit_bricks.end()) - hit_bricks.begin();
    const int64_t bricks = d.needed[0].bricks() + distinct_hits;
    const int64_t bytes = sat_mul(box_bricks(d.box), kStoreTableBytesPerBrick) +
                          sat_mul(std::min(bricks, box_bricks(d.box)), 512 * int64_t(schedules[l].slot_count()) * kStateBytes);
    peak = std::max(peak, bytes + previous);
    previous = bytes;
  }
  return peak;
}

std::vector<std::vector<uint32_t>> split_target(const TargetSet& target, int cell) {
  // Occupied cells, then union-find over 26-neighbouring cells.
  struct Key {
    int x, y, z;
    auto operator<=>(const Key&) const = default;
  };
  std::map<Key, int> cells;
  std::vector<int> cell_of(target.voxels.size());
  for (size_t i = 0; i < target.voxels.size(); ++i) {
    const Voxel& v = target.voxels[i];
    const Key k{floor_div(v.x, cell), floor_div(v.y, cell), floor_div(v.z, cell)};
    auto [it, inserted] = cells.emplace(k, int(cells.size()));
    cell_of[i] = it->second;
  }
  std::vector<int> parent(cells.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[size_t(a)] != a) a = parent[size_t(a)] = parent[size_t(parent[size_t(a)])];
    return a;
  };
  for (const auto& [k, id] : cells)
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          auto n = cells.find({k.x + dx, k.y + dy, k.z + dz});
          if (n == cells.end()) continue;
          const int a = find(id), b = find(n->second);
          if (a != b) parent[size_t(std::max(a, b))] = std::min(a, b);
        }
  std::map<int, size_t> piece_of_root;  // in order of first voxel (voxels are sorted)
  std::vector<std::vector<uint32_t>> pieces;
  for (size_t i = 0; i < target.voxels.size(); ++i) {
    const int root = find(cell_of[i]);
    auto [it, inserted] = piece_of_root.emplace(root, pieces.size());
    if (inserted) pieces.emplace_back();
    pieces[it->second].push_back(uint32_t(i));
  }
  return pieces;
}

}  // namespace solidtex
