#include "synthesis/dependency.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <map>
#include <utility>

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

// ---- Brick-level step, for stencils that are the same at every voxel of the level ----
//
// The per-voxel step marks (p + o, H(p, o)) for every updated p and offset o. With one offset
// list for the whole level, the marks of offset o are the updated set shifted by o, split by
// version: H(p, o) = min(latest, barrier versions of the barriers whose cell p + o leaves).
// "p + o stays in p's cell" is per axis a condition on p's coordinate, so the voxels of a
// destination brick reading a given version form a product of three 8-bit masks. Each
// destination brick gathers its bits from the (at most 8) source bricks under it, so each brick
// of every set is written by one task: no atomics, and the same sets as the per-voxel path.

using Bits = VoxelMask::Bits;

// Every row (byte) of a z-slice word with its low k bits set, 0 <= k <= 8.
constexpr uint64_t low_rows(int k) {
  return k >= 8 ? ~uint64_t(0) : uint64_t(0x0101010101010101ull) * ((uint64_t(1) << k) - 1);
}

// The brick mask {x in mx, y in my, z in mz}.
Bits product_mask(uint8_t mx, uint8_t my, uint8_t mz) {
  uint64_t slice = 0;
  for (int y = 0; y < 8; ++y)
    if ((my >> y) & 1) slice |= uint64_t(mx) << (8 * y);
  Bits b;
  for (int z = 0; z < 8; ++z) b[size_t(z)] = ((mz >> z) & 1) ? slice : 0;
  return b;
}

// Offset o as a brick shift: destination voxel t reads source t - o, i.e. `brick` whole
// bricks plus `rest` voxels (0..7) on each axis.
struct ShiftPlan {
  std::array<int, 3> o{}, brick{}, rest{};
  uint64_t keep_lo = 0, keep_hi = 0;  // x bits taken from the lower / upper source brick
};

// Dense brick coordinates: the level's brick cover with a margin of 2m bricks on every side,
// so that every destination brick (cover + m) and its sources (destination + [-m, m]) exist.
struct BrickGrid {
  std::array<int, 3> first{}, cover{}, n{};
  int pad = 0;
  size_t at(int x, int y, int z) const { return (size_t(z) * size_t(n[1]) + size_t(y)) * size_t(n[0]) + size_t(x); }
  size_t size() const { return size_t(n[0]) * size_t(n[1]) * size_t(n[2]); }
};

// Offsets sharing (dy, dz) share the y/z part of the shift: it is gathered once per x brick
// (y/z-shifted slices), and each member then shifts along x only.
struct ShiftGroup {
  int y_brick = 0, z_brick = 0, ry = 0, rz = 0;
  int xb_lo = 0, xb_hi = 0;  // x bricks the members read: their x brick shifts, plus one for the spill
  std::vector<size_t> members;  // into the plans
};

// The y/z-shifted slices of the source bricks at grid x = x for destination (Y, Z); returns
// the OR of all words (0: nothing to shift).
uint64_t gather_yz(const std::vector<const Bits*>& src, const BrickGrid& g, int x, int Y, int Z, const ShiftGroup& gr,
                   Bits& out) {
  const int y0 = Y + gr.y_brick, z0 = Z + gr.z_brick;
  uint64_t any = 0;
  for (int tz = 0; tz < 8; ++tz) {
    const int sz = tz + gr.rz;
    const int zb = z0 + (sz >> 3);
    const size_t wz = size_t(sz & 7);
    uint64_t w = (*src[g.at(x, y0, zb)])[wz] >> (8 * gr.ry);
    if (gr.ry) w |= (*src[g.at(x, y0 + 1, zb)])[wz] << (64 - 8 * gr.ry);
    out[size_t(tz)] = w;
    any |= w;
  }
  return any;
}

Result<int64_t> brick_step_back(const FrameStencils::Offsets& offsets, const CorrectionStep& step,
                                LevelDependencies& dep, int v, LatchedInterrupter& interrupter) {
  static const Bits kZero{};
  const VoxelMask& cur = dep.needed[size_t(v)];
  const BrickIndex& index = cur.index();
  int reach = 0;
  for (const auto& o : offsets)
    for (int a = 0; a < 3; ++a) reach = std::max(reach, std::abs(int(o[size_t(a)])));
  const int m = (reach + 7) / 8 + 1;
  BrickGrid g;
  g.first = index.first_brick();
  g.cover = index.extent();
  g.pad = 2 * m;
  for (int a = 0; a < 3; ++a) g.n[size_t(a)] = g.cover[size_t(a)] + 4 * m;

  // The update class as a brick pattern: it depends on coordinates mod s, and s divides 8
  // (checked by the caller), so every brick has the same pattern.
  Bits updates{};
  for (int bit = 0; bit < BrickIndex::kVoxels; ++bit)
    if (step.updates.contains(BrickIndex::voxel_at({0, 0, 0}, bit))) updates[size_t(bit >> 6)] |= uint64_t(1) << (bit & 63);

  // Sources (updated members) and carries (members the step leaves alone), per cover brick.
  std::vector<const Bits*> src(g.size(), &kZero);
  std::vector<int32_t> carry_of(g.size(), -1);
  std::vector<Bits> sources, carries;
  sources.reserve(size_t(cur.bricks()));
  carries.reserve(size_t(cur.bricks()));
  std::vector<uint8_t> candidate(g.size(), 0);
  int dlo[3], dhi[3];
  {
    int omin[3] = {0, 0, 0}, omax[3] = {0, 0, 0};
    for (const auto& o : offsets)
      for (int a = 0; a < 3; ++a) {
        omin[a] = std::min(omin[a], int(o[size_t(a)]));
        omax[a] = std::max(omax[a], int(o[size_t(a)]));
      }
    for (int a = 0; a < 3; ++a) {
      dlo[a] = floor_div(omin[a], 8);
      dhi[a] = floor_div(7 + omax[a], 8);
    }
  }
  int64_t updated = 0;
  Bits s;
  for (size_t b = 0; b < index.size(); ++b) {
    if (!cur.bits(b, s)) continue;
    const int cx = int(b % size_t(g.cover[0])), cy = int(b / size_t(g.cover[0]) % size_t(g.cover[1])),
              cz = int(b / (size_t(g.cover[0]) * size_t(g.cover[1])));
    const int X = cx + g.pad, Y = cy + g.pad, Z = cz + g.pad;
    Bits a, c;
    uint64_t any_a = 0, any_c = 0;
    for (size_t w = 0; w < 8; ++w) {
      a[w] = s[w] & updates[w];
      c[w] = s[w] & ~updates[w];
      any_a |= a[w];
      any_c |= c[w];
      updated += __builtin_popcountll(a[w]);
    }
    if (any_c) {
      carry_of[g.at(X, Y, Z)] = int32_t(carries.size());
      carries.push_back(c);
      candidate[g.at(X, Y, Z)] = 1;
    }
    if (any_a) {
      sources.push_back(a);
      src[g.at(X, Y, Z)] = &sources.back();
      for (int z = Z + dlo[2]; z <= Z + dhi[2]; ++z)
        for (int y = Y + dlo[1]; y <= Y + dhi[1]; ++y)
          for (int x = X + dlo[0]; x <= X + dhi[0]; ++x) candidate[g.at(x, y, z)] = 1;
    }
  }
  std::vector<std::array<int, 3>> dests;
  for (int z = 0; z < g.n[2]; ++z)
    for (int y = 0; y < g.n[1]; ++y)
      for (int x = 0; x < g.n[0]; ++x)
        if (candidate[g.at(x, y, z)]) dests.push_back({x, y, z});

  std::vector<ShiftPlan> plans;
  plans.reserve(offsets.size());
  for (const auto& o : offsets) {
    ShiftPlan p;
    for (int a = 0; a < 3; ++a) {
      p.o[size_t(a)] = o[size_t(a)];
      p.brick[size_t(a)] = floor_div(-int(o[size_t(a)]), 8);
      p.rest[size_t(a)] = -int(o[size_t(a)]) - 8 * p.brick[size_t(a)];
    }
    p.keep_lo = low_rows(8 - p.rest[0]);
    p.keep_hi = ~p.keep_lo;
    plans.push_back(p);
  }
  std::map<std::pair<int, int>, ShiftGroup> by_yz;
  for (size_t i = 0; i < plans.size(); ++i) {
    const ShiftPlan& p = plans[i];
    auto [it, fresh] = by_yz.try_emplace({p.o[1], p.o[2]});
    ShiftGroup& gr = it->second;
    if (fresh) {
      gr.y_brick = p.brick[1];
      gr.z_brick = p.brick[2];
      gr.ry = p.rest[1];
      gr.rz = p.rest[2];
      gr.xb_lo = p.brick[0];
      gr.xb_hi = p.brick[0] + 1;
    }
    gr.xb_lo = std::min(gr.xb_lo, p.brick[0]);
    gr.xb_hi = std::max(gr.xb_hi, p.brick[0] + 1);
    gr.members.push_back(i);
  }
  std::vector<ShiftGroup> groups;
  size_t widest = 0;
  for (auto& [key, gr] : by_yz) {
    widest = std::max(widest, size_t(gr.xb_hi - gr.xb_lo + 1));
    groups.push_back(std::move(gr));
  }

  // The window's versions (the same for every voxel) and, per barrier, axis, destination brick
  // coordinate and offset component, which destination voxels stay in their source's cell.
  const HistoryWindow::Resolved any = step.window.resolve({0, 0, 0});
  const int nb = std::clamp(any.count, 0, 4);
  std::array<int, 4> order{0, 1, 2, 3};
  std::sort(order.begin(), order.begin() + nb,
            [&](int i, int j) { return any.barrier_version[size_t(i)] < any.barrier_version[size_t(j)]; });
  const int W = 2 * reach + 1;
  // incell[k][a][G * W + o + reach]
  std::vector<std::array<std::vector<uint8_t>, 3>> incell{size_t(nb)};
  for (int k = 0; k < nb; ++k)
    for (int a = 0; a < 3; ++a) {
      std::vector<uint8_t>& t = incell[size_t(k)][size_t(a)];
      t.assign(size_t(g.n[size_t(a)]) * size_t(W), 0);
      for (int G = 0; G < g.n[size_t(a)]; ++G)
        for (int oa = -reach; oa <= reach; ++oa) {
          uint8_t mask = 0;
          for (int tt = 0; tt < 8; ++tt) {
            const int q = (G - g.pad + g.first[size_t(a)]) * 8 + tt;  // destination coordinate
            const int p = q - oa;                                      // the reader's
            const HistoryWindow::Resolved r = step.window.resolve({p, p, p});
            const int lo = a == 0 ? r.lo[size_t(k)].x : a == 1 ? r.lo[size_t(k)].y : r.lo[size_t(k)].z;
            const int hi = a == 0 ? r.hi[size_t(k)].x : a == 1 ? r.hi[size_t(k)].y : r.hi[size_t(k)].z;
            if (q >= lo && q < hi) mask = uint8_t(mask | (1u << tt));
          }
          t[size_t(G) * size_t(W) + size_t(oa + reach)] = mask;
        }
    }
  std::array<std::vector<uint8_t>, 3> inbox;
  const std::array<int, 3> blo{dep.box.lo.x, dep.box.lo.y, dep.box.lo.z}, bhi{dep.box.hi.x, dep.box.hi.y, dep.box.hi.z};
  for (int a = 0; a < 3; ++a) {
    inbox[size_t(a)].assign(size_t(g.n[size_t(a)]), 0);
    for (int G = 0; G < g.n[size_t(a)]; ++G)
      for (int tt = 0; tt < 8; ++tt) {
        const int q = (G - g.pad + g.first[size_t(a)]) * 8 + tt;
        if (q >= blo[size_t(a)] && q < bhi[size_t(a)]) inbox[size_t(a)][size_t(G)] |= uint8_t(1u << tt);
      }
  }

  // Accumulator slots: 0 = latest, 1 + j = the j-th lowest barrier version, nb + 1 = carry.
  std::array<int, 6> slot_version{};
  slot_version[0] = any.latest;
  for (int j = 0; j < nb; ++j) slot_version[size_t(1 + j)] = any.barrier_version[size_t(order[size_t(j)])];
  slot_version[size_t(nb + 1)] = v - 1;

  std::atomic<bool> escaped{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, dests.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
    if (interrupter.poll()) return;
    std::vector<Bits> yz(widest);
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const auto [X, Y, Z] = dests[i];
      std::array<Bits, 6> acc{};
      for (const ShiftGroup& gr : groups) {
        uint64_t any_group = 0;
        for (int xb = gr.xb_lo; xb <= gr.xb_hi; ++xb)
          any_group |= gather_yz(src, g, X + xb, Y, Z, gr, yz[size_t(xb - gr.xb_lo)]);
        if (!any_group) continue;
        for (const size_t pi : gr.members) {
          const ShiftPlan& p = plans[pi];
          const Bits& lo = yz[size_t(p.brick[0] - gr.xb_lo)];
          const Bits& hi = yz[size_t(p.brick[0] - gr.xb_lo + 1)];
          const int rx = p.rest[0];
          Bits rem;
          uint64_t any_bit = 0;
          for (size_t w = 0; w < 8; ++w) {
            uint64_t bits = (lo[w] >> rx) & p.keep_lo;
            if (rx) bits |= (hi[w] << (8 - rx)) & p.keep_hi;
            rem[w] = bits;
            any_bit |= bits;
          }
          if (!any_bit) continue;
          for (int j = 0; j < nb; ++j) {
            const int k = order[size_t(j)];
            if (slot_version[size_t(1 + j)] >= any.latest) break;  // min() keeps the latest
            const auto& t = incell[size_t(k)];
            const Bits in = product_mask(t[0][size_t(X) * size_t(W) + size_t(p.o[0] + reach)],
                                         t[1][size_t(Y) * size_t(W) + size_t(p.o[1] + reach)],
                                         t[2][size_t(Z) * size_t(W) + size_t(p.o[2] + reach)]);
            for (size_t w = 0; w < 8; ++w) {
              acc[size_t(1 + j)][w] |= rem[w] & ~in[w];
              rem[w] &= in[w];
            }
          }
          for (size_t w = 0; w < 8; ++w) acc[0][w] |= rem[w];
        }
      }
      const int32_t ci = carry_of[g.at(X, Y, Z)];
      if (ci >= 0) acc[size_t(nb + 1)] = carries[size_t(ci)];
      const int cx = X - g.pad, cy = Y - g.pad, cz = Z - g.pad;
      const bool in_cover = cx >= 0 && cy >= 0 && cz >= 0 && cx < g.cover[0] && cy < g.cover[1] && cz < g.cover[2];
      const Bits box = product_mask(inbox[0][size_t(X)], inbox[1][size_t(Y)], inbox[2][size_t(Z)]);
      const size_t b = in_cover ? (size_t(cz) * size_t(g.cover[1]) + size_t(cy)) * size_t(g.cover[0]) + size_t(cx) : 0;
      for (int k = 0; k < nb + 2; ++k) {
        Bits& bits = acc[size_t(k)];
        for (size_t w = 0; w < 8; ++w) {
          if (bits[w] & ~box[w]) escaped = true;
          bits[w] &= box[w];
        }
        if (in_cover) dep.needed[size_t(slot_version[size_t(k)])].or_bits(b, bits);
      }
    }
  });
  if (interrupter.stopped()) return Status(StatusCode::kCancelled, "synthesis cancelled");
  if (escaped) return Status(StatusCode::kInternal, "dependency escaped its bounding box (stencil reach too small)");
  return updated;
}

// The distinct parents of a set's voxels, sorted, found brick by brick: a child brick covers one
// octant (4^3 voxels) of its parent's brick, each parent bit the OR of a 2^3 block of children.
std::vector<Voxel> parents_of(const VoxelMask& set, const VoxelBox& parent_box) {
  VoxelMask parents(parent_box);
  const BrickIndex& ci = set.index();
  Bits child;
  for (size_t b = 0; b < ci.size(); ++b) {
    if (!set.bits(b, child)) continue;
    const Voxel origin = ci.brick_origin(b);  // multiples of 8, so halving is exact
    const Voxel po{origin.x >> 1, origin.y >> 1, origin.z >> 1};
    const int ox = po.x & 7, oy = po.y & 7, oz = po.z & 7;  // 0 or 4
    Bits add{};
    for (int k = 0; k < 4; ++k) {
      uint64_t slice = child[size_t(2 * k)] | child[size_t(2 * k + 1)];
      slice |= slice >> 8;  // row 2j |= row 2j + 1
      slice |= slice >> 1;  // bit 2i |= bit 2i + 1
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
          if ((slice >> (16 * j + 2 * i)) & 1) add[size_t(oz + k)] |= uint64_t(1) << ((oy + j) * 8 + ox + i);
    }
    parents.or_bits(parents.index().brick_of(po), add);
  }
  std::vector<Voxel> out = parents.to_vector();
  std::sort(out.begin(), out.end());  // the order take_cached and the cache lookups have always seen
  return out;
}

}  // namespace

// Level boxes, finest first: a level's sets stay within its final-version box dilated by the
// number of steps times the reach; the parents of that box bound the coarser final version.
std::vector<VoxelBox> dependency_boxes(const std::vector<LevelSchedule>& schedules, const FrameStencils& stencils,
                                       const VoxelBox& target_bounds, PyramidLevel top) {
  const int L = stencils.levels();
  std::vector<VoxelBox> boxes(static_cast<size_t>(L));
  VoxelBox final_box = target_bounds;
  for (int l = top.index; l >= 0; --l) {
    const int radius = schedules[size_t(l)].final_version() * stencils.reach(PyramidLevel{l});
    boxes[size_t(l)] = final_box.dilated(radius);
    const VoxelBox& b = boxes[size_t(l)];
    final_box = {parent_of(b.lo), {floor_div(b.hi.x - 1, 2) + 1, floor_div(b.hi.y - 1, 2) + 1, floor_div(b.hi.z - 1, 2) + 1}};
  }
  return boxes;
}

Result<std::vector<LevelDependencies>> analyze_dependencies(const DependencyInputs& in, const TargetSet& target,
                                                            PyramidLevel top, LatchedInterrupter& interrupter) {
  const int L = in.stencils->levels();
  if (top.index < 0 || top.index >= L) return Status(StatusCode::kInternal, "target level outside the pyramid");
  const std::vector<VoxelBox> boxes = dependency_boxes(*in.schedules, *in.stencils, target.bounds(), top);
  std::vector<LevelDependencies> deps(static_cast<size_t>(L));
  std::vector<Voxel> final_need = target.voxels;
  for (int l = top.index; l >= 0; --l) {
    const LevelSchedule& sch = (*in.schedules)[size_t(l)];
    const int V = sch.final_version();
    LevelDependencies& dep = deps[size_t(l)];
    dep.box = boxes[size_t(l)];
    for (int v = 0; v <= V; ++v) dep.needed.emplace_back(dep.box);
    dep.needed_final = int64_t(final_need.size());
    take_cached(in.cache, PyramidLevel{l}, final_need, dep, dep.needed[size_t(V)]);
    for (int v = V; v >= 1; --v) {
      if (interrupter.poll()) return Status(StatusCode::kCancelled, "synthesis cancelled");
      const CorrectionStep& step = sch.steps()[size_t(v - 1)];
      // The brick path needs one offset list for the level and an update class that repeats
      // with every brick; anything else takes the per-voxel path.
      const bool by_brick = !in.per_voxel && in.stencils->constant() && 8 % step.updates.s == 0;
      ReadStencil st;
      FrameStencils::Offsets scratch;
      SOLIDTEX_ASSIGN_OR_RETURN(
          const int64_t updates,
          by_brick ? brick_step_back(in.stencils->offsets(PyramidLevel{l}, {0, 0, 0}, st, scratch), step, dep, v,
                                     interrupter)
                   : step_back(*in.stencils, PyramidLevel{l}, step, dep, v, interrupter));
      dep.corrections += updates;
    }
    if (l > 0) final_need = parents_of(dep.needed[0], boxes[size_t(l - 1)]);
  }
  return deps;
}

}  // namespace solidtex
