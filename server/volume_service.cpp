#include "volume_service.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <iostream>
#include <map>
#include <mutex>
#include <string_view>
#include <thread>
#include <utility>

#include "api_json.h"
#include "array_etag.h"
#include "field/field_file.h"
#include "core/json_fields.h"
#include "query_params.h"
#include "synthesis/region_volume.h"
#include "synthesis/resident_bytes.h"
#include "synthesis/synthesizer.h"

namespace solidtex::server {

using nlohmann::json;

namespace {

constexpr size_t kRecentRequests = 16;

// The patterns of regions.label and field.spec in proto/volume.schema.json, matched exactly
// (without std::regex, whose recursion a long string could exhaust).
bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }
bool label_matches(std::string_view s) {
  if (starts_with(s, "halfspace:")) return is_number_list_text(s.substr(10), 4);
  if (starts_with(s, "box:")) return is_number_list_text(s.substr(4), 6);
  if (starts_with(s, "surface:")) return is_number_list_text(s.substr(8), 1);
  return false;
}
bool field_spec_matches(std::string_view s) {
  if (const size_t semi = s.find(";scale:"); semi != std::string_view::npos) {
    if (!is_number_list_text(s.substr(semi + 7), 3)) return false;
    s = s.substr(0, semi);
  }
  if (s == "identity") return true;
  if (starts_with(s, "quat:") || starts_with(s, "axis:")) return is_number_list_text(s.substr(5), 4);
  return false;
}

using Clock = std::chrono::steady_clock;

// What a loaded volume keeps between requests, outside its voxel cache: built at its first query
// (at creation for a surface label, whose band creation builds anyway), shared by the requests
// running on it, and dropped when the volume is evicted (LRU over --volume-state-mb, or idle
// for --idle-evict-s); rebuilt the same, bit for bit, at its next query. Immutable once built.
struct VolumeState {
  std::vector<std::shared_ptr<Synthesizer>> synths;  // one per exemplar (region)
  std::shared_ptr<RegionVolume> regions;
  std::shared_ptr<const FrameField> field;
  std::shared_ptr<const SurfaceDistance> surface;
  std::vector<std::shared_ptr<const Table>> tables;  // distinct; shared with other volumes of the exemplar
  std::vector<int64_t> table_bytes;                  // per entry of `tables`
  VoxelSampling sampling = VoxelSampling::kNearest;  // what resample "auto" stands for in cuts and points
  int64_t synthesizer_bytes = 0, field_bytes = 0, surface_bytes = 0;

  int64_t own_bytes() const { return synthesizer_bytes + field_bytes + surface_bytes; }
  int64_t tables_bytes() const {
    int64_t b = 0;
    for (int64_t t : table_bytes) b += t;
    return b;
  }
  int64_t bytes() const { return own_bytes() + tables_bytes(); }
};

struct Volume {
  json info;                                  // volume.json (the spec as given, plus id)
  std::vector<std::string> exemplar_ids;      // one, or two with a region label
  std::optional<RegionLabel> label;           // a surface label's band lives in the state
  std::shared_ptr<const FrameField> inline_field;  // identity or an inline spec; null: field.stf
  json surface_mesh;                          // regions.mesh of a surface label, else null
  json params_spec = json::object();          // as given; plane weights default per table
  uint32_t seed = 1;
  std::mutex build_mutex;                     // one build at a time
  // Guarded by the service mutex.
  std::shared_ptr<VolumeState> state;         // null while not loaded
  int active = 0;                             // requests running on the state
  Clock::time_point last_used = Clock::now(); // end of the last request (or load, creation)
  uint64_t last_tick = 0;                     // LRU order
  int64_t loads = 0, evictions = 0;
  // Statistics.
  std::mutex stats_mutex;
  std::vector<int64_t> voxels_per_level;
  int64_t requests = 0;
  std::deque<json> recent;
};

json stats_json(const std::string& kind, const TargetSet& target, const std::vector<SynthesisStats>& per_region,
                double seconds) {
  json levels = json::array();
  int64_t voxels = 0, corrections = 0, store_bytes = 0, estimated_bytes = 0, support_voxels = 0;
  for (const SynthesisStats& s : per_region) {
    support_voxels += s.support_voxels;
    store_bytes = std::max(store_bytes, s.store_bytes);
    estimated_bytes = std::max(estimated_bytes, s.estimated_bytes);
  }
  for (size_t r = 0; r < per_region.size(); ++r)
    for (const LevelStats& l : per_region[r].levels) {
      levels.push_back({{"region", r},
                        {"level", l.level},
                        {"voxels", l.voxels},
                        {"corrections", l.corrections},
                        {"cache_hits", l.cache_hits},
                        {"needed_final", l.needed_final}});
      voxels += l.voxels;
      corrections += l.corrections;
    }
  return {{"kind", kind},         {"target_voxels", int64_t(target.voxels.size())},
          {"support_voxels", support_voxels},
          {"samples", int64_t(target.sample.size())},
          {"voxels", voxels},     {"corrections", corrections},
          {"seconds", seconds},   {"levels", levels},
          {"store_bytes", store_bytes}, {"estimated_bytes", estimated_bytes}};
}

}  // namespace

struct VolumeService::Impl {
  Storage& store;
  ServerConfig config;
  ExemplarService& exemplars;
  FieldService& fields;
  MeshService& meshes;
  mutable std::mutex mutex;
  std::map<std::string, std::shared_ptr<Volume>> volumes;
  std::atomic<int64_t> voxels_total{0};
  std::vector<std::weak_ptr<Synthesizer>> live;  // every synthesizer built (guarded by mutex)
  // Loaded state (guarded by mutex).
  uint64_t tick = 0;
  int64_t loads_total = 0, evicted_budget = 0, evicted_idle = 0;
  // The idle sweeper.
  std::condition_variable sweep_wake;
  bool stopping = false;
  std::thread sweeper;

  Impl(Storage& s, const ServerConfig& c, ExemplarService& e, FieldService& f, MeshService& m)
      : store(s), config(c), exemplars(e), fields(f), meshes(m) {}
  ~Impl() {
    {
      std::lock_guard<std::mutex> g(mutex);
      stopping = true;
    }
    sweep_wake.notify_all();
    if (sweeper.joinable()) sweeper.join();
  }

  // The band of a surface label: the mesh (the volume's copy, or the mesh service's bytes when
  // creating) placed as `mesh_spec` says.
  Result<std::shared_ptr<const SurfaceDistance>> build_surface(const Volume& v, const json& mesh_spec,
                                                               const std::vector<uint8_t>& bytes) {
    SOLIDTEX_ASSIGN_OR_RETURN(Mesh mesh, meshes.decode(bytes));
    SOLIDTEX_ASSIGN_OR_RETURN(Placement placement,
                              placement_from_json(mesh_spec.value("placement", json::object()), "regions.mesh.placement", mesh.bounds(), nullptr));
    return SurfaceDistance::create(mesh, placement, v.label->distance + 1, config.max_request_bytes);
  }

  // Parses a spec (strictly) into a Volume; `field_bytes` receives the stored field to copy.
  Result<std::shared_ptr<Volume>> parse_spec(const json& j, std::vector<uint8_t>* field_bytes, json* field_desc) {
    SOLIDTEX_RETURN_IF_ERROR(check_keys(j, {"id", "name", "exemplar", "regions", "field", "seed", "params"}, ""));
    auto v = std::make_shared<Volume>();
    if (j.contains("name")) { SOLIDTEX_RETURN_IF_ERROR(json_text(j["name"], "name", 200).status()); }
    if (j.contains("exemplar") == j.contains("regions"))
      return Status(StatusCode::kInvalidArgument, "give exactly one of 'exemplar' and 'regions'", "exemplar");
    if (j.contains("exemplar")) {
      SOLIDTEX_ASSIGN_OR_RETURN(std::string e, json_text(j["exemplar"], "exemplar", 64));
      v->exemplar_ids.push_back(e);
    } else {
      const json& r = j["regions"];
      SOLIDTEX_RETURN_IF_ERROR(check_keys(r, {"exemplars", "label", "mesh"}, "regions"));
      if (!r.contains("exemplars") || !r["exemplars"].is_array() || r["exemplars"].size() != 2)
        return Status(StatusCode::kInvalidArgument, "must be an array of two exemplar ids", "regions.exemplars");
      for (size_t i = 0; i < 2; ++i) {
        SOLIDTEX_ASSIGN_OR_RETURN(std::string e, json_text(r["exemplars"][i], "regions.exemplars[" + std::to_string(i) + "]", 64));
        v->exemplar_ids.push_back(e);
      }
      if (!r.contains("label")) return Status(StatusCode::kInvalidArgument, "is required", "regions.label");
      SOLIDTEX_ASSIGN_OR_RETURN(std::string label, json_text(r["label"], "regions.label"));
      if (!label_matches(label))
        return Status(StatusCode::kInvalidArgument,
                      "must be halfspace:NX,NY,NZ,D, box:X0,Y0,Z0,X1,Y1,Z1 or surface:D (plain decimal numbers)", "regions.label");
      auto parsed = RegionLabel::parse(label);
      if (!parsed) return Status(StatusCode::kInvalidArgument, parsed.status().message(), "regions.label");
      v->label = *parsed;
      const bool shell = parsed->kind == RegionLabel::Kind::kSurfaceShell;
      if (shell != r.contains("mesh"))
        return Status(StatusCode::kInvalidArgument, shell ? "a surface label needs {\"id\", \"placement\"} of a mesh" : "only a surface label takes a mesh",
                      "regions.mesh");
      if (shell) {
        SOLIDTEX_RETURN_IF_ERROR(check_keys(r["mesh"], {"id", "placement"}, "regions.mesh"));
        if (!r["mesh"].contains("id")) return Status(StatusCode::kInvalidArgument, "is required", "regions.mesh.id");
        SOLIDTEX_RETURN_IF_ERROR(json_text(r["mesh"]["id"], "regions.mesh.id", 64).status());
        v->surface_mesh = r["mesh"];
      }
    }
    if (j.contains("seed")) {
      SOLIDTEX_ASSIGN_OR_RETURN(auto s, json_int(j["seed"], "seed", 0, int64_t(1) << 30));
      v->seed = uint32_t(s);
    }
    if (j.contains("params")) {
      if (!j["params"].is_object()) return Status(StatusCode::kInvalidArgument, "must be a JSON object", "params");
      v->params_spec = j["params"];
      SOLIDTEX_RETURN_IF_ERROR(synthesis_params_from_json(v->params_spec, "params", SynthesisParams{}).status());
    }
    *field_desc = json{{"kind", "identity"}};
    std::string spec = "identity";
    if (j.contains("field")) {
      const json& f = j["field"];
      SOLIDTEX_RETURN_IF_ERROR(check_keys(f, {"id", "spec", "revision"}, "field"));
      if (f.contains("id") == f.contains("spec"))
        return Status(StatusCode::kInvalidArgument, "give exactly one of 'id' and 'spec'", "field");
      if (f.contains("spec")) {
        SOLIDTEX_ASSIGN_OR_RETURN(spec, json_text(f["spec"], "field.spec"));
        // Only the inline forms, exactly: a spec must never name a file on the server.
        if (!field_spec_matches(spec))
          return Status(StatusCode::kInvalidArgument, "must be identity, quat:W,X,Y,Z or axis:AX,AY,AZ,DEG (optionally ;scale:SX,SY,SZ)",
                        "field.spec");
        *field_desc = json{{"kind", "spec"}, {"spec", spec}};
      } else {
        SOLIDTEX_ASSIGN_OR_RETURN(std::string fid, json_text(f["id"], "field.id", 64));
        if (field_bytes) {  // creating: copy the field's current revision
          int revision = 0;
          auto bytes = fields.file_bytes(fid, &revision);
          if (!bytes) return Status(bytes.status().code(), bytes.status().message(), "field.id");
          *field_bytes = std::move(*bytes);
          *field_desc = json{{"kind", "stored"}, {"id", fid}, {"revision", revision}};
        } else {
          *field_desc = f;
        }
      }
    }
    const bool stored_field = j.contains("field") && j["field"].contains("id");
    if (!stored_field) {  // inline spec, or identity by default
      auto parsed = parse_field_spec(spec);
      if (!parsed) return Status(StatusCode::kInvalidArgument, parsed.status().message(), "field.spec");
      v->inline_field = *parsed;
    }
    return v;
  }

  Status check_exemplars_ready(const Volume& v) {
    for (const std::string& id : v.exemplar_ids) {
      Status st = exemplars.check_ready(id);
      if (!st.is_ok()) return Status(st.code(), st.message(), v.label ? "regions.exemplars" : "exemplar");
    }
    return Status::ok();
  }

  // Builds a volume's state: field (the volume's own copy of a stored one), surface band,
  // tables, synthesizers. `surface` and `field`, when given, were just built by create().
  Result<std::shared_ptr<VolumeState>> build_state(const Volume& v, std::shared_ptr<const SurfaceDistance> surface,
                                                   std::shared_ptr<const FrameField> field) {
    const std::string id = v.info["id"].get<std::string>();
    auto st = std::make_shared<VolumeState>();
    if (field) st->field = std::move(field);
    else if (v.inline_field) st->field = v.inline_field;
    else {
      SOLIDTEX_ASSIGN_OR_RETURN(st->field, load_stored_field(id));
    }
    if (v.label && v.label->kind == RegionLabel::Kind::kSurfaceShell) {
      if (surface) {
        st->surface = std::move(surface);
      } else {  // start-up never builds bands before listening: the first query does
        SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, store.read(ResourceKind::kVolume, id, "mesh.source"));
        SOLIDTEX_ASSIGN_OR_RETURN(st->surface, build_surface(v, v.surface_mesh, bytes));
      }
    }
    for (const std::string& eid : v.exemplar_ids) {
      SOLIDTEX_ASSIGN_OR_RETURN(auto table, exemplars.table(eid));
      SynthesisParams base;
      base.plane_weights = table->params().suggested_plane_weights;
      SOLIDTEX_ASSIGN_OR_RETURN(SynthesisParams params, synthesis_params_from_json(v.params_spec, "params", base));
      params.seed = v.seed;
      SOLIDTEX_ASSIGN_OR_RETURN(auto s, Synthesizer::create(table, st->field, params, 0));
      st->synths.push_back(s);
      st->synthesizer_bytes += synthesizer_state_bytes(*s);
      if (std::find(st->tables.begin(), st->tables.end(), table) == st->tables.end()) {
        st->tables.push_back(table);
        st->table_bytes.push_back(table_resident_bytes(*table));
      }
    }
    if (v.label) {
      RegionLabel label = *v.label;
      label.surface = st->surface;
      SOLIDTEX_ASSIGN_OR_RETURN(st->regions, RegionVolume::create(st->synths, label));
      st->synthesizer_bytes += int64_t(sizeof(RegionVolume));
    }
    st->sampling = solidtex::preferred_voxel_sampling(st->tables, st->synths.front()->params().color);
    st->field_bytes = field_resident_bytes(*st->field);
    st->surface_bytes = st->surface ? st->surface->resident_bytes() : 0;
    return st;
  }

  // --- loaded state: acquire, release, eviction (the service mutex guards all of it) ---------

  void touch(Volume& v) {
    v.last_used = Clock::now();
    v.last_tick = ++tick;
  }

  bool registered_locked(const std::shared_ptr<Volume>& v) const {
    auto it = volumes.find(v->info["id"].get<std::string>());
    return it != volumes.end() && it->second == v;
  }

  // Resident bytes of every loaded volume's state; a table several volumes use counts once.
  int64_t state_bytes_locked() const {
    int64_t bytes = 0;
    std::map<const Table*, int64_t> tables;
    for (const auto& [id, v] : volumes)
      if (v->state) {
        bytes += v->state->own_bytes();
        for (size_t i = 0; i < v->state->tables.size(); ++i) tables[v->state->tables[i].get()] = v->state->table_bytes[i];
      }
    for (const auto& [t, b] : tables) bytes += b;
    return bytes;
  }

  void evict_locked(Volume& v, std::vector<std::shared_ptr<VolumeState>>& dropped) {
    dropped.push_back(std::move(v.state));
    v.state.reset();
    ++v.evictions;
  }

  // Evicts least-recently-used idle states while the total is over --volume-state-mb. Never a
  // state that running requests use (the total may exceed the budget while they run), nor the
  // most recently used one: a volume larger than the budget alone stays loaded while it is the
  // one in use, rather than being rebuilt at every query (until it idles or another is used).
  void evict_over_budget_locked(std::vector<std::shared_ptr<VolumeState>>& dropped) {
    int64_t total = state_bytes_locked();
    while (total > config.volume_state_bytes) {
      Volume* victim = nullptr;
      Volume* newest = nullptr;
      for (auto& [id, v] : volumes)
        if (v->state && (!newest || v->last_tick > newest->last_tick)) newest = v.get();
      for (auto& [id, v] : volumes)
        if (v->state && v->active == 0 && v.get() != newest && (!victim || v->last_tick < victim->last_tick))
          victim = v.get();
      if (!victim) break;
      evict_locked(*victim, dropped);
      ++evicted_budget;
      total = state_bytes_locked();
    }
  }

  void evict_idle_locked(std::vector<std::shared_ptr<VolumeState>>& dropped) {
    const auto now = Clock::now();
    const auto idle = std::chrono::duration<double>(config.idle_evict_s);
    for (auto& [id, v] : volumes)
      if (v->state && v->active == 0 && now - v->last_used >= idle) {
        evict_locked(*v, dropped);
        ++evicted_idle;
      }
  }

  void sweep_loop() {
    const double period = std::clamp(config.idle_evict_s / 4, 0.05, 5.0);
    std::unique_lock<std::mutex> lock(mutex);
    while (!stopping) {
      sweep_wake.wait_for(lock, std::chrono::duration<double>(period));
      if (stopping) break;
      std::vector<std::shared_ptr<VolumeState>> dropped;
      evict_idle_locked(dropped);
      if (dropped.empty()) continue;
      lock.unlock();
      dropped.clear();  // frees outside the lock
      rebalance_cache();
      lock.lock();
    }
  }

  // Installs a freshly built state as the volume's (unless it was deleted meanwhile: then only
  // the request that built it uses it), makes room under the budget and rebalances the cache.
  void install(const std::shared_ptr<Volume>& v, const std::shared_ptr<VolumeState>& st, bool for_request) {
    std::vector<std::shared_ptr<VolumeState>> dropped;
    {
      std::lock_guard<std::mutex> g(mutex);
      if (for_request) ++v->active;
      touch(*v);
      if (registered_locked(v)) {
        v->state = st;
        ++v->loads;
        ++loads_total;
        for (auto& s : st->synths) live.push_back(s);
        evict_over_budget_locked(dropped);
      }
    }
    dropped.clear();
    rebalance_cache();
  }

  // The volume's state held for one call: not evictable until the Hold is destroyed.
  class Hold {
   public:
    Hold(Impl& impl, std::shared_ptr<Volume> v, std::shared_ptr<VolumeState> state)
        : impl_(&impl), volume(std::move(v)), state(std::move(state)) {}
    Hold(Hold&& o) noexcept : impl_(std::exchange(o.impl_, nullptr)), volume(std::move(o.volume)), state(std::move(o.state)) {}
    Hold& operator=(Hold&&) = delete;
    ~Hold() {
      if (impl_) impl_->release(*volume);
    }

   private:
    Impl* impl_;

   public:
    std::shared_ptr<Volume> volume;
    std::shared_ptr<VolumeState> state;
  };
  Result<Hold> hold(const std::string& id) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto v, find(id));
    SOLIDTEX_ASSIGN_OR_RETURN(std::shared_ptr<VolumeState> state, acquire(v));
    return Hold(*this, std::move(v), std::move(state));
  }

  // The volume's state for one request, built when not loaded; release() must follow.
  Result<std::shared_ptr<VolumeState>> acquire(const std::shared_ptr<Volume>& v) {
    auto loaded = [&]() -> std::shared_ptr<VolumeState> {
      std::lock_guard<std::mutex> g(mutex);
      if (!v->state) return nullptr;
      ++v->active;
      touch(*v);
      return v->state;
    };
    if (auto st = loaded()) return st;
    std::lock_guard<std::mutex> b(v->build_mutex);
    if (auto st = loaded()) return st;  // built by another request meanwhile
    SOLIDTEX_ASSIGN_OR_RETURN(auto st, build_state(*v, nullptr, nullptr));
    install(v, st, true);
    return st;
  }

  void release(Volume& v) {
    std::vector<std::shared_ptr<VolumeState>> dropped;
    {
      std::lock_guard<std::mutex> g(mutex);
      --v.active;
      touch(v);
      evict_over_budget_locked(dropped);  // what running requests held may now go
    }
    if (dropped.empty()) return;
    dropped.clear();
    rebalance_cache();
  }

  // Splits the cache budget evenly over every live synthesizer.
  void rebalance_cache() {
    const auto synths = live_synthesizers();
    for (auto& s : synths) s->cache().set_budget_bytes(config.cache_bytes / int64_t(std::max<size_t>(1, synths.size())));
  }

  // Drops the synthesizers of evicted and deleted volumes (once their last query ended).
  std::vector<std::shared_ptr<Synthesizer>> live_synthesizers() {
    std::lock_guard<std::mutex> g(mutex);
    std::vector<std::shared_ptr<Synthesizer>> out;
    std::vector<std::weak_ptr<Synthesizer>> kept;
    for (auto& w : live)
      if (auto s = w.lock()) {
        out.push_back(s);
        kept.push_back(w);
      }
    live = std::move(kept);
    return out;
  }

  // A volume.json read back (start-up, read-through); defined below.
  Result<std::shared_ptr<Volume>> load_stored(const std::string& id);

  // The volume's own copy of its field (volumes/<id>/field.stf), decoded.
  Result<std::shared_ptr<const QuatGridField>> load_stored_field(const std::string& id) const {
    SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, store.read(ResourceKind::kVolume, id, "field.stf", int64_t(1) << 30));
    auto f = decode_field(bytes);
    if (!f) return f.status().with_context("volume " + id + " field.stf");
    return QuatGridField::create(f->origin, f->spacing, f->dims, f->nodes, f->log_scales);
  }

  // The volume, read through the store (several replicas on one data directory): one created
  // through another replica is loaded, one deleted through another is dropped (404). A store
  // that cannot be reached changes nothing: a volume this replica has loaded is served as it
  // knows it (its voxels are a pure function of what it holds; at worst one deleted elsewhere
  // answers until the store is back), any other answers the store's failure (502).
  // `listed`: a listing just showed it acknowledged.
  Result<std::shared_ptr<Volume>> find(const std::string& id, bool listed = false) {
    auto missing = [&] { return Status(StatusCode::kNotFound, "no volume '" + id + "'", "id"); };
    if (!Storage::valid_id(id)) return missing();
    bool acknowledged = listed;
    if (!acknowledged) {
      Result<bool> stored = store.acknowledged(ResourceKind::kVolume, id);
      if (!stored && stored.status().code() == StatusCode::kUnavailable) {
        std::lock_guard<std::mutex> g(mutex);
        auto it = volumes.find(id);
        if (it != volumes.end()) return it->second;
      }
      SOLIDTEX_ASSIGN_OR_RETURN(acknowledged, std::move(stored));
    }
    std::shared_ptr<VolumeState> dropped;
    {
      std::lock_guard<std::mutex> g(mutex);
      auto it = volumes.find(id);
      if (acknowledged && it != volumes.end()) return it->second;
      if (!acknowledged && it != volumes.end()) {  // deleted elsewhere
        dropped = std::move(it->second->state);  // running queries keep theirs until they finish
        volumes.erase(it);
      }
    }
    if (dropped) {
      dropped.reset();
      rebalance_cache();
    }
    if (!acknowledged) return missing();
    auto v = load_stored(id);
    if (!v && v.status().code() == StatusCode::kUnavailable) return v.status();  // the store's failure
    if (!v) {
      std::cerr << "solidtex serve: skipped volume " << id << ": " << v.status().to_string() << "\n";
      return missing();
    }
    std::lock_guard<std::mutex> g(mutex);
    auto [it, inserted] = volumes.emplace(id, *v);
    if (inserted) touch(*it->second);
    return it->second;
  }
  // Every volume of the store, and none that is gone from it; what this replica knows when the
  // store cannot be listed (VolumeService::list).
  void sync_all() {
    auto listed = store.ids(ResourceKind::kVolume);  // outside the mutex: queries go on meanwhile
    if (!listed) return;
    std::vector<std::string> unlisted;
    {
      std::lock_guard<std::mutex> g(mutex);
      for (const auto& [id, v] : volumes)
        if (!std::binary_search(listed->begin(), listed->end(), id)) unlisted.push_back(id);
    }
    for (const std::string& id : *listed) (void)find(id, true);
    for (const std::string& id : unlisted) (void)find(id);
  }
};

VolumeService::VolumeService(Storage& store, const ServerConfig& config, ExemplarService& exemplars,
                             FieldService& fields, MeshService& meshes)
    : impl_(std::make_unique<Impl>(store, config, exemplars, fields, meshes)) {}
VolumeService::~VolumeService() = default;

namespace {

// Appearance-changing defaults are written into a volume's stored spec, so that a later release
// changing them never changes a stored volume's voxels: writes each (name, value) as the params'
// value where they give none and returns whether it wrote any. A spec that is not an object,
// or whose params are not, is left for parse_spec to refuse.
bool pin_params(json& spec, const json& values) {
  if (!spec.is_object()) return false;
  json& params = spec["params"];
  if (params.is_null()) params = json::object();
  if (!params.is_object()) return false;
  bool wrote = false;
  for (const auto& [name, value] : values.items())
    if (!params.contains(name)) {
      params[name] = value;
      wrote = true;
    }
  return wrote;
}

// The defaults a new volume pins (SynthesisParams), and the ones volumes stored before each
// was pinned were synthesized with: typicality did not exist (0), fine levels ran two
// correction passes, the coarsest level started from slabs, output colors were means, the
// finest level ran 8 subpasses per pass, usage penalties were not applied, the finest level
// matched with the same typicality as the others, slab subparts were cubes (init_band 0), and
// the finest level matched whole triples (finest_match triple). finest_sources has always been
// square by default; it is pinned so that a later default cannot change a stored volume.
json current_defaults() {
  const json all = to_json(SynthesisParams{});
  json pinned = json::object();
  for (const char* key : {"typicality", "balance", "passes", "init", "color", "finest_subpass_size", "finest_typicality_scale",
                          "init_band", "finest_match", "finest_sources"})
    pinned[key] = all.at(key);
  return pinned;
}
json legacy_defaults() {
  return {{"typicality", 0.0}, {"passes", 2}, {"init", "slab"}, {"color", "mean"},
          {"finest_subpass_size", 2}, {"balance", 0.0}, {"finest_typicality_scale", 1.0},
          {"init_band", 0}, {"finest_match", "triple"}, {"finest_sources", "square"}};
}

}  // namespace

Result<std::shared_ptr<Volume>> VolumeService::Impl::load_stored(const std::string& id) {
  SOLIDTEX_ASSIGN_OR_RETURN(std::string text, store.read_text(ResourceKind::kVolume, id, "volume.json"));
  SOLIDTEX_ASSIGN_OR_RETURN(json info, parse_json_text(text, "volume.json"));
  json spec = info["spec"];
  // Volumes stored before a default was pinned keep the value they were synthesized with.
  if (pin_params(spec, legacy_defaults())) {
    info["spec"] = spec;
    info["params"] = spec["params"];
  }
  json desc;
  SOLIDTEX_ASSIGN_OR_RETURN(auto v, parse_spec(spec, nullptr, &desc));
  if (info["field"].value("kind", "") == "stored") {  // checked now, loaded at the first query
    SOLIDTEX_RETURN_IF_ERROR(load_stored_field(id).status());
    v->inline_field = nullptr;
  }
  SOLIDTEX_ASSIGN_OR_RETURN(const bool has_mesh, store.exists(ResourceKind::kVolume, id, "mesh.source"));
  if (v->label && v->label->kind == RegionLabel::Kind::kSurfaceShell && !has_mesh)
    return Status(StatusCode::kCorrupt, "the volume's mesh copy is missing", "mesh.source");
  v->info = info;
  return v;
}

Status VolumeService::start(std::vector<std::string>* report) {
  SOLIDTEX_ASSIGN_OR_RETURN(std::vector<std::string> ids, impl_->store.ids(ResourceKind::kVolume));
  for (const std::string& id : ids) {
    auto v = impl_->load_stored(id);
    if (!v && v.status().code() == StatusCode::kUnavailable) return v.status();
    if (!v) {
      if (report) report->push_back("skipped volume " + id + ": " + v.status().to_string());
      continue;
    }
    impl_->volumes.emplace(id, *v);
  }
  if (impl_->config.idle_evict_s > 0 && !impl_->sweeper.joinable())
    impl_->sweeper = std::thread([this] { impl_->sweep_loop(); });
  return Status::ok();
}

Result<json> VolumeService::create(const std::string& spec_text) {
  SOLIDTEX_ASSIGN_OR_RETURN(json spec, parse_json_text(spec_text, "body"));
  if (spec.contains("id")) return Status(StatusCode::kInvalidArgument, "unknown key", "id");
  pin_params(spec, current_defaults());
  std::vector<uint8_t> field_bytes;
  json field_desc;
  SOLIDTEX_ASSIGN_OR_RETURN(auto v, impl_->parse_spec(spec, &field_bytes, &field_desc));
  std::shared_ptr<const FrameField> field = v->inline_field;
  if (!field_bytes.empty()) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto stored, decode_field(field_bytes));
    SOLIDTEX_ASSIGN_OR_RETURN(field, QuatGridField::create(stored.origin, stored.spacing, stored.dims, stored.nodes, stored.log_scales));
  }
  SOLIDTEX_RETURN_IF_ERROR(impl_->check_exemplars_ready(*v));
  std::vector<uint8_t> mesh_bytes;
  std::shared_ptr<const SurfaceDistance> surface;
  if (v->label && v->label->kind == RegionLabel::Kind::kSurfaceShell) {
    const json& ms = spec["regions"]["mesh"];
    const std::string mesh_id = ms["id"].get<std::string>();
    SOLIDTEX_RETURN_IF_ERROR(impl_->meshes.mesh(mesh_id).status());  // 404 when unknown
    SOLIDTEX_ASSIGN_OR_RETURN(mesh_bytes, impl_->store.read(ResourceKind::kMesh, mesh_id, "source.mesh"));
    SOLIDTEX_ASSIGN_OR_RETURN(surface, impl_->build_surface(*v, ms, mesh_bytes));
  }
  const std::string id = Storage::new_id("vol_");
  SOLIDTEX_RETURN_IF_ERROR(impl_->store.create(ResourceKind::kVolume, id));
  v->info = {{"id", id},
             {"name", spec.value("name", "")},
             {"exemplars", v->exemplar_ids},
             {"label", spec.contains("regions") ? spec["regions"]["label"] : json("")},
             {"field", field_desc},
             {"field_description", field->describe()},
             {"seed", v->seed},
             {"params", v->params_spec},
             {"spec", spec}};
  // Write-once, like every file of a volume: a fresh id, never rewritten.
  Status st = field_bytes.empty() ? Status::ok()
                                  : impl_->store.create_new(ResourceKind::kVolume, id, "field.stf", field_bytes).status();
  if (st.is_ok() && !mesh_bytes.empty())
    st = impl_->store.create_new(ResourceKind::kVolume, id, "mesh.source", mesh_bytes).status();
  if (st.is_ok()) st = impl_->store.create_new_text(ResourceKind::kVolume, id, "volume.json", v->info.dump()).status();
  if (!st.is_ok()) {
    impl_->store.remove(ResourceKind::kVolume, id);
    return st;
  }
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    impl_->volumes.emplace(id, v);
    impl_->touch(*v);
  }
  if (surface) {
    // The band was built to check the label: keep it as the volume's loaded state rather than
    // building it again at the first query (a failure here is reported by that query instead).
    std::lock_guard<std::mutex> b(v->build_mutex);
    if (auto built = impl_->build_state(*v, surface, field)) impl_->install(v, *built, false);
  }
  json out = v->info;
  out.erase("spec");
  return out;
}

Result<json> VolumeService::get(const std::string& id) const {
  SOLIDTEX_ASSIGN_OR_RETURN(auto v, impl_->find(id));
  json out = v->info;
  out.erase("spec");
  return out;
}

json VolumeService::list() const {
  impl_->sync_all();
  std::lock_guard<std::mutex> g(impl_->mutex);
  json out = json::array();
  for (const auto& [id, v] : impl_->volumes) {
    json j = v->info;
    j.erase("spec");
    out.push_back(j);
  }
  return {{"volumes", out}};
}

Status VolumeService::remove(const std::string& id) {
  SOLIDTEX_RETURN_IF_ERROR(impl_->find(id).status());
  std::shared_ptr<VolumeState> dropped;
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    auto it = impl_->volumes.find(id);
    if (it == impl_->volumes.end()) return Status(StatusCode::kNotFound, "no volume '" + id + "'", "id");
    SOLIDTEX_RETURN_IF_ERROR(impl_->store.remove(ResourceKind::kVolume, id));
    dropped = std::move(it->second->state);  // running queries keep their shared_ptr until they finish
    it->second->state.reset();
    impl_->volumes.erase(it);
  }
  dropped.reset();
  impl_->rebalance_cache();
  return Status::ok();
}

bool VolumeService::uses_exemplar(const std::string& exemplar_id) const {
  impl_->sync_all();  // volumes created through other replicas count too
  std::lock_guard<std::mutex> g(impl_->mutex);
  for (const auto& [id, v] : impl_->volumes)
    for (const auto& e : v->exemplar_ids)
      if (e == exemplar_id) return true;
  return false;
}

Status VolumeService::check_target_size(int64_t samples, const std::string& field) const {
  if (samples > impl_->config.max_voxels)
    return Status(StatusCode::kUnprocessable,
                  "asks for " + std::to_string(samples) + " samples; the limit per request is " +
                      std::to_string(impl_->config.max_voxels) + " (--max-voxels)",
                  field);
  return Status::ok();
}

Result<VolumeService::ArrayInfo> VolumeService::array_info(const std::string& id) {
  SOLIDTEX_ASSIGN_OR_RETURN(const Impl::Hold held, impl_->hold(id));
  const auto& v = held.volume;
  const auto& state = held.state;
  ArrayInfo out;
  out.levels = state->regions ? 1 : state->synths[0]->table().levels();
  out.tag = fnv1a_hex(v->info["spec"].dump());  // the spec's canonical dump (sorted keys)
  return out;
}

Result<VoxelSampling> VolumeService::preferred_voxel_sampling(const std::string& id) {
  SOLIDTEX_ASSIGN_OR_RETURN(const Impl::Hold held, impl_->hold(id));
  return held.state->sampling;
}

Result<QueryResult> VolumeService::query(const std::string& id, const std::string& kind, const TargetSet& target,
                                         Interrupter& interrupter, int level) {
  SOLIDTEX_ASSIGN_OR_RETURN(const Impl::Hold held, impl_->hold(id));
  const auto& v = held.volume;
  const auto& state = held.state;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<SynthesisStats> per_region;
  QueryResult out;
  SynthesisOptions options;
  options.max_bytes = impl_->config.max_request_bytes;
  options.level = level;
  // What a refusal for size names: the request's own field.
  options.target_field = kind == "points" ? "points" : kind == "surface" ? "mesh" : "size";
  if (state->regions && level >= 0) return Status(StatusCode::kNotFound, "region volumes serve the finest level only", "level");
  if (state->regions) {
    SOLIDTEX_ASSIGN_OR_RETURN(out.rgb, state->regions->synthesize(target, interrupter, &per_region, options));
  } else {
    per_region.resize(1);
    SOLIDTEX_ASSIGN_OR_RETURN(out.rgb, state->synths[0]->synthesize(target, interrupter, &per_region[0], options));
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const SynthesisStats& s : per_region) out.voxels_synthesized += s.voxels;
  impl_->voxels_total += out.voxels_synthesized;
  std::lock_guard<std::mutex> g(v->stats_mutex);
  ++v->requests;
  for (const SynthesisStats& s : per_region)
    for (const LevelStats& l : s.levels) {
      if (v->voxels_per_level.size() <= size_t(l.level)) v->voxels_per_level.resize(size_t(l.level) + 1, 0);
      v->voxels_per_level[size_t(l.level)] += l.voxels;
    }
  out.stats = stats_json(kind, target, per_region, seconds);
  v->recent.push_back(out.stats);
  if (v->recent.size() > kRecentRequests) v->recent.pop_front();
  return out;
}

Result<json> VolumeService::stats(const std::string& id) const {
  SOLIDTEX_ASSIGN_OR_RETURN(auto v, impl_->find(id));
  std::shared_ptr<VolumeState> st;
  json state;
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    st = v->state;
    state = {{"loaded", bool(st)},
             {"bytes", st ? st->bytes() : 0},
             {"synthesizer_bytes", st ? st->synthesizer_bytes : 0},
             {"table_bytes", st ? st->tables_bytes() : 0},
             {"field_bytes", st ? st->field_bytes : 0},
             {"surface_bytes", st ? st->surface_bytes : 0},
             {"active_requests", v->active},
             {"loads", v->loads},
             {"evictions", v->evictions},
             {"idle_seconds", v->active > 0 ? 0.0 : std::chrono::duration<double>(Clock::now() - v->last_used).count()}};
  }
  json cache = {{"bytes", 0}, {"budget_bytes", 0}, {"hits", 0}, {"misses", 0}, {"bricks", 0}, {"evicted_bricks", 0}};
  std::vector<int64_t> cached;
  if (st)
    for (const auto& s : st->synths) {
      const VoxelCache::Counters c = s->cache().counters();
      cache["bytes"] = cache["bytes"].get<int64_t>() + c.bytes;
      cache["budget_bytes"] = cache["budget_bytes"].get<int64_t>() + s->cache().budget_bytes();
      cache["hits"] = cache["hits"].get<int64_t>() + c.hits;
      cache["misses"] = cache["misses"].get<int64_t>() + c.misses;
      cache["bricks"] = cache["bricks"].get<int64_t>() + c.bricks;
      cache["evicted_bricks"] = cache["evicted_bricks"].get<int64_t>() + c.evicted_bricks;
      if (cached.size() < c.voxels_per_level.size()) cached.resize(c.voxels_per_level.size(), 0);
      for (size_t l = 0; l < c.voxels_per_level.size(); ++l) cached[l] += c.voxels_per_level[l];
    }
  int64_t cached_total = 0;
  for (int64_t n : cached) cached_total += n;
  cache["bytes_per_voxel"] = cached_total > 0 ? double(cache["bytes"].get<int64_t>()) / double(cached_total) : 0.0;
  std::lock_guard<std::mutex> g(v->stats_mutex);
  json levels = json::array();
  for (size_t l = 0; l < std::max(cached.size(), v->voxels_per_level.size()); ++l)
    levels.push_back({{"level", l},
                      {"voxels_synthesized", l < v->voxels_per_level.size() ? v->voxels_per_level[l] : 0},
                      {"cached_voxels", l < cached.size() ? cached[l] : 0}});
  return json{{"volume", id}, {"levels", levels}, {"cache", cache}, {"state", state}, {"requests", v->requests},
              {"recent", json(std::vector<json>(v->recent.begin(), v->recent.end()))}};
}

int64_t VolumeService::cache_bytes() const {
  int64_t bytes = 0;
  for (auto& s : impl_->live_synthesizers()) bytes += s->cache().counters().bytes;
  return bytes;
}

VolumeStateTotals VolumeService::state_totals() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  VolumeStateTotals t;
  t.bytes = impl_->state_bytes_locked();
  t.budget_bytes = impl_->config.volume_state_bytes;
  for (const auto& [id, v] : impl_->volumes) t.loaded += v->state ? 1 : 0;
  t.loads = impl_->loads_total;
  t.evicted_budget = impl_->evicted_budget;
  t.evicted_idle = impl_->evicted_idle;
  return t;
}

int64_t VolumeService::voxels_synthesized() const { return impl_->voxels_total.load(); }

}  // namespace solidtex::server
