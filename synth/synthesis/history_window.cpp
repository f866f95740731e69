#include "synthesis/history_window.h"

#include <algorithm>

namespace solidtex {

HistoryWindow HistoryWindow::latest(int step_version) {
  HistoryWindow w;
  w.latest_ = step_version - 1;
  return w;
}

HistoryWindow HistoryWindow::grid(int step_version, CellLattice cells, int barrier_version) {
  HistoryWindow w = latest(step_version);
  w.barriers_.push_back({cells, barrier_version});
  return w;
}

HistoryWindow HistoryWindow::intersect(const HistoryWindow& other) const {
  // resolve() supports up to four barrier components; the schedules use at most one.
  HistoryWindow w;
  w.latest_ = std::min(latest_, other.latest_);
  w.barriers_ = barriers_;
  w.barriers_.insert(w.barriers_.end(), other.barriers_.begin(), other.barriers_.end());
  return w;
}

HistoryWindow::Resolved HistoryWindow::resolve(const Voxel& p) const {
  Resolved r;
  r.latest = latest_;
  for (const Barrier& b : barriers_) {
    const int s = b.cells.size;
    const Voxel lo{b.cells.cell_of(p.x) * s + b.cells.offset, b.cells.cell_of(p.y) * s + b.cells.offset,
                   b.cells.cell_of(p.z) * s + b.cells.offset};
    r.lo[size_t(r.count)] = lo;
    r.hi[size_t(r.count)] = {lo.x + s, lo.y + s, lo.z + s};
    r.barrier_version[size_t(r.count)] = b.version;
    ++r.count;
  }
  return r;
}

NeighbourSlots::StepTable NeighbourSlots::StepTable::make(const LevelSchedule& schedule,
                                                         const HistoryWindow::Resolved& window) {
  StepTable t;
  const int s = schedule.subpass_size();
  for (int m = 0; m < 128; ++m) {
    if (s == 1 && m >= 16) break;  // one update class: the parity bits are never set
    int v = window.latest;
    for (int b = 0; b < window.count; ++b)
      if (m & (1 << b)) v = std::min(v, window.barrier_version[size_t(b)]);
    t.slot[size_t(m)] = schedule.slot_of_class(m >> 4, v);
  }
  return t;
}

NeighbourSlots::NeighbourSlots(const StepTable& table, const LevelSchedule& schedule,
                               const HistoryWindow::Resolved& window, const Voxel& p)
    : table_(&table) {
  const int s = schedule.subpass_size();
  const int centre[3] = {p.x, p.y, p.z};
  for (int a = 0; a < 3; ++a)
    for (int o = -kReach; o <= kReach; ++o) {
      const int c = centre[a] + o;
      uint8_t bits = s == 1 ? 0 : uint8_t((c & 1) << (4 + a));
      for (int b = 0; b < window.count; ++b) {
        const int lo[3] = {window.lo[size_t(b)].x, window.lo[size_t(b)].y, window.lo[size_t(b)].z};
        const int hi[3] = {window.hi[size_t(b)].x, window.hi[size_t(b)].y, window.hi[size_t(b)].z};
        if (c < lo[a] || c >= hi[a]) bits |= uint8_t(1 << b);
      }
      axis_[size_t(a)][size_t(o + kReach)] = bits;
    }
}

std::vector<int> HistoryWindow::materialize(const Voxel& p, int d) const {
  std::vector<int> out;
  out.reserve(size_t(d) * d * d);
  const int h = d / 2;
  for (int z = -h; z < d - h; ++z)
    for (int y = -h; y < d - h; ++y)
      for (int x = -h; x < d - h; ++x) out.push_back(version(p, x, y, z));
  return out;
}

LevelSchedule LevelSchedule::make(int level, int levels, const SynthesisParams& params) {
  LevelSchedule s;
  const bool coarsest = level == 0;
  const int passes = coarsest ? params.coarse_passes : params.passes;
  const bool plain = coarsest || params.scheme == Scheme::kPlain;
  s.s_ = plain ? 1 : level == levels - 1 ? params.finest_subpass_size : params.subpass_size;
  const int classes = s.s_ == 1 ? 1 : 8;
  const CellLattice primary{params.cell_size, 0};
  const CellLattice dual{params.cell_size, params.cell_size / 2};
  const int grid_passes = params.scheme == Scheme::kDualGrid ? (passes + 1) / 2 : passes;
  int version = 0;
  int barrier = 0;  // version the current barrier group started from
  for (int pass = 0; pass < passes; ++pass) {
    const bool use_dual = !plain && params.scheme == Scheme::kDualGrid && pass >= grid_passes;
    if (use_dual && pass == grid_passes) barrier = version;  // dual reads the grid passes' result
    for (int c = 0; c < classes; ++c) {
      CorrectionStep step;
      step.version = ++version;
      step.updates = {s.s_, c};
      step.window = HistoryWindow::latest(step.version);
      if (!plain && (params.scheme == Scheme::kGrid || params.scheme == Scheme::kDualGrid))
        step.window = step.window.intersect(HistoryWindow::grid(step.version, use_dual ? dual : primary, barrier));
      s.steps_.push_back(step);
    }
  }
  s.slot_table_.assign(size_t(classes) * (size_t(version) + 1), 0);
  for (int c = 0; c < classes; ++c) {
    int count = 0;
    for (int v = 1; v <= version; ++v) {
      if (s.steps_[size_t(v - 1)].updates.s == 1 || s.steps_[size_t(v - 1)].updates.index == c) ++count;
      s.slot_table_[size_t(c) * (size_t(version) + 1) + size_t(v)] = count;
    }
    s.slot_count_ = std::max(s.slot_count_, count + 1);
  }
  return s;
}

}  // namespace solidtex
