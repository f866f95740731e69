#include "synthesis/dependency.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

namespace solidtex {
namespace {

Voxel add(const Voxel& p, const std::array<int8_t, 3>& o) { return {p.x + o[0], p.y + o[1], p.z + o[2]}; }

// Splits the final-version needs into cache hits and the set to synthesize.
void take_cached(VoxelCache* cache, PyramidLevel l, const std::vector<Voxel>& final_need, LevelDependencies& dep,
                 VoxelMask& final_set) {
  std::vector<CoordinateTriple> cached;
  std::vector<uint8_t> found(final_need.size(), 0);
  if (cache) cache->lookup(l, final_need, cached, found);
  for (size_t i = 0; i < final_need.size(); ++i) {
    if (found[i]) {
      dep.cache_hits.push_back(final_need[i]);
      dep.cached.push_back(cached[i]);
    } else {
      final_set.insert(final_need[i]);
    }
  }
}

// One step backwards: set v's members that step v updates read their stencil at the window's
// versions; the others carry down to v - 1. Returns the number of updates, or an error when a
// read escapes the level box.
Result<int64_t> step_back(const FrameStencils& stencils, PyramidLevel l, const CorrectionStep& step,
                          LevelDependencies& dep, int v, LatchedInterrupter& interrupter) {
  const std::vector<Voxel> members = dep.needed[size_t(v)].to_vector();
  std::atomic<int64_t> updated{0};
  std::atomic<bool> escaped{false};
  // Set union is order-independent, so the parallel inserts give the same sets.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, members.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
    if (interrupter.poll()) return;  // deadlines hold inside a step, not only between steps
    ReadStencil stencil;
    FrameStencils::Offsets offsets;
    int64_t local_updates = 0;
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const Voxel& p = members[i];
      if (!step.updates.contains(p)) {
        dep.needed[size_t(v - 1)].insert(p);
        continue;
      }
      ++local_updates;
      const HistoryWindow::Resolved window = step.window.resolve(p);
      for (const auto& o : stencils.offsets(l, p, stencil, offsets)) {
        const Voxel q = add(p, o);
        if (!dep.box.contains(q)) {
          escaped = true;
          continue;
        }
        dep.needed[size_t(window.version_of(q))].insert(q);
      }
    }
    updated += local_updates;
  });
  if (interrupter.stopped()) return Status(StatusCode::kCancelled, "synthesis cancelled");
  if (escaped) return Status(StatusCode::kInternal, "dependency escaped its bounding box (stencil reach too small)");
  return updated.load();
}

std::vector<Voxel> parents_of(const VoxelMask& set) {
  std::vector<Voxel> parents;
  parents.reserve(size_t(set.count()) / 4 + 1);
  for (const Voxel& p : set.to_vector()) parents.push_back(parent_of(p));
  std::sort(parents.begin(), parents.end());
  parents.erase(std::unique(parents.begin(), parents.end()), parents.end());
  return parents;
}

}  // namespace

// Level boxes, finest first: a level's sets stay within its final-version box dilated by the
// number of steps times the reach; the parents of that box bound the coarser final version.
std::vector<VoxelBox> dependency_boxes(const std::vector<LevelSchedule>& schedules, const FrameStencils& stencils,
                                       const VoxelBox& target_bounds) {
  const int L = stencils.levels();
  std::vector<VoxelBox> boxes(static_cast<size_t>(L));
  VoxelBox final_box = target_bounds;
  for (int l = L - 1; l >= 0; --l) {
    const int radius = schedules[size_t(l)].final_version() * stencils.reach(PyramidLevel{l});
    boxes[size_t(l)] = final_box.dilated(radius);
    const VoxelBox& b = boxes[size_t(l)];
    final_box = {parent_of(b.lo), {floor_div(b.hi.x - 1, 2) + 1, floor_div(b.hi.y - 1, 2) + 1, floor_div(b.hi.z - 1, 2) + 1}};
  }
  return boxes;
}

Result<std::vector<LevelDependencies>> analyze_dependencies(const DependencyInputs& in, const TargetSet& target,
                                                            LatchedInterrupter& interrupter) {
  const int L = in.stencils->levels();
  const std::vector<VoxelBox> boxes = dependency_boxes(*in.schedules, *in.stencils, target.bounds());
  std::vector<LevelDependencies> deps(static_cast<size_t>(L));
  std::vector<Voxel> final_need = target.voxels;
  for (int l = L - 1; l >= 0; --l) {
    const LevelSchedule& sch = (*in.schedules)[size_t(l)];
    const int V = sch.final_version();
    LevelDependencies& dep = deps[size_t(l)];
    dep.box = boxes[size_t(l)];
    for (int v = 0; v <= V; ++v) dep.needed.emplace_back(dep.box);
    dep.needed_final = int64_t(final_need.size());
    take_cached(in.cache, PyramidLevel{l}, final_need, dep, dep.needed[size_t(V)]);
    for (int v = V; v >= 1; --v) {
      if (interrupter.poll()) return Status(StatusCode::kCancelled, "synthesis cancelled");
      SOLIDTEX_ASSIGN_OR_RETURN(const int64_t updates,
                                step_back(*in.stencils, PyramidLevel{l}, sch.steps()[size_t(v - 1)], dep, v, interrupter));
      dep.corrections += updates;
    }
    if (l > 0) final_need = parents_of(dep.needed[0]);
  }
  return deps;
}

}  // namespace solidtex
