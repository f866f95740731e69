// Volumes: a solid texture defined by one exemplar table (or two split by a region label), a
// frame field and synthesis parameters, queried lazily by cuts, boxes and points.
//
// A volume is immutable: volume.json keeps the spec as given, and a stored field is copied
// into the volume (field.stf) at creation, and so is the mesh of a surface-distance label
// (mesh.source; regions {"label": "surface:D", "mesh": {"id", "placement"}}).
// Loaded state: what a volume keeps between queries outside its voxel cache (its tables, its
// field, a surface label's distance band, its synthesizers and their voxel caches) is built at
// its first query (a surface volume's at creation, which builds the band anyway) and counted
// (stats()' "state"; state_totals()). Loaded volumes are evicted least recently used first when
// their total passes --volume-state-mb, and when idle for --idle-evict-s; a state that a running
// request uses is never evicted (requests hold it by shared_ptr). An evicted volume is rebuilt
// at its next query. The service-wide cache budget (--cache-mb) is split evenly over the live
// synthesizers. Because synthesis is spatially deterministic, a query answers the same bits
// whichever request, order, thread count, cache state or eviction computed its voxels, and the
// same as `solidtex slice` with the same table, field, parameters and seed.
// Reads go through the store (several replicas on one data directory, README): a volume created
// through another replica is loaded at its first access here, one deleted through another
// answers 404 (and its loaded state is dropped).
// Thread-safe: queries on one volume run concurrently (the synthesizer is thread-safe).
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "storage.h"
#include "exemplar_service.h"
#include "field_service.h"
#include "mesh_service.h"
#include "core/interrupter.h"
#include "server_config.h"
#include "synthesis/target.h"

namespace solidtex::server {

struct QueryResult {
  std::vector<std::array<float, 3>> rgb;  // linear RGB per target sample
  int64_t voxels_synthesized = 0;         // over all levels and regions (0: all cached)
  nlohmann::json stats;                   // this request's entry in stats()' "recent"
};

// Loaded volumes over the whole service (/metrics).
struct VolumeStateTotals {
  int64_t bytes = 0;         // resident state of the loaded volumes (a shared table counts once)
  int64_t budget_bytes = 0;  // --volume-state-mb
  int64_t loaded = 0;        // volumes whose state is loaded
  int64_t loads = 0;         // states built since start
  int64_t evicted_budget = 0, evicted_idle = 0;  // evictions since start, by reason
};

class VolumeService {
 public:
  VolumeService(Storage& store, const ServerConfig& config, ExemplarService& exemplars, FieldService& fields,
                MeshService& meshes);
  ~VolumeService();

  Status start(std::vector<std::string>* report);
  Result<nlohmann::json> create(const std::string& spec_json);
  Result<nlohmann::json> get(const std::string& id) const;
  nlohmann::json list() const;
  Status remove(const std::string& id);
  bool uses_exemplar(const std::string& exemplar_id) const;

  // Bounded by --max-request-mb (kUnprocessable). --max-voxels bounds the sizes clients choose:
  // the handlers check it (check_target_size, naming their field) before building a target; the
  // array views' chunks are their fixed 32^3 unit, which every array client must be able to read.
  // `level`: the pyramid level of the target's voxels (SynthesisOptions::level; -1 finest).
  Result<QueryResult> query(const std::string& id, const std::string& kind, const TargetSet& target,
                            Interrupter& interrupter, int level = -1);
  // What the chunked-array views need: the synthesis levels served (region volumes serve the
  // finest only: their labels are defined on finest voxels) and a tag that changes whenever the
  // volume's voxels could (a hash of its stored spec: exemplars, field, seed, pinned params).
  struct ArrayInfo {
    int levels = 1;
    std::string tag;
  };
  Result<ArrayInfo> array_info(const std::string& id);
  // What resample "auto" stands for in this volume's plane cuts and points: its tables' preferred
  // sampling (synthesis/voxel_sampling.h), worked out once per loaded state.
  Result<VoxelSampling> preferred_voxel_sampling(const std::string& id);
  Status check_target_size(int64_t samples, const std::string& field) const;
  Result<nlohmann::json> stats(const std::string& id) const;

  int64_t cache_bytes() const;
  int64_t voxels_synthesized() const;
  VolumeStateTotals state_totals() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace solidtex::server
