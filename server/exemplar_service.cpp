#include "exemplar_service.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <iostream>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

#include "synthesis/usage_balance.h"
#include "analysis/analysis.h"
#include "api_json.h"
#include "analysis/exemplar.h"
#include "core/image_io.h"
#include "core/json_fields.h"
#include "analysis/table_file.h"

namespace solidtex::server {

using nlohmann::json;

namespace {

enum class State { kQueued, kRunning, kReady, kFailed };


std::string job_id_of(const std::string& exemplar_id) { return "job_" + exemplar_id.substr(3); }

// Decoding errors of an uploaded image: the body arrived fine, its content is unusable.
Status as_upload_error(const Status& s) {
  if (s.code() == StatusCode::kTooLarge) return Status(StatusCode::kUnprocessable, s.message(), s.field());
  return s;
}

struct Entry {
  json meta;
  State state = State::kQueued;
  int percent = 0;
  Status error;
  json levels;
  int64_t table_bytes = 0;
  double seconds = 0;
  std::weak_ptr<const Table> table;  // decoded, while a loaded volume holds it
  bool cancel = false;  // DELETE while running: the analysis stops, then the exemplar goes
  // This replica holds the job's lease: the job is in `pending` or running here. An entry
  // queued or running without it is another replica's job, watched through the store.
  bool owned = false;
};

double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string host_name() {
  char buf[256] = {0};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "";
  return buf;
}

// An acknowledged analysis runs again after a restart; one that was running when the
// process died twice (a poison pill) is marked failed instead of crash-looping the server.
constexpr int kMaxAnalysisAttempts = 2;

// How long an analysis job keeps retrying a store that cannot be reached (an S3 server
// restarting) before it fails: an acknowledged upload outlives a short outage.
constexpr auto kStoreOutageTolerance = std::chrono::seconds(120);

const Status& status_of(const Status& s) { return s; }
template <typename T>
const Status& status_of(const Result<T>& r) { return r.status(); }

}  // namespace

struct ExemplarService::Impl {
  Storage& store;
  ServerConfig config;
  mutable std::mutex mutex;
  std::condition_variable wake;
  std::condition_variable finished;  // a running analysis ended (DELETE waits on it)
  std::map<std::string, Entry> entries;
  std::deque<std::string> pending;
  std::vector<std::thread> threads;
  std::atomic<bool> stopping{false};
  int running = 0;
  // Leases (see the header): who this replica is, and the thread renewing its leases.
  const std::string replica = Storage::new_id("rep_");
  const std::string host = host_name();
  std::condition_variable renew_wake;
  std::thread renewer;

  Impl(Storage& s, const ServerConfig& c) : store(s), config(c) {}

  // --- job leases (exemplars/<id>/lease) ------------------------------------------------------

  std::string lease_text() const {
    return json{{"owner", replica}, {"host", host}, {"pid", int64_t(::getpid())},
                {"seconds", config.job_lease_s}, {"expires", wall_seconds() + config.job_lease_s}}
        .dump();
  }
  // The lease as stored: `present` false when there is none; `body` {} when unreadable.
  struct Lease {
    bool present = false;
    json body = json::object();
    std::string etag;
    double age = 0;  // seconds since it was written, by the store's clock
  };
  Result<Lease> read_lease(const std::string& id) const {
    auto v = store.read_versioned(ResourceKind::kExemplar, id, "lease");
    if (!v) {
      if (v.status().code() == StatusCode::kNotFound) return Lease{};
      return v.status();
    }
    Lease l;
    l.present = true;
    l.etag = v->etag;
    l.age = v->age_seconds;
    json j = json::parse(v->bytes.begin(), v->bytes.end(), nullptr, false);
    if (!j.is_discarded() && j.is_object()) l.body = std::move(j);
    return l;
  }
  bool ours(const Lease& lease) const { return lease.present && lease.body.value("owner", "") == replica; }
  // Nobody works on the job: no lease, one not renewed for longer than its owner's lease
  // length (its age by the store's clock, so that replicas' clocks do not enter it), or one of
  // a process on this host that is gone (kill -9, crash: so a restart on the same store need
  // not wait for the expiry).
  bool orphaned(const Lease& lease) const {
    if (!lease.present) return true;
    if (ours(lease)) return false;
    if (lease.age > lease.body.value("seconds", config.job_lease_s)) return true;
    const int64_t pid = lease.body.value("pid", int64_t(0));
    return lease.body.value("host", "") == host && pid > 0 && pid != ::getpid() && ::kill(pid_t(pid), 0) != 0 &&
           errno == ESRCH;
  }
  // Claims the job: creates the lease if there is none (create-if-absent), or replaces an
  // orphaned one only if it is unchanged since it was read (compare-and-swap on its etag).
  // Of several replicas claiming at once exactly one wins; never delete-then-create, with
  // which two could.
  bool claim(const std::string& id) {
    const std::string text = lease_text();
    auto created = store.create_new_text(ResourceKind::kExemplar, id, "lease", text);
    if (created || created.status().code() != StatusCode::kAlreadyExists) return created.is_ok();
    auto lease = read_lease(id);
    if (!lease || !orphaned(*lease)) return false;
    if (!lease->present) return store.create_new_text(ResourceKind::kExemplar, id, "lease", text).is_ok();
    return store.replace_if_match(ResourceKind::kExemplar, id, "lease", as_bytes(text), lease->etag).is_ok();
  }
  // Extends this replica's lease; false when another replica has taken the job over. A store
  // that cannot be reached right now is not a takeover: the next renewal tries again.
  bool renew(const std::string& id) {
    auto lease = read_lease(id);
    if (!lease) return true;
    if (!ours(*lease)) return false;
    auto renewed = store.replace_if_match(ResourceKind::kExemplar, id, "lease", as_bytes(lease_text()), lease->etag);
    return renewed.is_ok() || renewed.status().code() != StatusCode::kFailedPrecondition;
  }
  void release(const std::string& id) {
    auto lease = read_lease(id);
    if (lease && ours(*lease)) (void)store.remove_if_match(ResourceKind::kExemplar, id, "lease", lease->etag);
  }

  void renew_loop() {
    const auto period = std::chrono::duration<double>(config.job_lease_s / 3);
    std::unique_lock<std::mutex> lock(mutex);
    while (!stopping.load()) {
      renew_wake.wait_for(lock, period, [&] { return stopping.load(); });
      if (stopping.load()) return;
      for (auto& [id, e] : entries) {
        if (!e.owned || (e.state != State::kQueued && e.state != State::kRunning)) continue;
        if (renew(id)) continue;
        // Taken over (this replica stalled past its lease): a queued job is left to the new
        // owner; a running one finishes here too (the same result, written twice).
        if (e.state == State::kQueued) {
          pending.erase(std::remove(pending.begin(), pending.end(), id), pending.end());
          e.owned = false;
          e.state = State::kRunning;
        }
      }
    }
  }

  // --- the store as the truth: read-through ---------------------------------------------------

  // Brings the entry of `id` up to date with the store (mutex held): loads an acknowledged
  // exemplar this replica has not seen (uploaded through another replica), drops one whose
  // directory is gone (deleted through another replica), takes up another replica's result,
  // and claims a job nobody works on (adopt_locked). Null: no such exemplar; an error: the
  // store could not be read (nothing changed), unless this replica knows the exemplar: then
  // its entry as this replica knows it (a job running here keeps answering its progress).
  // `listed`: a listing just showed it acknowledged.
  Result<Entry*> sync_locked(const std::string& id, std::vector<std::string>* report = nullptr, bool listed = false) {
    if (!Storage::valid_id(id)) return nullptr;
    auto it = entries.find(id);
    bool acknowledged = listed;
    if (!acknowledged) {
      Result<bool> stored = store.acknowledged(ResourceKind::kExemplar, id);
      if (!stored && stored.status().code() == StatusCode::kUnavailable && it != entries.end()) return &it->second;
      SOLIDTEX_ASSIGN_OR_RETURN(acknowledged, std::move(stored));
    }
    if (it != entries.end()) {
      Entry& e = it->second;
      if (!acknowledged) {  // deleted elsewhere
        if (e.owned && e.state == State::kRunning) {  // the worker ends it, then it goes
          e.cancel = true;
          return nullptr;
        }
        pending.erase(std::remove(pending.begin(), pending.end(), id), pending.end());
        entries.erase(it);
        return nullptr;
      }
      if (!e.owned && (e.state == State::kQueued || e.state == State::kRunning)) adopt_locked(id, e, report);
      return &e;
    }
    if (!acknowledged) return nullptr;
    auto text = store.read_text(ResourceKind::kExemplar, id, "meta.json");
    auto meta = text ? parse_json_text(*text, "meta.json") : Result<json>(text.status());
    if (!meta) {
      if (meta.status().code() == StatusCode::kUnavailable) return meta.status();  // the store's failure
      if (report) report->push_back("skipped exemplar " + id + ": " + meta.status().to_string());
      return nullptr;
    }
    Entry fresh;
    fresh.meta = *meta;
    fresh.state = State::kRunning;
    Entry& e = entries.emplace(id, std::move(fresh)).first->second;
    adopt_locked(id, e, report);
    return &e;
  }

  // An entry whose job this replica does not hold: the stored result when there is one, else
  // the job itself when nobody works on it (orphaned), else left to its owner. A store that
  // cannot be read leaves the entry as it is until the next look.
  void adopt_locked(const std::string& id, Entry& e, std::vector<std::string>* report) {
    auto say = [&](const std::string& line) {
      if (report) report->push_back(line);
      else std::cerr << "solidtex serve: " << line << "\n";
    };
    const auto has_result = store.exists(ResourceKind::kExemplar, id, "result.json");
    if (!has_result) return;
    if (*has_result) {
      auto r = store.read_text(ResourceKind::kExemplar, id, "result.json");
      auto record = r ? parse_json_text(*r, "result.json") : Result<json>(r.status());
      if (record) {
        apply_result(e, *record);
      } else {
        e.state = State::kFailed;
        e.error = record.status();
      }
      return;
    }
    e.state = State::kRunning;  // another replica's, as far as this one knows
    const auto lease = read_lease(id);
    if (!lease || !orphaned(*lease)) return;
    // The owner writes the result before it releases the lease, so a lease missing now may be a
    // job that finished since the look above: look for its result again before taking it over.
    if (!lease->present) {
      const auto finished = store.exists(ResourceKind::kExemplar, id, "result.json");
      if (!finished) return;
      if (*finished) return adopt_locked(id, e, report);
    }
    if (attempts(id) >= kMaxAnalysisAttempts) {
      const json record{{"error", status_json(Status(StatusCode::kInternal,
                                                     "the analysis was interrupted " + std::to_string(kMaxAnalysisAttempts) +
                                                         " times by a server crash; it is not retried"))}};
      (void)store.write_text(ResourceKind::kExemplar, id, "result.json", record.dump());
      apply_result(e, record);
      say("marked the analysis of exemplar " + id + " failed: it crashed the server before");
      return;
    }
    if (!claim(id)) return;
    e.owned = true;
    e.state = State::kQueued;
    e.percent = 0;
    pending.push_back(id);
    wake.notify_one();
    say((report ? "re-queued the analysis of exemplar " : "took over the analysis of exemplar ") + id +
        " (its lease was missing or had expired)");
  }

  // Every exemplar of the store, and none that is gone from it (mutex held); what this replica
  // knows when the store cannot be listed (ExemplarService::list).
  void sync_all_locked() {
    auto ids = ids_to_sync(store, ResourceKind::kExemplar, entries);
    if (!ids) return;
    for (const std::string& id : ids->listed) (void)sync_locked(id, nullptr, true);
    for (const std::string& id : ids->unlisted) (void)sync_locked(id);
  }

  // `max_bytes` > 0: the analysis cost limit, checked as the images are decoded (uploads).
  Result<ExemplarSet> build_set(const std::vector<std::pair<std::string, std::vector<uint8_t>>>& parts,
                                const std::string& grain, float mask_weight, AnalysisParams& params,
                                int64_t max_bytes = 0, std::string* applied_grain = nullptr) const {
    ExemplarInputs in;
    bool have_xy = false, have_mask = false;
    for (const auto& [name, bytes] : parts) {
      if (name != "xy" && name != "yz" && name != "zx" && name != "mask" && name != "mask_yz" && name != "mask_zx")
        return Status(StatusCode::kInvalidArgument, "unknown part (expected xy, yz, zx, mask, mask_yz, mask_zx)", name);
      have_mask = have_mask || name.rfind("mask", 0) == 0;
    }
    // The analysis cost model is linear in the planes' pixels: check it after each exemplar image
    // (exemplars first, masks after), so that a small body of several huge images (blank PNGs
    // compress to almost nothing) is refused after decoding one of them, never all six.
    int64_t per_pixel = 0;
    {
      ExemplarInputs tiny;
      tiny.xy = ImageF(8, 8, 3);
      if (have_mask) tiny.mask_xy = ImageF(8, 8, 3);
      // Automatic levels resolve to 1 on this 8x8 probe: fewer than any real image gets, so
      // still a lower bound; the full estimate follows once the images are decoded.
      if (auto t = ExemplarSet::create(std::move(tiny))) per_pixel = estimate_analysis_bytes(*t, params) / 64;
    }
    int64_t pixels = 0;
    std::vector<const std::pair<std::string, std::vector<uint8_t>>*> ordered;
    for (const auto& part : parts)
      if (part.first.rfind("mask", 0) != 0) ordered.push_back(&part);
    for (const auto& part : parts)
      if (part.first.rfind("mask", 0) == 0) ordered.push_back(&part);
    for (const auto* part : ordered) {
      const auto& [name, bytes] = *part;
      auto img = decode_image(bytes, config.image_limits, name);
      if (!img) return as_upload_error(img.status());
      if (name.rfind("mask", 0) != 0) {
        // grain x, y or crossed: xy in all planes (auto is known only after decoding; the full estimate follows)
        pixels += img->pixel_count() * (name == "xy" && (grain == "x" || grain == "y" || grain == "crossed") ? 3 : 1);
        if (const int64_t at_least = pixels * per_pixel; max_bytes > 0 && at_least > max_bytes)
          return Status(StatusCode::kUnprocessable,
                        "analysing this exemplar needs at least " + std::to_string(at_least >> 20) + " MB; the limit is " +
                            std::to_string(max_bytes >> 20) +
                            " MB (--max-request-mb): send a smaller image or fewer levels",
                        name);
      }
      if (name == "xy") { in.xy = std::move(*img); have_xy = true; }
      else if (name == "yz") in.yz = std::move(*img);
      else if (name == "zx") in.zx = std::move(*img);
      else if (name == "mask") in.mask_xy = std::move(*img);
      else if (name == "mask_yz") in.mask_yz = std::move(*img);
      else if (name == "mask_zx") in.mask_zx = std::move(*img);
      else return Status(StatusCode::kInvalidArgument, "unknown part (expected xy, yz, zx, mask, mask_yz, mask_zx)", name);
    }
    if (!have_xy) return Status(StatusCode::kInvalidArgument, "an exemplar image is required (part 'xy' or 'image')", "xy");
    SOLIDTEX_ASSIGN_OR_RETURN(std::string layout, apply_grain_layout(grain, in, params.suggested_plane_weights));
    if (applied_grain) *applied_grain = layout;
    in.mask_weight = mask_weight;
    auto set = ExemplarSet::create(std::move(in));
    if (!set) return Status(StatusCode::kUnprocessable, set.status().message(), set.status().field());
    return set;
  }

  json exemplar_json(const std::string& id, const Entry& e) const {
    json j = {{"id", id},
              {"name", e.meta.value("name", "")},
              {"state", e.state == State::kReady ? "ready" : e.state == State::kFailed ? "failed" : "analyzing"},
              {"job_id", job_id_of(id)},
              {"planes", e.meta.value("planes", 1)},
              {"has_mask", e.meta.value("has_mask", false)},
              {"width", e.meta.value("width", 0)},
              {"height", e.meta.value("height", 0)},
              {"grain", e.meta.value("grain", "")},
              {"params", e.meta["params"]},
              {"error", status_json(e.error)}};
    if (e.state == State::kReady) {
      j["levels"] = e.levels;
      j["table_bytes"] = e.table_bytes;
      j["seconds"] = e.seconds;
    }
    return j;
  }

  json job_json(const std::string& id, const Entry& e) const {
    const char* state = e.state == State::kQueued    ? "queued"
                        : e.state == State::kRunning ? "running"
                        : e.state == State::kReady   ? "succeeded"
                                                     : "failed";
    return {{"id", job_id_of(id)}, {"kind", "analysis"},        {"exemplar_id", id},
            {"state", state},      {"percent", e.percent},      {"seconds", e.seconds},
            {"error", status_json(e.error)}};
  }

  // Reports progress into the entry; stops when the service shuts down.
  class JobInterrupter : public Interrupter {
   public:
    JobInterrupter(Impl& impl, std::string id) : impl_(impl), id_(std::move(id)) {}
    // The job's percent spans [from, to] while the next stage reports 0..100, so progress
    // never runs backwards between analysis and usage balancing.
    void stage(int from, int to) {
      from_ = from;
      to_ = to;
    }
    bool was_interrupted(int percent) override {
      if (percent >= 0) percent = from_ + percent * (to_ - from_) / 100;
      if (percent >= 0) {
        std::lock_guard<std::mutex> g(impl_.mutex);
        auto it = impl_.entries.find(id_);
        if (it != impl_.entries.end()) it->second.percent = std::min(percent, 99);
      }
      std::lock_guard<std::mutex> g(impl_.mutex);
      auto it = impl_.entries.find(id_);
      return impl_.stopping.load() || (it != impl_.entries.end() && it->second.cancel);
    }

   private:
    Impl& impl_;
    std::string id_;
    int from_ = 0, to_ = 100;
  };

  int attempts(const std::string& id) const {
    auto text = store.read_text(ResourceKind::kExemplar, id, "attempts");
    if (!text) return 0;
    try {
      return std::stoi(*text);
    } catch (...) {
      return kMaxAnalysisAttempts;  // unreadable marker: treat as exhausted, never crash-loop
    }
  }

  bool interrupted(const std::string& id) {
    std::lock_guard<std::mutex> g(mutex);
    auto it = entries.find(id);
    return stopping.load() || it == entries.end() || it->second.cancel;
  }

  // `op` (a store read or write of job `id`), retried with backoff while the store answers
  // "unavailable" (kUnavailable), for up to kStoreOutageTolerance or until the job is
  // cancelled or the server stops. Other errors, and success, return at once.
  template <typename Op>
  auto through_outages(const std::string& id, Op&& op) -> decltype(op()) {
    const auto give_up = std::chrono::steady_clock::now() + kStoreOutageTolerance;
    auto backoff = std::chrono::milliseconds(250);
    for (bool logged = false;; backoff = std::min(backoff * 2, std::chrono::milliseconds(4000))) {
      auto r = op();
      const Status& st = status_of(r);
      if (st.code() != StatusCode::kUnavailable || std::chrono::steady_clock::now() + backoff > give_up) return r;
      if (!logged) {
        std::cerr << "analysis of exemplar " << id << ": " << st.message() << "; retrying until the store is back\n";
        logged = true;
      }
      for (auto slept = std::chrono::milliseconds(0); slept < backoff; slept += std::chrono::milliseconds(50)) {
        if (interrupted(id)) return r;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    }
  }

  // `attempt` was made durable (worker) before the job showed as running.
  void run_analysis(const std::string& id, int attempt) {
    json meta;
    {
      std::lock_guard<std::mutex> g(mutex);
      meta = entries.at(id).meta;
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto result = [&]() -> Result<json> {
      std::vector<std::pair<std::string, std::vector<uint8_t>>> parts;
      for (const auto& name : meta["parts"]) {
        SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, through_outages(id, [&] {
                                    return store.read(ResourceKind::kExemplar, id, name.get<std::string>() + ".img");
                                  }));
        parts.emplace_back(name.get<std::string>(), std::move(bytes));
      }
      SOLIDTEX_ASSIGN_OR_RETURN(AnalysisParams params, analysis_params_from_json(meta["params"], "params"));
      AnalysisParams p = params;
      SOLIDTEX_ASSIGN_OR_RETURN(ExemplarSet set, build_set(parts, meta.value("grain", ""), meta.value("mask_weight", 1.0f), p));
      JobInterrupter interrupter(*this, id);
      interrupter.stage(0, 75);
      SOLIDTEX_ASSIGN_OR_RETURN(AnalysisResult r, analyze(set, params, interrupter));
      interrupter.stage(75, 100);
      SOLIDTEX_ASSIGN_OR_RETURN(r.table, balance_usage(r.table, {}, interrupter));
      const std::vector<uint8_t> bytes = encode_table(*r.table);
      SOLIDTEX_RETURN_IF_ERROR(through_outages(id, [&] { return store.write(ResourceKind::kExemplar, id, "table.stx", bytes); }));
      return json{{"levels", to_json(r.levels)}, {"table_bytes", int64_t(bytes.size())},
                  {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
    }();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!result && stopping.load()) {  // abandoned by a clean shutdown: runs again, uncounted
      (void)store.write_text(ResourceKind::kExemplar, id, "attempts", std::to_string(attempt - 1));
      return;  // shutdown() releases the lease
    }
    {
      std::lock_guard<std::mutex> g(mutex);
      auto it = entries.find(id);
      if (it != entries.end() && it->second.cancel) return;  // DELETE removes it
    }
    json record = result ? *result : json{{"error", status_json(result.status())}, {"seconds", seconds}};
    // An exemplar deleted meanwhile has no directory any more; the write then fails harmlessly.
    const std::string text = record.dump();
    Status st = through_outages(id, [&] { return store.write_text(ResourceKind::kExemplar, id, "result.json", text); });
    std::lock_guard<std::mutex> g(mutex);
    release(id);  // the result is there: the lease has served
    auto it = entries.find(id);
    if (it == entries.end()) return;
    it->second.owned = false;
    apply_result(it->second, st.is_ok() ? record : json{{"error", status_json(st)}});
  }

  void apply_result(Entry& e, const json& record) {
    e.seconds = record.value("seconds", 0.0);
    if (record.contains("error") && !record["error"].is_null()) {
      e.state = State::kFailed;
      const json& err = record["error"];
      StatusCode code = StatusCode::kInternal;
      for (int c = 1; c <= int(StatusCode::kIo); ++c)
        if (err.value("code", "") == status_code_name(StatusCode(c))) code = StatusCode(c);
      e.error = Status(code, err.value("message", ""), err.value("field", ""));
    } else {
      e.state = State::kReady;
      e.percent = 100;
      e.levels = record.value("levels", json::array());
      e.table_bytes = record.value("table_bytes", int64_t(0));
    }
  }

  void worker() {
    for (;;) {
      std::string id;
      {
        std::unique_lock<std::mutex> lock(mutex);
        wake.wait(lock, [&] { return stopping.load() || !pending.empty(); });
        if (stopping.load()) return;
        id = pending.front();
        pending.pop_front();
        if (!entries.count(id)) continue;
        ++running;  // counted against --max-jobs from here on
      }
      // Durable before the job shows as running and its work starts, so that a crash from then
      // on is counted at the next start (a client that sees "running" and kills the server has
      // used one attempt).
      const int attempt = attempts(id) + 1;
      (void)store.write_text(ResourceKind::kExemplar, id, "attempts", std::to_string(attempt));
      {
        std::lock_guard<std::mutex> g(mutex);
        auto it = entries.find(id);
        if (it == entries.end() || it->second.state != State::kQueued) {  // deleted meanwhile
          --running;
          finished.notify_all();
          continue;
        }
        it->second.state = State::kRunning;
      }
      run_analysis(id, attempt);
      std::lock_guard<std::mutex> g(mutex);
      --running;
      auto it = entries.find(id);
      if (it != entries.end() && it->second.state == State::kRunning && it->second.cancel)
        it->second.state = State::kFailed;  // cancelled; the waiting DELETE removes it
      finished.notify_all();
    }
  }
};

ExemplarService::ExemplarService(Storage& store, const ServerConfig& config)
    : impl_(std::make_unique<Impl>(store, config)) {}

ExemplarService::~ExemplarService() { shutdown(); }

Status ExemplarService::start(std::vector<std::string>* report) {
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    SOLIDTEX_ASSIGN_OR_RETURN(std::vector<std::string> ids, impl_->store.ids(ResourceKind::kExemplar));
    for (const std::string& id : ids) SOLIDTEX_RETURN_IF_ERROR(impl_->sync_locked(id, report, true).status());
  }
  for (int i = 0; i < impl_->config.analysis_threads; ++i) impl_->threads.emplace_back([this] { impl_->worker(); });
  impl_->renewer = std::thread([this] { impl_->renew_loop(); });
  return Status::ok();
}

void ExemplarService::shutdown() {
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    impl_->stopping = true;
  }
  impl_->wake.notify_all();
  impl_->renew_wake.notify_all();
  for (auto& t : impl_->threads) t.join();
  impl_->threads.clear();
  if (impl_->renewer.joinable()) impl_->renewer.join();
  // Jobs left unfinished here go back to whichever replica looks next (or to the next start).
  std::lock_guard<std::mutex> g(impl_->mutex);
  for (auto& [id, e] : impl_->entries)
    if (e.owned && (e.state == State::kQueued || e.state == State::kRunning)) {
      impl_->release(id);
      e.owned = false;
    }
}

int ExemplarService::jobs_pending() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  return int(impl_->pending.size()) + impl_->running;
}

Result<json> ExemplarService::upload(ExemplarUpload up) {
  for (auto& [name, bytes] : up.parts)
    if (name == "image") name = "xy";
  if (!(up.mask_weight >= 0 && up.mask_weight <= 10))
    return Status(StatusCode::kInvalidArgument, "must be in [0, 10]", "mask_weight");
  if (jobs_pending() >= impl_->config.max_jobs)
    return Status(StatusCode::kRateLimited,
                  std::to_string(impl_->config.max_jobs) + " analyses are already queued or running; retry later");
  AnalysisParams params = up.params;
  params.search_k = std::max(params.search_k, params.candidates / 2 + 1);
  SOLIDTEX_RETURN_IF_ERROR(params.validate());
  // "auto" is resolved here, once: the stored grain is the layout applied ("", "x", "y" or "crossed").
  std::string grain;
  SOLIDTEX_ASSIGN_OR_RETURN(ExemplarSet set, impl_->build_set(up.parts, up.grain, up.mask_weight, params,
                                                               impl_->config.max_request_bytes, &grain));
  params = resolve_levels(params, set);  // stored and analysed with the level count it resolves to
  if (const int64_t bytes = estimate_analysis_bytes(set, params); bytes > impl_->config.max_request_bytes)
    return Status(StatusCode::kUnprocessable,
                  "analysing this exemplar needs about " + std::to_string(bytes >> 20) + " MB; the limit is " +
                      std::to_string(impl_->config.max_request_bytes >> 20) +
                      " MB (--max-request-mb): send a smaller image or fewer levels",
                  "xy");

  const std::string id = Storage::new_id("ex_");
  json parts = json::array();
  SOLIDTEX_RETURN_IF_ERROR(impl_->store.create(ResourceKind::kExemplar, id));
  for (const auto& [name, bytes] : up.parts) {
    SOLIDTEX_RETURN_IF_ERROR(impl_->store.create_new(ResourceKind::kExemplar, id, name + ".img", bytes).status());
    parts.push_back(name);
  }
  // The job's lease before the acknowledgement: no other replica ever sees this job unclaimed.
  if (!impl_->claim(id)) {
    impl_->store.remove(ResourceKind::kExemplar, id);
    return Status(StatusCode::kIo, "cannot create the analysis lease of '" + id + "'");
  }
  const ImageF& xy = set.plane(Plane::kXY);
  Entry e;
  e.owned = true;
  e.meta = {{"id", id},
            {"name", up.name},
            {"params", to_json(params)},
            {"grain", grain},
            {"mask_weight", up.mask_weight},
            {"parts", parts},
            {"planes", set.shared() ? 1 : 3},
            {"has_mask", set.has_mask()},
            {"width", xy.width},
            {"height", xy.height}};
  Status st = impl_->store.create_new_text(ResourceKind::kExemplar, id, "meta.json", e.meta.dump()).status();
  if (!st.is_ok()) {
    impl_->store.remove(ResourceKind::kExemplar, id);
    return st;
  }
  std::lock_guard<std::mutex> g(impl_->mutex);
  // Replaces a copy a concurrent read may have loaded from the store since meta.json was written
  // (that copy would not know this replica holds the job).
  const Entry& stored = impl_->entries.insert_or_assign(id, std::move(e)).first->second;
  impl_->pending.push_back(id);
  impl_->wake.notify_one();
  return json{{"exemplar", impl_->exemplar_json(id, stored)}, {"job", impl_->job_json(id, stored)}};
}

Result<json> ExemplarService::get(const std::string& id) const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  SOLIDTEX_ASSIGN_OR_RETURN(const Entry* e, impl_->sync_locked(id));
  if (!e) return Status(StatusCode::kNotFound, "no exemplar '" + id + "'", "id");
  return impl_->exemplar_json(id, *e);
}

json ExemplarService::list() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  impl_->sync_all_locked();
  json out = json::array();
  for (const auto& [id, e] : impl_->entries) out.push_back(impl_->exemplar_json(id, e));
  return {{"exemplars", out}};
}

Result<json> ExemplarService::job(const std::string& job_id) const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  if (job_id.rfind("job_", 0) == 0) {
    const std::string id = "ex_" + job_id.substr(4);
    SOLIDTEX_ASSIGN_OR_RETURN(const Entry* e, impl_->sync_locked(id));
    if (e) return impl_->job_json(id, *e);
  }
  return Status(StatusCode::kNotFound, "no job '" + job_id + "'", "id");
}

Status ExemplarService::remove(const std::string& id, const std::function<bool(const std::string&)>& in_use) {
  std::unique_lock<std::mutex> g(impl_->mutex);
  SOLIDTEX_ASSIGN_OR_RETURN(const Entry* found, impl_->sync_locked(id));
  if (!found) return Status(StatusCode::kNotFound, "no exemplar '" + id + "'", "id");
  auto it = impl_->entries.find(id);
  // Another replica's job is not stopped from here: its owner notices the directory is gone
  // (its writes fail harmlessly) and drops the exemplar at its next look.
  if (!it->second.owned) {
  } else if (it->second.state == State::kQueued) {  // never started: just drop it from the queue
    auto& q = impl_->pending;
    q.erase(std::remove(q.begin(), q.end(), id), q.end());
  } else if (it->second.state == State::kRunning) {  // cancel, and wait until the worker lets go
    it->second.cancel = true;
    const bool ended = impl_->finished.wait_for(g, std::chrono::seconds(30), [&] {
      auto e = impl_->entries.find(id);
      return e == impl_->entries.end() || e->second.state != State::kRunning;
    });
    if (!ended) return Status(StatusCode::kResourceExhausted, "the analysis of '" + id + "' is still stopping; retry", "id");
    it = impl_->entries.find(id);
    if (it == impl_->entries.end()) return Status::ok();
  }
  if (in_use(id)) return Status(StatusCode::kFailedPrecondition, "exemplar '" + id + "' is used by a volume", "id");
  SOLIDTEX_RETURN_IF_ERROR(impl_->store.remove(ResourceKind::kExemplar, id));
  impl_->entries.erase(it);
  return Status::ok();
}

Status ExemplarService::check_ready(const std::string& id) const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  SOLIDTEX_ASSIGN_OR_RETURN(const Entry* e, impl_->sync_locked(id));
  if (!e) return Status(StatusCode::kNotFound, "no exemplar '" + id + "'", "exemplar");
  if (e->state != State::kReady)
    return Status(StatusCode::kFailedPrecondition, "exemplar '" + id + "' is not ready", "exemplar");
  return Status::ok();
}

Result<std::shared_ptr<const Table>> ExemplarService::table(const std::string& id) {
  {
    SOLIDTEX_RETURN_IF_ERROR(check_ready(id));
    std::lock_guard<std::mutex> g(impl_->mutex);
    auto it = impl_->entries.find(id);
    if (it != impl_->entries.end())
      if (auto held = it->second.table.lock()) return held;
  }
  // Decoding (Table::assemble rebuilds stacks) runs outside the lock.
  SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, table_bytes(id));
  SOLIDTEX_ASSIGN_OR_RETURN(auto table, decode_table(bytes));
  std::lock_guard<std::mutex> g(impl_->mutex);
  auto it = impl_->entries.find(id);
  if (it == impl_->entries.end()) return table;
  if (auto held = it->second.table.lock()) return held;  // decoded meanwhile by another request
  it->second.table = table;
  return table;
}

Result<std::vector<uint8_t>> ExemplarService::table_bytes(const std::string& id) const {
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    SOLIDTEX_ASSIGN_OR_RETURN(const Entry* e, impl_->sync_locked(id));
    if (!e) return Status(StatusCode::kNotFound, "no exemplar '" + id + "'", "id");
    if (e->state != State::kReady)
      return Status(StatusCode::kFailedPrecondition, "exemplar '" + id + "' is not ready", "id");
  }
  return impl_->store.read(ResourceKind::kExemplar, id, "table.stx");
}

}  // namespace solidtex::server
