// History windows (Zhang §5.2) and the correction schedule built from them.
//
// Versions count *steps*, not passes: at level l, version 0 is the initialised/upsampled
// value and step i (1-based) produces version i. A step updates one class of voxels (all of
// them, or one of the s^3 subpass classes by position mod s); every other voxel carries
// version i-1 forward unchanged. So "the latest version" of any neighbour before step i is
// simply i-1, and the paper's subpass windows (Fig. 6a-c, written in per-pass versions)
// become the plain window H = i-1 here; what makes them subpasses is the update class.
//
// A window answers H(p, o): the version at which the correction of p reads neighbour p+o.
// Components combine by intersection, H = min(H1, H2) (§5.3.1):
//   latest            H = i-1 everywhere;
//   grid(M, off, b)   H = i-1 if p+o lies in p's cell of the lattice of M^3 cells whose
//                     corners sit at off + M*k on every axis, else the barrier version b.
// Dual-grid is grid with off = M/2 and b = the grid passes' final version.
// The dependency analysis (dependency.h) only ever asks windows and update classes; it holds
// nothing scheme-specific. Immutable; thread-safe.
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "synthesis/synthesis_params.h"
#include "core/types.h"

namespace solidtex {

struct CellLattice {
  int size = 12;
  int offset = 0;
  int cell_of(int c) const {
    const int r = c - offset;
    return r >= 0 ? r / size : -((-r + size - 1) / size);
  }
};

class HistoryWindow {
 public:
  // The window of step `step_version`: every neighbour at step_version - 1.
  static HistoryWindow latest(int step_version);
  // Barrier window: neighbours outside p's cell are read at `barrier_version`.
  static HistoryWindow grid(int step_version, CellLattice cells, int barrier_version);
  HistoryWindow intersect(const HistoryWindow& other) const;

  int version(const Voxel& p, int ox, int oy, int oz) const {
    int v = latest_;
    for (const Barrier& b : barriers_) {
      if (b.cells.cell_of(p.x) != b.cells.cell_of(p.x + ox) || b.cells.cell_of(p.y) != b.cells.cell_of(p.y + oy) ||
          b.cells.cell_of(p.z) != b.cells.cell_of(p.z + oz))
        v = std::min(v, b.version);
    }
    return v;
  }
  // The window of one voxel p with its cells resolved to bounds, so that per-neighbour
  // lookups are comparisons only: version_of(q) == version(p, q - p).
  struct Resolved {
    int latest = 0;
    int count = 0;
    std::array<int, 4> barrier_version{};
    std::array<Voxel, 4> lo{}, hi{};  // p's cell, half-open, per barrier (at most 4)
    int version_of(const Voxel& q) const {
      int v = latest;
      for (int b = 0; b < count; ++b)
        if (q.x < lo[size_t(b)].x || q.y < lo[size_t(b)].y || q.z < lo[size_t(b)].z || q.x >= hi[size_t(b)].x ||
            q.y >= hi[size_t(b)].y || q.z >= hi[size_t(b)].z)
          v = std::min(v, barrier_version[size_t(b)]);
      return v;
    }
  };
  Resolved resolve(const Voxel& p) const;

  // The D x D x D window of p as an array (x fastest), offsets -D/2..D/2: for inspection/tests.
  std::vector<int> materialize(const Voxel& p, int d) const;
  bool has_barrier() const { return !barriers_.empty(); }

 private:
  struct Barrier {
    CellLattice cells;
    int version;
  };
  int latest_ = 0;
  std::vector<Barrier> barriers_;
};

// Which voxels a step updates: all (s = 1) or those with (x mod s, y mod s, z mod s) == class.
struct UpdateClass {
  int s = 1;
  int index = 0;  // x%s + s*(y%s) + s*s*(z%s)
  static int class_of(const Voxel& p, int s) {
    if (s == 1) return 0;
    return (p.x & 1) + 2 * (p.y & 1) + 4 * (p.z & 1);
  }
  bool contains(const Voxel& p) const { return s == 1 || class_of(p, s) == index; }
};

struct CorrectionStep {
  int version = 1;  // the version this step produces
  UpdateClass updates;
  HistoryWindow window;
};

// The steps of one pyramid level, plus storage slots: a voxel's value at version v is its
// value after its slot(p, v)-th update (slot 0 = version 0).
class LevelSchedule {
 public:
  // Level `level` of a pyramid of `levels`: the coarsest runs plain passes, the finest uses
  // params.finest_subpass_size, the others params.subpass_size.
  static LevelSchedule make(int level, int levels, const SynthesisParams& params);
  const std::vector<CorrectionStep>& steps() const { return steps_; }
  int final_version() const { return int(steps_.size()); }
  int slot(const Voxel& p, int version) const {
    return slot_table_[size_t(UpdateClass::class_of(p, s_) * (final_version() + 1) + version)];
  }
  // slot(p, version) for any p of update class `cls` (UpdateClass::class_of(p, subpass_size())).
  int slot_of_class(int cls, int version) const { return slot_table_[size_t(cls * (final_version() + 1) + version)]; }
  int slot_count() const { return slot_count_; }  // max updates of any voxel + 1
  int subpass_size() const { return s_; }

 private:
  std::vector<CorrectionStep> steps_;
  int s_ = 1;
  int slot_count_ = 1;
  std::vector<int> slot_table_;  // [class * (final_version + 1) + version]
};

// The storage slot of every neighbour p + o of one voxel p, |o| <= kReach on each axis, for
// one step: slot(o) == schedule.slot(p + o, window.version_of(p + o)). Being outside a
// barrier's cell and the update class both decide axis by axis, so a lookup is three small
// table reads or-ed together and one read of the step's table; built once per corrected voxel.
class NeighbourSlots {
 public:
  static constexpr int kReach = 8;
  // The slot per (update class, outside-barrier mask) of one step. It depends on the window's
  // versions only, which are the same for every voxel of the step (resolve() moves the cells,
  // not the versions), so it is built once per step.
  struct StepTable {
    std::array<int, 128> slot{};  // by (class << 4) | outside-barrier mask
    static StepTable make(const LevelSchedule& schedule, const HistoryWindow::Resolved& window);
  };
  // `table` must be StepTable::make of the same step and outlive this object.
  NeighbourSlots(const StepTable& table, const LevelSchedule& schedule, const HistoryWindow::Resolved& window,
                 const Voxel& p);
  int slot(int dx, int dy, int dz) const {
    return table_->slot[size_t(axis_[0][size_t(dx + kReach)] | axis_[1][size_t(dy + kReach)] | axis_[2][size_t(dz + kReach)])];
  }

 private:
  // Per axis and offset: bit b (0-3) when outside barrier b's cell on that axis, bit 4 + axis
  // for the odd coordinate that makes up the update class.
  std::array<std::array<uint8_t, 2 * kReach + 1>, 3> axis_{};
  const StepTable* table_;
};

}  // namespace solidtex
