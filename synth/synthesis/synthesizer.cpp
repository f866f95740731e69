#include "synthesis/synthesizer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>

#include "synthesis/correction.h"
#include "synthesis/level_store.h"
#include "synthesis/pyramid_init.h"
#include "synthesis/voxel_mask.h"

namespace solidtex {

struct Synthesizer::Impl {
  std::vector<CorrectionContext> contexts;
  bool constant_field = false;
  Rot3 constant_rotation;
  std::vector<ReadStencil> constant_stencil;                              // per level
  std::vector<std::vector<std::array<int8_t, 3>>> constant_offsets;      // per level
  std::vector<int> reach;                                                 // per level, voxels per step
};

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Serialises interrupter calls from worker threads and latches cancellation.
class Poller {
 public:
  explicit Poller(Interrupter& i) : interrupter_(i) {}
  bool poll(int percent) {
    if (stop_.load(std::memory_order_relaxed)) return true;
    std::lock_guard<std::mutex> g(mutex_);
    if (interrupter_.was_interrupted(std::clamp(percent, 0, 100))) stop_ = true;
    return stop_;
  }
  bool stopped() const { return stop_.load(); }

 private:
  Interrupter& interrupter_;
  std::mutex mutex_;
  std::atomic<bool> stop_{false};
};

Voxel add(const Voxel& p, const std::array<int8_t, 3>& o) { return {p.x + o[0], p.y + o[1], p.z + o[2]}; }
Voxel parent_of(const Voxel& p) { return {floor_div(p.x, 2), floor_div(p.y, 2), floor_div(p.z, 2)}; }

// The frame of a voxel: at the finest level the field at its centre; at coarser levels the
// field is smoothed over the voxel's footprint (Zhang §6), as the sign-aligned, renormalised
// mean of 8 samples at +-1/4 of the voxel's size around the centre (log scales averaged too).
Rot3 smoothed_frame(const FrameField& field, const WorldPoint& c, int level, int levels) {
  if (level == levels - 1) return Rot3::from_quat(field.at(c), field.scale_at(c));
  const double r = 0.25 * double(stack_spacing(PyramidLevel{level}, levels));
  Quat acc{0, 0, 0, 0}, ref{};
  std::array<double, 3> log_scale{0, 0, 0};
  for (int k = 0; k < 8; ++k) {
    const WorldPoint q{c.x + ((k & 1) ? r : -r), c.y + ((k & 2) ? r : -r), c.z + ((k & 4) ? r : -r)};
    Quat f = field.at(q);
    if (k == 0) ref = f;
    if (f.dot(ref) < 0) f = {-f.w, -f.x, -f.y, -f.z};
    acc = {acc.w + f.w, acc.x + f.x, acc.y + f.y, acc.z + f.z};
    const auto sc = field.scale_at(q);
    for (int a = 0; a < 3; ++a) log_scale[size_t(a)] += std::log(sc[size_t(a)]) / 8;
  }
  return Rot3::from_quat(acc.normalized(), {std::exp(log_scale[0]), std::exp(log_scale[1]), std::exp(log_scale[2])});
}

const VoxelState& dummy_state() {
  static const VoxelState s{};
  return s;
}

}  // namespace

Result<std::shared_ptr<Synthesizer>> Synthesizer::create(std::shared_ptr<const Table> table,
                                                         std::shared_ptr<const FrameField> field,
                                                         const SynthesisParams& params, int64_t cache_bytes) {
  if (!table) return Status(StatusCode::kInvalidArgument, "no table", "table");
  if (!field) return Status(StatusCode::kInvalidArgument, "no field", "field");
  SOLIDTEX_RETURN_IF_ERROR(params.validate());
  if (cache_bytes < 0) return Status(StatusCode::kInvalidArgument, "must be >= 0", "cache_bytes");
  auto s = std::shared_ptr<Synthesizer>(new Synthesizer());
  s->table_ = std::move(table);
  s->field_ = std::move(field);
  s->params_ = params;
  const int L = s->table_->levels();
  s->cache_ = std::make_unique<VoxelCache>(L, cache_bytes);
  s->impl_ = std::make_shared<Impl>();
  const int n = s->table_->params().neighborhood;
  // A local offset of at most N/2 on two axes reaches N/2 * sqrt(2) * scale voxels.
  const int base_reach = int(std::ceil((n / 2) * std::sqrt(2.0) * s->field_->max_scale()));
  if (base_reach + 1 > 120) return Status(StatusCode::kInvalidArgument, "field scales reach too far", "field");
  s->impl_->constant_field = s->field_->is_constant();
  if (s->impl_->constant_field)
    s->impl_->constant_rotation = Rot3::from_quat(s->field_->at({0, 0, 0}), s->field_->scale_at({0, 0, 0}));
  for (int l = 0; l < L; ++l) {
    s->schedules_.push_back(LevelSchedule::make(l, params));
    s->impl_->contexts.push_back(CorrectionContext::make(*s->table_, PyramidLevel{l}, params.plane_weights,
                                                              params.matcher == Matcher::kCoherent));
    const bool trilinear = l < params.trilinear_levels;
    s->impl_->reach.push_back(base_reach + 1);
    ReadStencil st;
    std::vector<std::array<int8_t, 3>> offs;
    if (s->impl_->constant_field) {
      build_stencil(s->impl_->constant_rotation, n, trilinear, st);
      stencil_offsets(st, offs);
    }
    s->impl_->constant_stencil.push_back(std::move(st));
    s->impl_->constant_offsets.push_back(std::move(offs));
  }
  return s;
}

Result<std::vector<std::array<float, 3>>> Synthesizer::synthesize(const TargetSet& target, Interrupter& interrupter,
                                                                  SynthesisStats* stats_out,
                                                                  const SynthesisOptions& options) {
  const auto t_start = Clock::now();
  if (target.voxels.empty()) return Status(StatusCode::kInvalidArgument, "the request selects no voxels", "target");
  const Table& table = *table_;
  const Impl& impl = *impl_;
  const int L = table.levels();
  const int n = table.params().neighborhood;
  const int channels = table.exemplars().channels();
  SynthesisStats stats;
  stats.levels.resize(size_t(L));
  Poller poller(interrupter);
  interrupter.start("synthesize");

  auto rotation = [&](int l, const Voxel& p) {
    return impl.constant_field ? impl.constant_rotation
                               : smoothed_frame(*field_, voxel_centre(PyramidLevel{l}, L, p), l, L);
  };

  // Bounding boxes: a level's sets stay within its final-version box dilated by its reach.
  std::vector<VoxelBox> box0(static_cast<size_t>(L));
  VoxelBox final_box = target.bounds();
  for (int l = L - 1; l >= 0; --l) {
    const int radius = schedules_[size_t(l)].final_version() * impl.reach[size_t(l)];
    box0[size_t(l)] = final_box.dilated(radius);
    const VoxelBox& b = box0[size_t(l)];
    final_box = {parent_of(b.lo), {floor_div(b.hi.x - 1, 2) + 1, floor_div(b.hi.y - 1, 2) + 1, floor_div(b.hi.z - 1, 2) + 1}};
  }

  // ---- Backward: dependency sets per level and version. ----
  const auto t_dep = Clock::now();
  std::vector<std::vector<VoxelMask>> masks(static_cast<size_t>(L));
  std::vector<std::unique_ptr<LevelStore>> stores(static_cast<size_t>(L));
  std::vector<std::vector<Voxel>> cache_hits(static_cast<size_t>(L));
  std::vector<Voxel> final_need = target.voxels;
  for (int l = L - 1; l >= 0; --l) {
    const LevelSchedule& sch = schedules_[size_t(l)];
    const int V = sch.final_version();
    auto& m = masks[size_t(l)];
    m.clear();
    for (int v = 0; v <= V; ++v) m.emplace_back(box0[size_t(l)]);
    stores[size_t(l)] = std::make_unique<LevelStore>(box0[size_t(l)], sch.slot_count());
    LevelStore& store = *stores[size_t(l)];
    stats.levels[size_t(l)].level = l;
    stats.levels[size_t(l)].needed_final = int64_t(final_need.size());

    std::vector<CoordinateTriple> cached;
    std::vector<uint8_t> found(final_need.size(), 0);
    if (options.use_cache) cache_->lookup(PyramidLevel{l}, final_need, cached, found);
    for (size_t i = 0; i < final_need.size(); ++i) {
      const Voxel& p = final_need[i];
      if (found[i]) {
        store.allocate(p);
        VoxelState& s = store.at(p, sch.slot(p, V));
        s.triple = cached[i];
        matching_color(*impl.contexts[size_t(l)].level, s.triple, channels, impl.contexts[size_t(l)].color_weights, s.color.data());
        store.set_flag(p, sch.slot(p, V), LevelStore::kRequired);
        cache_hits[size_t(l)].push_back(p);
      } else {
        m[size_t(V)].insert(p);
      }
    }
    stats.levels[size_t(l)].cache_hits = int64_t(cache_hits[size_t(l)].size());

    const bool trilinear = l < params_.trilinear_levels;
    for (int v = V; v >= 1; --v) {
      if (poller.poll(-1)) return Status(StatusCode::kCancelled, "synthesis cancelled");
      const CorrectionStep& step = sch.steps()[size_t(v - 1)];
      const std::vector<Voxel> members = m[size_t(v)].to_vector();
      std::atomic<int64_t> updated{0};
      std::atomic<bool> escaped{false};
      // Set union is order-independent, so the parallel inserts give the same sets.
      tbb::parallel_for(tbb::blocked_range<size_t>(0, members.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
        ReadStencil stencil;
        std::vector<std::array<int8_t, 3>> offsets;
        int64_t local_updates = 0;
        for (size_t i = r.begin(); i != r.end(); ++i) {
          const Voxel& p = members[i];
          if (!step.updates.contains(p)) {
            m[size_t(v - 1)].insert(p);
            continue;
          }
          ++local_updates;
          const std::vector<std::array<int8_t, 3>>* offs = &impl.constant_offsets[size_t(l)];
          if (!impl.constant_field) {
            build_stencil(rotation(l, p), n, trilinear, stencil);
            stencil_offsets(stencil, offsets);
            offs = &offsets;
          }
          const HistoryWindow::Resolved window = step.window.resolve(p);
          for (const auto& o : *offs) {
            const Voxel q = add(p, o);
            if (!box0[size_t(l)].contains(q)) {
              escaped = true;
              continue;
            }
            m[size_t(window.version_of(q))].insert(q);
          }
        }
        updated += local_updates;
      });
      if (escaped) return Status(StatusCode::kInternal, "dependency escaped its bounding box (stencil reach too small)");
      stats.levels[size_t(l)].corrections += updated;
    }
    stats.levels[size_t(l)].voxels = m[0].count();
    if (l > 0) {
      std::vector<Voxel> parents;
      parents.reserve(size_t(m[0].count()) / 4 + 1);
      for (const Voxel& p : m[0].to_vector()) parents.push_back(parent_of(p));
      std::sort(parents.begin(), parents.end());
      parents.erase(std::unique(parents.begin(), parents.end()), parents.end());
      final_need = std::move(parents);
    }
  }
  stats.dependency_seconds = since(t_dep);
  auto finish = [&]() {
    interrupter.end();
    for (const LevelStats& ls : stats.levels) {
      stats.voxels += ls.voxels;
      stats.corrections += ls.corrections;
    }
    stats.seconds = since(t_start);
  };
  if (options.dependencies_only) {
    finish();
    if (stats_out) *stats_out = std::move(stats);
    return std::vector<std::array<float, 3>>{};
  }

  // ---- Forward: synthesize inside the sets, coarsest level first. ----
  std::atomic<int64_t> unsound{0};
  int64_t unread = 0;
  auto check_tightness = [&](int l) {
    if (!options.instrument) return;
    const LevelSchedule& sch = schedules_[size_t(l)];
    LevelStore& store = *stores[size_t(l)];
    for (int v = 0; v <= sch.final_version(); ++v)
      for (const Voxel& p : masks[size_t(l)][size_t(v)].to_vector())
        if (!(store.flags(p, sch.slot(p, v)) & LevelStore::kRead)) ++unread;
    for (const Voxel& p : cache_hits[size_t(l)])
      if (!(store.flags(p, sch.slot(p, sch.final_version())) & LevelStore::kRead)) ++unread;
  };

  for (int l = 0; l < L; ++l) {
    const auto t_level = Clock::now();
    const LevelSchedule& sch = schedules_[size_t(l)];
    const int V = sch.final_version();
    LevelStore& store = *stores[size_t(l)];
    const CorrectionContext& ctx = impl.contexts[size_t(l)];
    const std::vector<Voxel> level_voxels = masks[size_t(l)][0].to_vector();
    for (const Voxel& p : level_voxels) store.allocate(p);
    if (options.instrument)
      for (int v = 0; v <= V; ++v)
        for (const Voxel& p : masks[size_t(l)][size_t(v)].to_vector())
          store.set_flag(p, sch.slot(p, v), LevelStore::kRequired);

    // Version 0.
    LevelStore* parent_store = l > 0 ? stores[size_t(l - 1)].get() : nullptr;
    const LevelSchedule* parent_sch = l > 0 ? &schedules_[size_t(l - 1)] : nullptr;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, level_voxels.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const Voxel& p = level_voxels[i];
        VoxelState& s = store.at(p, 0);
        if (l == 0) {
          s.triple = init_triple(table, p, rotation(0, p), params_);
        } else {
          const Voxel P = parent_of(p);
          const int pslot = parent_sch->slot(P, parent_sch->final_version());
          if (options.instrument) {
            if (!(parent_store->flags(P, pslot) & LevelStore::kRequired)) {
              ++unsound;
              continue;
            }
            parent_store->set_flag(P, pslot, LevelStore::kRead);
          }
          s.triple = upsample_triple(table, PyramidLevel{l}, p, parent_store->at(P, pslot).triple, rotation(l - 1, P));
        }
        matching_color(*ctx.level, s.triple, channels, ctx.color_weights, s.color.data());
      }
    });
    if (l > 0) {
      check_tightness(l - 1);
      stores[size_t(l - 1)].reset();
    }

    // Correction steps.
    const bool trilinear = l < params_.trilinear_levels;
    for (int v = 1; v <= V; ++v) {
      const int percent = int(100.0 * (l + double(v) / (V + 1)) / L);
      if (poller.poll(percent)) return Status(StatusCode::kCancelled, "synthesis cancelled");
      const CorrectionStep& step = sch.steps()[size_t(v - 1)];
      std::vector<Voxel> updates;
      for (const Voxel& p : masks[size_t(l)][size_t(v)].to_vector())
        if (step.updates.contains(p)) updates.push_back(p);
      tbb::parallel_for(tbb::blocked_range<size_t>(0, updates.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        CorrectionScratch scratch;
        ReadStencil local;
        for (size_t i = r.begin(); i != r.end(); ++i) {
          const Voxel& p = updates[i];
          const ReadStencil* st = &impl.constant_stencil[size_t(l)];
          if (!impl.constant_field) {
            build_stencil(rotation(l, p), n, trilinear, local);
            st = &local;
          }
          const HistoryWindow::Resolved window = step.window.resolve(p);
          const LevelStore::Neighborhood near(store, p);
          auto read = [&](int dx, int dy, int dz) -> const VoxelState& {
            const Voxel q{p.x + dx, p.y + dy, p.z + dz};
            const int slot = sch.slot(q, window.version_of(q));
            if (options.instrument) {
              if (!store.has(q) || !(store.flags(q, slot) & LevelStore::kRequired)) {
                ++unsound;
                return dummy_state();
              }
              store.set_flag(q, slot, LevelStore::kRead);
            }
            return near.at(dx, dy, dz, slot);
          };
          VoxelState& out = store.at(p, sch.slot(p, v));
          out.triple = correct_voxel(ctx, *st, read, scratch);
          matching_color(*ctx.level, out.triple, channels, ctx.color_weights, out.color.data());
        }
      });
    }

    if (options.use_cache) {
      std::vector<Voxel> finals = masks[size_t(l)][size_t(V)].to_vector();
      std::vector<CoordinateTriple> triples;
      triples.reserve(finals.size());
      for (const Voxel& p : finals) triples.push_back(store.at(p, sch.slot(p, V)).triple);
      cache_->insert(PyramidLevel{l}, finals, triples);
    }
    stats.store_bytes = std::max(stats.store_bytes, store.bytes() + (parent_store ? 0 : 0));
    stats.levels[size_t(l)].seconds = since(t_level);
  }

  // Output colors.
  const int fl = L - 1;
  const LevelSchedule& fsch = schedules_[size_t(fl)];
  LevelStore& fstore = *stores[size_t(fl)];
  std::vector<std::array<float, 3>> voxel_rgb(target.voxels.size());
  for (size_t i = 0; i < target.voxels.size(); ++i) {
    const Voxel& p = target.voxels[i];
    const int slot = fsch.slot(p, fsch.final_version());
    if (options.instrument) fstore.set_flag(p, slot, LevelStore::kRead);
    output_color(table, fstore.at(p, slot).triple, impl.contexts[size_t(fl)].color_weights, voxel_rgb[i].data());
  }
  check_tightness(fl);
  std::vector<std::array<float, 3>> out(target.sample.size());
  for (size_t i = 0; i < target.sample.size(); ++i) out[i] = voxel_rgb[target.sample[i]];

  stats.unsound_reads = unsound.load();
  stats.unread_required = unread;
  finish();
  if (stats_out) *stats_out = std::move(stats);
  return out;
}

}  // namespace solidtex
