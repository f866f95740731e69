#include "field_service.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <mutex>
#include <optional>

#include "api_json.h"
#include "core/json_fields.h"
#include "mesh/mesh_geometry.h"
#include "field/sketch.h"
#include "field/tensor_field.h"

namespace solidtex::server {

using nlohmann::json;

namespace {

constexpr size_t kMaxLiveSolvers = 8;
constexpr int64_t kMaxFramesPerRequest = 65536;

// r<N>.stf, r<N>.json (built by appending: GCC 12 warns falsely (-Wrestrict) about "r" + std::string).
std::string revision_name(int revision, const char* extension) {
  std::string s = "r";
  s += std::to_string(revision);
  s += extension;
  return s;
}
std::string stf_name(int revision) { return revision_name(revision, ".stf"); }
std::string json_name(int revision) { return revision_name(revision, ".json"); }

struct FieldEntry {
  int revision = 0;
  json info;                                  // r<N>.json: what GET answers
  std::shared_ptr<const QuatGridField> field;  // the current revision, decoded
  std::unique_ptr<FieldSolver> solver;        // live solver (may be null: rebuilt on demand)
  uint64_t last_use = 0;
  // Serialises the changes of one field (add_curve, remove_last_curve, remove); waited for in
  // steps that poll the request's interrupter (lock_busy), never without a deadline.
  std::shared_ptr<std::timed_mutex> busy = std::make_shared<std::timed_mutex>();
};

constexpr auto kBusyPollStep = std::chrono::milliseconds(50);

// Takes `busy`, polling `interrupter` every kBusyPollStep while another change of the field
// holds it: kCancelled (the Api answers 504 past the deadline) when it asks to stop first.
Status lock_busy(std::timed_mutex& busy, std::unique_lock<std::timed_mutex>& lock, Interrupter& interrupter) {
  lock = std::unique_lock<std::timed_mutex>(busy, std::defer_lock);
  while (!lock.try_lock_for(kBusyPollStep))
    if (interrupter.was_interrupted())
      return Status(StatusCode::kCancelled, "cancelled while waiting for another change of the field to finish");
  return Status::ok();
}

// One change of a field at a time: the entry's mutex (kept alive while held) and its lock;
// members are destroyed in reverse order, so the lock is released before the mutex can go.
struct FieldChangeLock {
  std::shared_ptr<std::timed_mutex> mutex;
  std::unique_lock<std::timed_mutex> lock;
};

// 409 when the caller said which revision it expects and the field is at another one.
Status check_revision(std::optional<int> expected, int current) {
  if (!expected || *expected == current) return Status::ok();
  return Status(StatusCode::kFailedPrecondition,
                "the field is at revision " + std::to_string(current) + ", not " + std::to_string(*expected) +
                    " (changed since); nothing was changed",
                "revision");
}

// A revision's .stf without its .json older than this is a leftover of a writer that died
// between the two (writing both takes milliseconds); a younger one is a write in progress.
constexpr double kRevisionLeftoverSeconds = 60;

// 409: revision `revision` was claimed by another writer (another replica) first.
Status revision_taken(int revision) {
  return Status(StatusCode::kFailedPrecondition,
                "revision " + std::to_string(revision) +
                    " of the field was written meanwhile through another replica (or is being written); nothing was "
                    "changed: read the field and retry",
                "revision");
}

}  // namespace

struct FieldService::Impl {
  Storage& store;
  ServerConfig config;
  mutable std::mutex mutex;
  std::map<std::string, FieldEntry> entries;
  uint64_t tick = 0;

  Impl(Storage& s, const ServerConfig& c) : store(s), config(c) {}

  // Solves a whole sketch within the configured grid-size limit (422 beyond it).
  Result<std::unique_ptr<FieldSolver>> solve(const Sketch& sketch, Interrupter& interrupter, FieldSolveStats& stats) const {
    return FieldSolver::solve(sketch, &stats, interrupter, config.max_field_nodes);
  }

  // Writes revision `revision` (the .stf, then its .json) and returns the info.
  Result<json> store_revision(const std::string& id, int revision, const FieldSolver& solver,
                              const FieldSolveStats& stats, const std::string& sketch_text, FieldEntry& e) {
    StoredField f;
    f.origin = solver.origin();
    f.spacing = solver.spacing();
    f.dims = solver.dims();
    f.singular_nodes = stats.singular_nodes;
    f.nodes = solver.nodes();
    f.log_scales = solver.log_scales();
    f.sketch_json = sketch_text;
    json info = {{"id", id},
                 {"revision", revision},
                 {"curves", solver.curve_count()},
                 {"dims", f.dims},
                 {"origin", {f.origin.x, f.origin.y, f.origin.z}},
                 {"spacing", f.spacing},
                 {"singular_nodes", f.singular_nodes},
                 {"residual", stats.residual},
                 {"seconds", stats.seconds},
                 {"has_scales", !f.log_scales.empty()}};
    return write_revision(id, revision, f, std::move(info), e);
  }

  // Writes `f` as revision `revision` (the .stf, then its .json holding `info`) and returns the info.
  // Both files are write-once (create_new), so that two replicas changing one field at once
  // never both write revision N: the one that creates r<N>.stf first goes on, the other gets
  // revision_taken (409) with nothing written, its change being based on a revision that is no
  // longer the newest (retrying with N+1 would silently drop the winner's curve).
  Result<json> write_revision(const std::string& id, int revision, const StoredField& f, json info, FieldEntry& e) {
    const std::vector<uint8_t> bytes = encode_field(f);
    auto stf = store.create_new(ResourceKind::kField, id, stf_name(revision), bytes);
    if (!stf && stf.status().code() == StatusCode::kAlreadyExists) {
      // An old .stf without its .json is no live writer's: taken back (only if unchanged since
      // read, so that two replicas taking it back cannot both succeed).
      SOLIDTEX_ASSIGN_OR_RETURN(bool done, store.exists(ResourceKind::kField, id, json_name(revision)));
      auto old = done ? Result<VersionedObject>(Status(StatusCode::kAlreadyExists, "written"))
                      : store.read_versioned(ResourceKind::kField, id, stf_name(revision), int64_t(1) << 32);
      if (old && old->age_seconds > kRevisionLeftoverSeconds &&
          store.remove_if_match(ResourceKind::kField, id, stf_name(revision), old->etag).is_ok())
        stf = store.create_new(ResourceKind::kField, id, stf_name(revision), bytes);
    }
    if (!stf) return stf.status().code() == StatusCode::kAlreadyExists ? revision_taken(revision) : stf.status();
    auto acknowledged = store.create_new_text(ResourceKind::kField, id, json_name(revision), info.dump());
    if (!acknowledged) {
      (void)store.remove_if_match(ResourceKind::kField, id, stf_name(revision), *stf);  // no leftover to wait out
      return acknowledged.status().code() == StatusCode::kAlreadyExists ? revision_taken(revision) : acknowledged.status();
    }
    SOLIDTEX_ASSIGN_OR_RETURN(e.field, QuatGridField::create(f.origin, f.spacing, f.dims, f.nodes, f.log_scales));
    e.revision = revision;
    e.info = info;
    return info;
  }

  // Keeps at most kMaxLiveSolvers solvers in memory (least recently used dropped).
  void trim_solvers() {
    size_t live = 0;
    for (auto& [id, e] : entries) live += e.solver ? 1 : 0;
    while (live > kMaxLiveSolvers) {
      FieldEntry* oldest = nullptr;
      for (auto& [id, e] : entries)
        if (e.solver && (!oldest || e.last_use < oldest->last_use)) oldest = &e;
      oldest->solver.reset();
      --live;
    }
  }

  Result<StoredField> load_revision(const std::string& id, int revision) const {
    SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, store.read(ResourceKind::kField, id, stf_name(revision)));
    return decode_field(bytes);
  }

  // The stored field's newest revision with both files (a crash between its .stf and .json
  // leaves the previous revision current), decoded into `e`.
  Status load_newest(const std::string& id, FieldEntry& e) const {
    int revision = 0;
    SOLIDTEX_ASSIGN_OR_RETURN(std::vector<std::string> files, store.files(ResourceKind::kField, id));
    for (const std::string& f : files) {
      if (f.size() > 6 && f[0] == 'r' && f.ends_with(".json")) {
        const int r = std::atoi(f.substr(1, f.size() - 6).c_str());
        if (r > revision && std::binary_search(files.begin(), files.end(), stf_name(r))) revision = r;
      }
    }
    SOLIDTEX_ASSIGN_OR_RETURN(std::string text, store.read_text(ResourceKind::kField, id, json_name(revision)));
    SOLIDTEX_ASSIGN_OR_RETURN(json info, parse_json_text(text, "field info"));
    SOLIDTEX_ASSIGN_OR_RETURN(StoredField stored, load_revision(id, revision));
    SOLIDTEX_ASSIGN_OR_RETURN(e.field, QuatGridField::create(stored.origin, stored.spacing, stored.dims, stored.nodes,
                                                            stored.log_scales));
    e.info = std::move(info);
    e.revision = revision;
    return Status::ok();
  }

  // Read-through (mutex held; several replicas on one data directory): loads a field created
  // through another replica, takes up revisions another replica added (a newer r<N>.json; the
  // live solver, of an older revision, is dropped), and drops a field deleted through another
  // replica. Null: no such field; an error: the store could not be read (nothing changed),
  // unless this replica knows the field: then its entry at the revision this replica knows
  // (revisions are write-once, so that one stays valid; a newer one is taken up once the
  // store answers again). Changes of one field through two replicas at the same moment are
  // serialised by the store: revisions are write-once (write_revision), the later change
  // answers 409.
  // `listed`: a listing just showed it acknowledged.
  Result<FieldEntry*> sync_locked(const std::string& id, std::vector<std::string>* report = nullptr,
                                  bool listed = false) {
    if (!Storage::valid_id(id)) return nullptr;
    auto it = entries.find(id);
    auto unavailable = [](const Status& st) { return st.code() == StatusCode::kUnavailable; };
    bool acknowledged = listed;
    if (!acknowledged) {
      Result<bool> stored = store.acknowledged(ResourceKind::kField, id);
      if (!stored && unavailable(stored.status()) && it != entries.end()) return &it->second;
      SOLIDTEX_ASSIGN_OR_RETURN(acknowledged, std::move(stored));
    }
    if (!acknowledged) {
      if (it != entries.end()) entries.erase(it);
      return nullptr;
    }
    if (it != entries.end()) {
      FieldEntry& e = it->second;
      Result<bool> next = store.exists(ResourceKind::kField, id, json_name(e.revision + 1));
      if (!next && unavailable(next.status())) return &e;
      SOLIDTEX_ASSIGN_OR_RETURN(bool has_next, std::move(next));
      if (has_next) {  // its .json is written last: the .stf is there too
        FieldEntry newer;
        if (load_newest(id, newer).is_ok() && newer.revision > e.revision) {
          e.field = newer.field;
          e.info = newer.info;
          e.revision = newer.revision;
          e.solver.reset();
        }
      }
      return &e;
    }
    FieldEntry e;
    if (Status st = load_newest(id, e); !st.is_ok()) {
      if (st.code() == StatusCode::kUnavailable) return st;  // the store's failure, not the field's
      if (report) report->push_back("skipped field " + id + ": " + st.to_string());
      return nullptr;
    }
    return &entries.emplace(id, std::move(e)).first->second;
  }
  // Waits (interruptibly) until no other change of field `id` runs and holds it in `out`.
  Status lock_change(const std::string& id, FieldChangeLock& out, Interrupter& interrupter) {
    {
      std::lock_guard<std::mutex> g(mutex);
      SOLIDTEX_ASSIGN_OR_RETURN(FieldEntry* e, sync_locked(id));
      if (!e) return Status(StatusCode::kNotFound, "no field '" + id + "'", "id");
      out.mutex = e->busy;
    }
    return lock_busy(*out.mutex, out.lock, interrupter);
  }
  // A list shows what this replica knows when the store cannot be read (FieldService::list).
  void sync_all_locked() {
    auto ids = ids_to_sync(store, ResourceKind::kField, entries);
    if (!ids) return;
    for (const std::string& id : ids->listed) (void)sync_locked(id, nullptr, true);
    for (const std::string& id : ids->unlisted) (void)sync_locked(id);
  }
};

FieldService::FieldService(Storage& store, const ServerConfig& config) : impl_(std::make_unique<Impl>(store, config)) {}
FieldService::~FieldService() = default;

Status FieldService::start(std::vector<std::string>* report) {
  std::lock_guard<std::mutex> g(impl_->mutex);
  SOLIDTEX_ASSIGN_OR_RETURN(std::vector<std::string> ids, impl_->store.ids(ResourceKind::kField));
  for (const std::string& id : ids) SOLIDTEX_RETURN_IF_ERROR(impl_->sync_locked(id, report, true).status());
  return Status::ok();
}

Result<json> FieldService::create(const std::string& sketch_text, Interrupter& interrupter) {
  SOLIDTEX_ASSIGN_OR_RETURN(Sketch sketch, parse_sketch_json(sketch_text));
  FieldSolveStats stats;
  SOLIDTEX_ASSIGN_OR_RETURN(auto solver, impl_->solve(sketch, interrupter, stats));
  const std::string id = Storage::new_id("fld_");
  SOLIDTEX_RETURN_IF_ERROR(impl_->store.create(ResourceKind::kField, id));
  FieldEntry e;
  auto info = impl_->store_revision(id, 1, *solver, stats, sketch_text, e);
  if (!info) {
    impl_->store.remove(ResourceKind::kField, id);
    return info.status();
  }
  std::lock_guard<std::mutex> g(impl_->mutex);
  e.solver = std::move(solver);
  e.last_use = ++impl_->tick;
  impl_->entries.emplace(id, std::move(e));
  impl_->trim_solvers();
  return *info;
}

Result<json> FieldService::create_from_mesh(const Mesh& mesh, const MeshFieldOptions& o, Interrupter& interrupter) {
  if (o.shortest_side_cells < 2 || o.shortest_side_cells > 256)
    return Status(StatusCode::kInvalidArgument, "must be in [2, 256]", "shortest_side_cells");
  if (o.max_constraints < 1 || o.max_constraints > 20000)
    return Status(StatusCode::kInvalidArgument, "must be in [1, 20000]", "max_constraints");
  const MeshBounds box = placed_box(mesh.bounds(), o.placement, o.margin);
  Sketch sketch;
  sketch.domain.min = {box.min[0], box.min[1], box.min[2]};
  sketch.domain.max = {box.max[0], box.max[1], box.max[2]};
  sketch.domain.shortest_side_cells = o.shortest_side_cells;
  const double spacing =
      std::min({box.max[0] - box.min[0], box.max[1] - box.min[1], box.max[2] - box.min[2]}) / o.shortest_side_cells;
  int dropped = 0;
  if (o.kind == MeshFieldOptions::Kind::kCurvature) {
    SOLIDTEX_ASSIGN_OR_RETURN(sketch.frames, curvature_frames(mesh, o.placement, o.max_constraints, spacing));
  } else {
    std::vector<SketchCurve> candidates;
    auto crests = crest_curves(mesh, o.placement, o.feature_angle_degrees);
    if (crests) candidates = std::move(*crests);
    else if (o.curves.empty()) return crests.status();
    SOLIDTEX_ASSIGN_OR_RETURN(auto user, surface_curves(mesh, o.placement, o.curves));
    for (size_t i = 0; i < user.size(); ++i) {
      SOLIDTEX_RETURN_IF_ERROR(validate_curve(user[i], sketch.domain, int(i)).with_context("user curve"));
    }
    candidates.insert(candidates.end(), user.begin(), user.end());
    // Crest chains that define no frame somewhere (e.g. a tangent along a vertex normal at a
    // cusp) are skipped, and counted.
    for (auto& c : candidates) {
      if (validate_curve(c, sketch.domain, int(sketch.curves.size())).is_ok()) sketch.curves.push_back(std::move(c));
      else ++dropped;
    }
    if (sketch.curves.empty()) return Status(StatusCode::kUnprocessable, "no usable feature curve", "mesh");
  }
  const std::string text = sketch_to_json(sketch);
  SOLIDTEX_ASSIGN_OR_RETURN(json info, create(text, interrupter));
  info["from_mesh"] = {{"kind", o.kind == MeshFieldOptions::Kind::kCurvature ? "curvature" : "features"},
                       {"frames", int64_t(sketch.frames.size())},
                       {"curves", int64_t(sketch.curves.size())},
                       {"dropped_curves", dropped},
                       {"placement", {{"scale", o.placement.scale}, {"translate", o.placement.translate}}}};
  return info;
}

Result<json> FieldService::add_curve(const std::string& id, const std::string& curve_text, Interrupter& interrupter,
                                     std::optional<int> expected_revision) {
  FieldChangeLock one_at_a_time;
  SOLIDTEX_RETURN_IF_ERROR(impl_->lock_change(id, one_at_a_time, interrupter));
  int revision = 0;
  std::unique_ptr<FieldSolver> solver;
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    SOLIDTEX_ASSIGN_OR_RETURN(FieldEntry* found, impl_->sync_locked(id));
    if (!found) return Status(StatusCode::kNotFound, "no field '" + id + "'", "id");
    auto it = impl_->entries.find(id);
    revision = it->second.revision;
    SOLIDTEX_RETURN_IF_ERROR(check_revision(expected_revision, revision));
    solver = std::move(it->second.solver);
  }
  SOLIDTEX_ASSIGN_OR_RETURN(StoredField current, impl_->load_revision(id, revision));
  SOLIDTEX_ASSIGN_OR_RETURN(Sketch sketch, parse_sketch_json(current.sketch_json));
  const int index = int(sketch.curves.size());
  SOLIDTEX_ASSIGN_OR_RETURN(SketchCurve curve, parse_curve_json(curve_text, index));
  SOLIDTEX_RETURN_IF_ERROR(validate_curve(curve, sketch.domain, index));
  FieldSolveStats stats;
  if (!solver) {
    SOLIDTEX_ASSIGN_OR_RETURN(solver, impl_->solve(sketch, interrupter, stats));
  }
  const auto t0 = std::chrono::steady_clock::now();
  SOLIDTEX_RETURN_IF_ERROR(solver->add_curve(curve, index, &stats, interrupter));
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The stored sketch grows by the curve, so the revision's file is a complete sketch.
  json sketch_json = json::parse(current.sketch_json);
  sketch_json["curves"].push_back(json::parse(curve_text));
  FieldEntry updated;
  SOLIDTEX_ASSIGN_OR_RETURN(json info, impl_->store_revision(id, revision + 1, *solver, stats, sketch_json.dump(), updated));
  std::lock_guard<std::mutex> g(impl_->mutex);
  auto it = impl_->entries.find(id);
  if (it == impl_->entries.end()) return Status(StatusCode::kNotFound, "field '" + id + "' was deleted", "id");
  it->second.revision = updated.revision;
  it->second.info = updated.info;
  it->second.field = updated.field;
  it->second.solver = std::move(solver);
  it->second.last_use = ++impl_->tick;
  impl_->trim_solvers();
  return info;
}

Result<json> FieldService::remove_last_curve(const std::string& id, Interrupter& interrupter,
                                             std::optional<int> expected_revision) {
  FieldChangeLock one_at_a_time;
  SOLIDTEX_RETURN_IF_ERROR(impl_->lock_change(id, one_at_a_time, interrupter));
  int revision = 0;
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    SOLIDTEX_ASSIGN_OR_RETURN(FieldEntry* found, impl_->sync_locked(id));
    if (!found) return Status(StatusCode::kNotFound, "no field '" + id + "'", "id");
    auto it = impl_->entries.find(id);
    revision = it->second.revision;
    SOLIDTEX_RETURN_IF_ERROR(check_revision(expected_revision, revision));
  }
  const auto t0 = std::chrono::steady_clock::now();
  SOLIDTEX_ASSIGN_OR_RETURN(StoredField current, impl_->load_revision(id, revision));
  SOLIDTEX_ASSIGN_OR_RETURN(Sketch sketch, parse_sketch_json(current.sketch_json));
  if (sketch.curves.empty()) return Status(StatusCode::kFailedPrecondition, "the field has no curve to remove", "curves");
  if (sketch.curves.size() == 1 && sketch.frames.empty())
    return Status(StatusCode::kFailedPrecondition,
                  "the field's only curve cannot be removed: a sketch needs a curve or a frame (delete the field instead)",
                  "curves");
  sketch.curves.pop_back();
  json target = json::parse(current.sketch_json);
  target["curves"].erase(target["curves"].end() - 1);
  // Undo restores the newest earlier revision drawn with exactly these curves, bit for bit (an
  // incremental solve need not equal a fresh one); a sketch never stored (a field created with
  // several curves) is solved afresh.
  FieldEntry updated;
  std::unique_ptr<FieldSolver> solver;
  json info;
  int restored = 0;
  // Every earlier revision may be read: the scan polls the interrupter at each one, and a
  // revision whose files cannot be read or decoded is passed over (an older match, or a fresh
  // solve, serves as well).
  for (int r = revision - 1; r >= 1 && !restored; --r) {
    if (interrupter.was_interrupted())
      return Status(StatusCode::kCancelled, "cancelled while looking for the revision to restore");
    auto earlier = impl_->load_revision(id, r);
    if (!earlier || json::parse(earlier->sketch_json, nullptr, false) != target) continue;
    auto text = impl_->store.read_text(ResourceKind::kField, id, json_name(r));
    if (!text) continue;
    auto parsed = parse_json_text(*text, "field info");
    if (!parsed || !parsed->is_object()) continue;
    json earlier_info = std::move(*parsed);
    earlier_info["revision"] = revision + 1;
    earlier_info["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    SOLIDTEX_ASSIGN_OR_RETURN(info, impl_->write_revision(id, revision + 1, *earlier, std::move(earlier_info), updated));
    restored = r;
  }
  if (!restored) {
    FieldSolveStats stats;
    SOLIDTEX_ASSIGN_OR_RETURN(solver, impl_->solve(sketch, interrupter, stats));
    SOLIDTEX_ASSIGN_OR_RETURN(info, impl_->store_revision(id, revision + 1, *solver, stats, target.dump(), updated));
  }
  std::lock_guard<std::mutex> g(impl_->mutex);
  auto it = impl_->entries.find(id);
  if (it == impl_->entries.end()) return Status(StatusCode::kNotFound, "field '" + id + "' was deleted", "id");
  it->second.revision = updated.revision;
  it->second.info = updated.info;
  it->second.field = updated.field;
  // A restored revision has no live solver: the next added curve re-solves its sketch first.
  it->second.solver = std::move(solver);
  it->second.last_use = ++impl_->tick;
  impl_->trim_solvers();
  return info;
}

Result<json> FieldService::get(const std::string& id) const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  SOLIDTEX_ASSIGN_OR_RETURN(const FieldEntry* e, impl_->sync_locked(id));
  if (!e) return Status(StatusCode::kNotFound, "no field '" + id + "'", "id");
  return e->info;
}

json FieldService::list() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  impl_->sync_all_locked();
  json out = json::array();
  for (const auto& [id, e] : impl_->entries) out.push_back(e.info);
  return {{"fields", out}};
}

Status FieldService::remove(const std::string& id, Interrupter& interrupter) {
  // A curve being added or removed finishes first (its answer stands), so that no revision is
  // ever written into a field directory that is being deleted.
  FieldChangeLock one_at_a_time;
  SOLIDTEX_RETURN_IF_ERROR(impl_->lock_change(id, one_at_a_time, interrupter));
  std::lock_guard<std::mutex> g(impl_->mutex);
  SOLIDTEX_ASSIGN_OR_RETURN(FieldEntry* found, impl_->sync_locked(id));
  if (!found) return Status(StatusCode::kNotFound, "no field '" + id + "'", "id");
  auto it = impl_->entries.find(id);
  SOLIDTEX_RETURN_IF_ERROR(impl_->store.remove(ResourceKind::kField, id));
  impl_->entries.erase(it);
  return Status::ok();
}

Result<std::vector<uint8_t>> FieldService::file_bytes(const std::string& id, int* revision) const {
  int r = 0;
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    SOLIDTEX_ASSIGN_OR_RETURN(const FieldEntry* e, impl_->sync_locked(id));
    if (!e) return Status(StatusCode::kNotFound, "no field '" + id + "'", "id");
    r = e->revision;
  }
  if (revision) *revision = r;
  return impl_->store.read(ResourceKind::kField, id, stf_name(r));
}

Result<json> FieldService::sample_frames(const std::string& id, const WorldPoint& min, std::array<int, 3> size,
                                         double step) const {
  std::shared_ptr<const QuatGridField> field;
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    SOLIDTEX_ASSIGN_OR_RETURN(const FieldEntry* e, impl_->sync_locked(id));
    if (!e) return Status(StatusCode::kNotFound, "no field '" + id + "'", "id");
    field = e->field;
  }
  int64_t count = 1;
  for (int s : size) {
    if (s < 1) return Status(StatusCode::kInvalidArgument, "every count must be >= 1", "size");
    count *= s;
    if (count > kMaxFramesPerRequest)
      return Status(StatusCode::kUnprocessable, "at most " + std::to_string(kMaxFramesPerRequest) + " points per request", "size");
  }
  if (!(step > 0 && step <= 1e6)) return Status(StatusCode::kInvalidArgument, "must be in (0, 1e6]", "step");
  json points = json::array(), quats = json::array(), scales = json::array();
  for (int k = 0; k < size[2]; ++k)
    for (int j = 0; j < size[1]; ++j)
      for (int i = 0; i < size[0]; ++i) {
        const WorldPoint p{min.x + step * i, min.y + step * j, min.z + step * k};
        const Quat q = field->at(p);
        const auto s = field->scale_at(p);
        points.push_back({p.x, p.y, p.z});
        quats.push_back({q.w, q.x, q.y, q.z});
        scales.push_back({s[0], s[1], s[2]});
      }
  return json{{"points", points}, {"quaternions", quats}, {"scales", scales}};
}

}  // namespace solidtex::server
