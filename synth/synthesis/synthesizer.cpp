#include "synthesis/synthesizer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <numeric>
#include <string>
#include <type_traits>

#include "synthesis/correction.h"
#include "synthesis/cost_model.h"
#include "synthesis/dependency.h"
#include "synthesis/frame_stencils.h"
#include "synthesis/level_store.h"
#include "synthesis/patch_vote.h"
#include "synthesis/pyramid_init.h"

namespace solidtex {

struct Synthesizer::Impl {
  std::vector<CorrectionContext> contexts;  // per level
  FrameStencils stencils;
  // Per level, measured at the first estimate (cost_model.h); shared between synthesizers
  // whose schedule, stencils and constant field agree, since it depends on nothing else.
  std::mutex spread_mutex;
  std::vector<int> spread;  // empty until measured
};

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

const VoxelState& dummy_state() {
  static const VoxelState s{};
  return s;
}

// Instrumented mode: every (voxel, slot) of the sets is flagged required before a level runs;
// every read flags it read. A read of an unflagged pair is unsound (the sets missed a
// dependency); a required pair never read is a tightness failure (the sets hold too much).
class SetChecks {
 public:
  explicit SetChecks(bool on) : on_(on) {}
  bool on() const { return on_; }

  void mark_required(const LevelSchedule& sch, const LevelDependencies& dep, LevelStore& store) const {
    if (!on_) return;
    const int V = sch.final_version();
    for (const Voxel& p : dep.cache_hits) store.set_flag(p, sch.slot(p, V), LevelStore::kRequired);
    for (int v = 0; v <= V; ++v)
      for (const Voxel& p : dep.needed[size_t(v)].to_vector()) store.set_flag(p, sch.slot(p, v), LevelStore::kRequired);
  }
  // Records a read of (q, slot); false (and counted) when the sets do not hold it.
  bool read(LevelStore& store, const Voxel& q, int slot) {
    if (!on_) return true;
    if (!(store.flags(q, slot) & LevelStore::kRequired)) {
      ++unsound_;
      return false;
    }
    store.set_flag(q, slot, LevelStore::kRead);
    return true;
  }
  void count_unread(const LevelSchedule& sch, const LevelDependencies& dep, const LevelStore& store) {
    if (!on_) return;
    const int V = sch.final_version();
    for (int v = 0; v <= V; ++v)
      for (const Voxel& p : dep.needed[size_t(v)].to_vector())
        if (!(store.flags(p, sch.slot(p, v)) & LevelStore::kRead)) ++unread_;
    for (const Voxel& p : dep.cache_hits)
      if (!(store.flags(p, sch.slot(p, V)) & LevelStore::kRead)) ++unread_;
  }
  int64_t unsound() const { return unsound_.load(); }
  int64_t unread() const { return unread_; }

 private:
  bool on_;
  std::atomic<int64_t> unsound_{0};
  int64_t unread_ = 0;
};

// What a correction reads (correction.h's reader): neighbours' colors and triples at the slots
// the step's window names, through the 27 cached bricks when the stencil reaches no further.
// A read outside the sets is a dependency-analysis bug: it is flagged and reads a dummy state,
// never memory outside the store.
struct StoreReader {
  LevelStore& store;  // non-const for the instrumented mode's read flags
  const LevelSchedule& sch;
  const HistoryWindow::Resolved& window;
  const LevelStore::Neighborhood& near;
  const NeighbourSlots& slots;
  const Voxel p;
  const bool near_reaches;
  SetChecks& checks;
  std::atomic<bool>& outside_store;

  const StateColor& color(int dx, int dy, int dz) const { return read<StateColor>(dx, dy, dz); }
  const CoordinateTriple& triple(int dx, int dy, int dz) const { return read<CoordinateTriple>(dx, dy, dz); }

 private:
  template <class T>
  const T& read(int dx, int dy, int dz) const {
    const Voxel q{p.x + dx, p.y + dy, p.z + dz};
    const int slot = near_reaches ? slots.slot(dx, dy, dz) : sch.slot(q, window.version_of(q));
    const T* v = nullptr;
    if (checks.read(store, q, slot)) {
      if constexpr (std::is_same_v<T, StateColor>)
        v = near_reaches ? near.color(dx, dy, dz, slot) : (store.has(q) ? &store.color(q, slot) : nullptr);
      else
        v = near_reaches ? near.triple(dx, dy, dz, slot) : (store.has(q) ? &store.triple(q, slot) : nullptr);
      if (!v) outside_store = true;
    }
    if (v) return *v;
    if constexpr (std::is_same_v<T, StateColor>)
      return dummy_state().color;
    else
      return dummy_state().triple;
  }
};

// Targets whose voxels lie farther apart than this (finest voxels, 26-connected cells) are
// synthesized piece by piece: one piece's dependency sets never span the gap between them.
constexpr int kPieceCell = 256;

TargetSet piece_target(const TargetSet& target, const std::vector<uint32_t>& piece) {
  std::vector<Voxel> voxels;
  voxels.reserve(piece.size());
  for (uint32_t i : piece) voxels.push_back(target.voxels[i]);
  return TargetSet::from_voxels(voxels, int(voxels.size()), 1);
}

Status too_much_memory(int64_t bytes, int64_t limit, const std::string& field) {
  return Status(StatusCode::kUnprocessable,
                "this request needs up to " + std::to_string(bytes >> 20) + " MB of working memory; the limit is " +
                    std::to_string(limit >> 20) + " MB (ask for a smaller or thinner cut or box, or closer points)",
                field);
}

void add_stats(SynthesisStats& into, const SynthesisStats& piece) {
  for (size_t l = 0; l < into.levels.size(); ++l) {
    LevelStats& a = into.levels[l];
    const LevelStats& b = piece.levels[l];
    a.level = b.level;
    a.voxels += b.voxels;
    a.corrections += b.corrections;
    a.cache_hits += b.cache_hits;
    a.needed_final += b.needed_final;
    a.seconds += b.seconds;
  }
  into.dependency_seconds += piece.dependency_seconds;
  into.support_voxels += piece.support_voxels;
  into.store_bytes = std::max(into.store_bytes, piece.store_bytes);
  into.estimated_bytes = std::max(into.estimated_bytes, piece.estimated_bytes);
  into.unsound_reads += piece.unsound_reads;
  into.unread_required += piece.unread_required;
}

// Everything one level's forward pass reads.
struct LevelPass {
  PyramidLevel level;
  const Table& table;
  const SynthesisParams& params;
  const LevelSchedule& schedule;
  const CorrectionContext& ctx;
  const FrameStencils& frames;
};

// A level's store: every voxel of its version-0 set and every cache hit, the hits' final
// values filled in from the cache.
std::unique_ptr<LevelStore> make_level_store(const LevelPass& pass, const LevelDependencies& dep) {
  const LevelSchedule& sch = pass.schedule;
  const CorrectionContext& ctx = pass.ctx;
  auto store = std::make_unique<LevelStore>(dep.box, sch.slot_count());
  for (const Voxel& p : dep.needed[0].to_vector()) store->allocate(p);
  for (size_t i = 0; i < dep.cache_hits.size(); ++i) {
    const Voxel& p = dep.cache_hits[i];
    store->allocate(p);
    const int slot = sch.slot(p, sch.final_version());
    store->triple(p, slot) = dep.cached[i];
    matching_color(*ctx.level, dep.cached[i], ctx.channels, ctx.color_weights, store->color(p, slot).data());
  }
  return store;
}

// Version 0 of every voxel of the level's version-0 set: initialisation at the coarsest level,
// upsampling from the parent's final version elsewhere (pyramid_init.h).
Status initialise_level(const LevelPass& pass, const LevelDependencies& dep, LevelStore& store,
                      const LevelSchedule* parent_sch, LevelStore* parent_store, SetChecks& checks) {
  const PyramidLevel l = pass.level;
  const CorrectionContext& ctx = pass.ctx;
  const FrameStencils& frames = pass.frames;
  const std::vector<Voxel> voxels = dep.needed[0].to_vector();
  std::atomic<bool> missing_parent{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, voxels.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const Voxel& p = voxels[i];
      CoordinateTriple& triple = store.triple(p, 0);
      if (l.index == 0) {
        triple = init_triple(pass.table, p, frames.rotation(l, p), pass.params);
      } else {
        const Voxel P = parent_of(p);
        const PyramidLevel pl{l.index - 1};
        const int pslot = parent_sch->slot(P, parent_sch->final_version());
        if (!checks.read(*parent_store, P, pslot)) continue;
        if (!parent_store->has(P)) {
          missing_parent = true;
          continue;
        }
        triple = upsample_triple(pass.table, l, p, parent_store->triple(P, pslot), frames.rotation(pl, P));
      }
      matching_color(*ctx.level, triple, ctx.channels, ctx.color_weights, store.color(p, 0).data());
    }
  });
  if (missing_parent) return Status(StatusCode::kInternal, "an upsampled voxel's parent is outside the coarser level's sets");
  return Status::ok();
}

// The level's correction steps, each on exactly the voxels of its set that it updates.
Status correct_level(const LevelPass& pass, const LevelDependencies& dep, LevelStore& store, SetChecks& checks,
                     LatchedInterrupter& poller) {
  const PyramidLevel l = pass.level;
  const LevelSchedule& sch = pass.schedule;
  const CorrectionContext& ctx = pass.ctx;
  const FrameStencils& frames = pass.frames;
  const int V = sch.final_version();
  const int L = pass.table.levels();
  // Stretched fields (scales > ~1.4 at N = 9) reach past the 27 bricks Neighborhood caches.
  const bool near_reaches = frames.reach(l) <= LevelStore::Neighborhood::kReach && frames.reach(l) <= NeighbourSlots::kReach;
  for (int v = 1; v <= V; ++v) {
    const int percent = int(100.0 * (l.index + double(v) / (V + 1)) / L);
    if (poller.poll(percent)) return Status(StatusCode::kCancelled, "synthesis cancelled");
    const CorrectionStep& step = sch.steps()[size_t(v - 1)];
    std::atomic<bool> outside_store{false};
    const NeighbourSlots::StepTable slot_table = NeighbourSlots::StepTable::make(sch, step.window.resolve(Voxel{}));
    std::vector<Voxel> updates;
    for (const Voxel& p : dep.needed[size_t(v)].to_vector())
      if (step.updates.contains(p)) updates.push_back(p);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, updates.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
      if (poller.poll(percent)) return;  // a step can take seconds: deadlines hold inside it
      CorrectionScratch scratch;
      ReadStencil local;
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const Voxel& p = updates[i];
        const ReadStencil& st = frames.stencil(l, p, local);
        const HistoryWindow::Resolved window = step.window.resolve(p);
        const LevelStore::Neighborhood near(store, p);
        const NeighbourSlots slots(slot_table, sch, window, p);
        StoreReader read{store, sch, window, near, slots, p, near_reaches, checks, outside_store};
        const int out = sch.slot(p, v);
        const CoordinateTriple t = correct_voxel(ctx, st, read, scratch);
        store.triple(p, out) = t;
        matching_color(*ctx.level, t, ctx.channels, ctx.color_weights, store.color(p, out).data());
      }
    });
    if (poller.stopped()) return Status(StatusCode::kCancelled, "synthesis cancelled");
    if (outside_store)
      return Status(StatusCode::kInternal, "a correction read a voxel outside the level's dependency sets");
  }
  return Status::ok();
}

// Final versions go to the cache; by purity any later request would compute the same values.
// Not only the sets' final versions: a voxel that no step after v updates (its slot at v is its
// final slot) holds its final value in needed[v] already. With one correction pass that is every
// voxel a correction produced, so a cut leaves voxels around it final in the cache. (Which
// ones follows the subpass order: a z cut's corrections run before the odd-z classes, so the
// cut at z + 2 finds most of itself, the cut at z + 1 only its coarser levels.)
void write_back(const LevelPass& pass, const LevelDependencies& dep, const LevelStore& store, VoxelCache& cache) {
  const LevelSchedule& sch = pass.schedule;
  const int V = sch.final_version();
  VoxelMask taken(dep.box);
  std::vector<Voxel> finals;
  std::vector<CoordinateTriple> triples;
  for (int v = V; v >= 0; --v)
    for (const Voxel& p : dep.needed[size_t(v)].to_vector()) {
      const int slot = sch.slot(p, v);
      if (slot != sch.slot(p, V) || !taken.insert(p)) continue;
      finals.push_back(p);
      triples.push_back(store.triple(p, slot));
    }
  cache.insert(pass.level, finals, triples);
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
  SOLIDTEX_ASSIGN_OR_RETURN(s->impl_->stencils, FrameStencils::make(*s->field_, s->table_->params().neighborhood, L,
                                                                    params.trilinear_levels));
  for (int l = 0; l < L; ++l) {
    s->schedules_.push_back(LevelSchedule::make(l, L, params));
    s->impl_->contexts.push_back(CorrectionContext::make(*s->table_, PyramidLevel{l}, params));
  }
  return s;
}

Result<std::vector<int>> Synthesizer::spread(LatchedInterrupter& interrupter) const {
  static std::mutex memo_mutex;
  static std::map<std::string, std::vector<int>> memo;
  std::lock_guard<std::mutex> g(impl_->spread_mutex);
  if (!impl_->spread.empty()) return impl_->spread;
  std::string key;
  if (impl_->stencils.constant()) {
    const SynthesisParams& p = params_;
    key = std::string(scheme_name(p.scheme)) + "/" + std::to_string(p.coarse_passes) + "/" + std::to_string(p.passes) +
          "/" + std::to_string(p.subpass_size) + "/" + std::to_string(p.finest_subpass_size) + "/" + std::to_string(p.cell_size) + "/" +
          std::to_string(p.trilinear_levels) + "/" + std::to_string(table_->params().neighborhood) + "/" +
          std::to_string(table_->levels()) + "/" + field_->describe();
    std::lock_guard<std::mutex> m(memo_mutex);
    if (auto it = memo.find(key); it != memo.end()) return impl_->spread = it->second;
  }
  SOLIDTEX_ASSIGN_OR_RETURN(impl_->spread, measure_spread(schedules_, impl_->stencils, interrupter));
  if (!key.empty()) {
    std::lock_guard<std::mutex> m(memo_mutex);
    memo.emplace(key, impl_->spread);
  }
  return impl_->spread;
}

int Synthesizer::support_reach(PyramidLevel top) const {
  return impl_->contexts[size_t(top.index)].color_rule == ColorRule::kVote ? impl_->stencils.candidate_reach() : 0;
}

TargetSet Synthesizer::color_support(const TargetSet& target, PyramidLevel top) const {
  if (impl_->contexts[size_t(top.index)].color_rule != ColorRule::kVote) return target;
  // vote_support is sorted and distinct already: sample i is voxel i (from_voxels would sort
  // and search it again).
  TargetSet support;
  support.voxels = vote_support(target.voxels, impl_->stencils, top);
  support.width = int(support.voxels.size());
  support.height = 1;
  support.sample.resize(support.voxels.size());
  std::iota(support.sample.begin(), support.sample.end(), 0u);
  return support;
}

Result<RequestCost> Synthesizer::estimate(const TargetSet& target, Interrupter& interrupter) const {
  LatchedInterrupter poller(interrupter);
  SOLIDTEX_ASSIGN_OR_RETURN(const std::vector<int> spread, this->spread(poller));
  const auto pieces = split_target(target, kPieceCell);
  const PyramidLevel finest{table_->levels() - 1};
  const int reach = support_reach(finest);
  if (pieces.size() == 1) return estimate_cost(schedules_, impl_->stencils, spread, target, reach);
  RequestCost worst;
  for (const auto& piece : pieces) {
    RequestCost c = estimate_cost(schedules_, impl_->stencils, spread, piece_target(target, piece), reach);
    if (c.bytes > worst.bytes) worst = std::move(c);
  }
  return worst;
}

Result<std::vector<std::array<float, 3>>> Synthesizer::synthesize_piece(const TargetSet& target,
                                                                        LatchedInterrupter& poller, SynthesisStats& stats,
                                                                        const SynthesisOptions& options) {
  const int L = table_->levels();
  const PyramidLevel top{options.level < 0 ? L - 1 : options.level};
  if (options.max_bytes > 0) {
    // The estimate treats the target as finest voxels: an upper bound for coarser targets.
    SOLIDTEX_ASSIGN_OR_RETURN(const std::vector<int> spread, this->spread(poller));
    const RequestCost cost = estimate_cost(schedules_, impl_->stencils, spread, target, support_reach(top));
    stats.estimated_bytes = cost.bytes;
    if (cost.bytes > options.max_bytes) return too_much_memory(cost.bytes, options.max_bytes, options.target_field);
  }
  // Listed only once the estimate allows it: a vote support holds up to 27x the target.
  const TargetSet synthesized = color_support(target, top);
  stats.support_voxels = int64_t(synthesized.voxels.size());

  // Backwards: what the target depends on.
  const auto t_dep = Clock::now();
  const DependencyInputs inputs{&schedules_, &impl_->stencils, options.use_cache ? cache_.get() : nullptr};
  SOLIDTEX_ASSIGN_OR_RETURN(const std::vector<LevelDependencies> deps, analyze_dependencies(inputs, synthesized, top, poller));
  for (int l = 0; l <= top.index; ++l) {
    LevelStats& ls = stats.levels[size_t(l)];
    ls.level = l;
    ls.needed_final = deps[size_t(l)].needed_final;
    ls.cache_hits = int64_t(deps[size_t(l)].cache_hits.size());
    ls.corrections = deps[size_t(l)].corrections;
    ls.voxels = deps[size_t(l)].needed[0].count();
  }
  stats.dependency_seconds = since(t_dep);
  if (options.dependencies_only) return std::vector<std::array<float, 3>>{};
  if (options.max_bytes > 0) {
    const int64_t bytes = store_bytes(schedules_, deps);
    if (bytes > options.max_bytes) return too_much_memory(bytes, options.max_bytes, options.target_field);
  }

  // Forwards, coarsest level first, inside the sets.
  SetChecks checks(options.instrument);
  std::unique_ptr<LevelStore> parent;
  for (int l = 0; l <= top.index; ++l) {
    const auto t_level = Clock::now();
    const PyramidLevel level{l};
    const LevelDependencies& dep = deps[size_t(l)];
    const LevelPass pass{level, *table_, params_, schedules_[size_t(l)], impl_->contexts[size_t(l)], impl_->stencils};
    std::unique_ptr<LevelStore> store = make_level_store(pass, dep);
    checks.mark_required(pass.schedule, dep, *store);
    SOLIDTEX_RETURN_IF_ERROR(
        initialise_level(pass, dep, *store, l > 0 ? &schedules_[size_t(l - 1)] : nullptr, parent.get(), checks));
    if (parent) checks.count_unread(schedules_[size_t(l - 1)], deps[size_t(l - 1)], *parent);
    parent.reset();
    SOLIDTEX_RETURN_IF_ERROR(correct_level(pass, dep, *store, checks, poller));
    if (options.use_cache) write_back(pass, dep, *store, *cache_);
    stats.store_bytes = std::max(stats.store_bytes, store->bytes());
    stats.levels[size_t(l)].seconds = since(t_level);
    parent = std::move(store);
  }

  // Output colors of the target level's final versions (votes read the support around them).
  const LevelSchedule& fsch = schedules_[size_t(top.index)];
  const CorrectionContext& fctx = impl_->contexts[size_t(top.index)];
  std::vector<std::array<float, 3>> voxel_rgb(target.voxels.size());
  std::atomic<bool> outside{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, target.voxels.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    ReadStencil local;
    auto final_triple = [&](const Voxel& q) -> CoordinateTriple {
      const int slot = fsch.slot(q, fsch.final_version());
      if (!checks.read(*parent, q, slot) || !parent->has(q)) {
        outside = true;
        return {};
      }
      return parent->triple(q, slot);
    };
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const Voxel& p = target.voxels[i];
      const CoordinateTriple own = final_triple(p);
      if (fctx.color_rule != ColorRule::kVote) {
        output_color(*table_, own, fctx.color_weights, fctx.color_rule, voxel_rgb[i].data());
        continue;
      }
      const ReadStencil& st = impl_->stencils.stencil(top, p, local);
      VoteSources sources;
      for (int k = 0; k < 3; ++k)
        for (int ab = 0; ab < 9; ++ab) {
          const auto& o = st.candidate[size_t(k)][size_t(ab)];
          sources[size_t(k)][size_t(ab)] = final_triple({p.x + o[0], p.y + o[1], p.z + o[2]}).at[size_t(k)];
        }
      vote_color(*table_, fctx.color_weights, fctx.spacing, own, sources, voxel_rgb[i].data());
    }
  });
  if (outside) return Status(StatusCode::kInternal, "an output color read a voxel outside the target level's sets");
  checks.count_unread(fsch, deps[size_t(top.index)], *parent);
  stats.unsound_reads = checks.unsound();
  stats.unread_required = checks.unread();
  return voxel_rgb;
}

Result<std::vector<std::array<float, 3>>> Synthesizer::synthesize(const TargetSet& target, Interrupter& interrupter,
                                                                  SynthesisStats* stats_out,
                                                                  const SynthesisOptions& options) {
  const auto t_start = Clock::now();
  if (target.voxels.empty()) return Status(StatusCode::kInvalidArgument, "the request selects no voxels", "target");
  const int L = table_->levels();
  if (options.level < -1 || options.level >= L)
    return Status(StatusCode::kInvalidArgument,
                  "is " + std::to_string(options.level) + "; the pyramid has levels 0.." + std::to_string(L - 1), "level");
  SynthesisStats stats;
  stats.levels.resize(size_t(L));
  LatchedInterrupter poller(interrupter);
  interrupter.start("synthesize");

  // Scattered targets go piece by piece (by purity, the same bits as one pass would give).
  const auto pieces = split_target(target, kPieceCell);
  std::vector<std::array<float, 3>> voxel_rgb;
  for (const auto& piece : pieces) {
    SynthesisStats ps;
    ps.levels.resize(size_t(L));
    auto colors = pieces.size() == 1 ? synthesize_piece(target, poller, ps, options)
                                     : synthesize_piece(piece_target(target, piece), poller, ps, options);
    if (!colors.is_ok()) {
      interrupter.end();
      return colors.status();
    }
    if (pieces.size() == 1) {
      voxel_rgb = std::move(*colors);
    } else if (!options.dependencies_only) {
      voxel_rgb.resize(target.voxels.size());
      for (size_t i = 0; i < piece.size(); ++i) voxel_rgb[piece[i]] = (*colors)[i];
    }
    add_stats(stats, ps);
  }
  for (const LevelStats& ls : stats.levels) {
    stats.voxels += ls.voxels;
    stats.corrections += ls.corrections;
  }
  std::vector<std::array<float, 3>> out;
  if (!options.dependencies_only) out = target.resolve(voxel_rgb);
  interrupter.end();
  stats.seconds = since(t_start);
  if (stats_out) *stats_out = std::move(stats);
  return out;
}

}  // namespace solidtex
