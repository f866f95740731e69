// Exemplars: uploads, their background analysis into candidate-triple tables, and the tables.
//
// upload() decodes every image (dimensions checked from the header first) and builds the
// ExemplarSet synchronously, so bad input is refused before anything is stored; then it stores
// the uploaded bytes and meta.json (the acknowledgement: see storage.h, data_store.h) and queues the
// analysis. Analyses run on `analysis_threads` threads of their own, at most `max_jobs`
// queued or running (beyond: kRateLimited). A job's id derives from its exemplar's, so a job
// survives restarts: start() re-queues every acknowledged exemplar without a result, and an
// analysis interrupted by shutdown writes nothing and runs again at the next start.
// Analysis is deterministic, so the stored table equals `solidtex analyze` on the same inputs.
//
// Several replicas on one data directory (README): the store is the truth. Every read (get,
// list, job, check_ready, table) first brings its entries up to date with the store: an
// exemplar uploaded through another replica is loaded, one deleted through another replica is
// dropped (404), and another replica's result is taken up. A job is claimed by a lease object,
// exemplars/<id>/lease ({"owner", "host", "pid", "seconds", "expires"}), through the store's
// conditional operations (storage.h): created if absent by the uploading replica before
// meta.json, renewed every third of --job-lease-seconds while the job is queued or running
// here (replace if its etag is unchanged: a replica whose lease was taken over learns it from
// the failed renewal), removed once result.json is written or at shutdown (remove if
// unchanged). A replica that finds an exemplar without result.json whose lease is missing,
// older than its owner's "seconds", or held by a process of the same host that no longer
// exists, takes the job over (create if absent, or replace if unchanged: of several replicas
// exactly one wins) and runs it. It looks at start-up and whenever a client reads that
// exemplar or its job (including lists); there is no background scan. A lease's age is
// measured by the store's clock (S3: the server's; local: the file's mtime against this
// host's clock), and hosts sharing a store need distinct names. A store that cannot be read
// answers kUnavailable (502) for reads of one exemplar; list() then shows what this
// replica knows. Thread-safe.
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "analysis/analysis_params.h"
#include "storage.h"
#include "server_config.h"
#include "analysis/table.h"

namespace solidtex::server {

struct ExemplarUpload {
  std::string name;
  AnalysisParams params;
  std::string grain = "auto";  // auto, none, x, y or crossed (exemplar.h: apply_grain_layout)
  float mask_weight = 1.0f;  // [0, 10]
  // Named parts: "xy" (required), "yz" and "zx" (both or neither), "mask", "mask_yz", "mask_zx".
  std::vector<std::pair<std::string, std::vector<uint8_t>>> parts;
};

class ExemplarService {
 public:
  ExemplarService(Storage& store, const ServerConfig& config);
  ~ExemplarService();  // shutdown()

  Status start(std::vector<std::string>* report);
  // Stops the analysis threads; a running analysis is abandoned (re-run at next start).
  void shutdown();

  Result<nlohmann::json> upload(ExemplarUpload upload);  // {"exemplar": ..., "job": ...}
  Result<nlohmann::json> get(const std::string& id) const;
  nlohmann::json list() const;
  Result<nlohmann::json> job(const std::string& job_id) const;
  // kFailedPrecondition while analysing or when `in_use(id)` says a volume needs it.
  Status remove(const std::string& id, const std::function<bool(const std::string&)>& in_use);
  // The decoded table of a ready exemplar (kFailedPrecondition otherwise). Shared while anyone
  // holds it (the loaded volumes that use it): the service keeps only a weak reference, so a
  // table no loaded volume uses is freed and decoded again (the same bits) when next asked for.
  Result<std::shared_ptr<const Table>> table(const std::string& id);
  // What table() would refuse with, without decoding anything (kNotFound, kFailedPrecondition).
  Status check_ready(const std::string& id) const;
  Result<std::vector<uint8_t>> table_bytes(const std::string& id) const;
  int jobs_pending() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace solidtex::server
