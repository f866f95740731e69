// Volumes: a solid texture defined by one exemplar table (or two split by a region label), a
// frame field and synthesis parameters, queried lazily by cuts, boxes and points.
//
// A volume is immutable: volume.json keeps the spec as given, and a stored field is copied
// into the volume (field.stf) at creation, and so is the mesh of a surface-distance label
// (mesh.source; regions {"label": "surface:D", "mesh": {"id", "placement"}}). Synthesizers (and their voxel caches) are built at
// the first query and kept; the service-wide cache budget (--cache-mb) is split evenly over
// the live synthesizers. Because synthesis is spatially deterministic, a query answers the
// same bits whichever request, order, thread count or cache state computed its voxels, and the
// same as `solidtex slice` with the same table, field, parameters and seed.
// Thread-safe: queries on one volume run concurrently (the synthesizer is thread-safe).
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "data_store.h"
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

class VolumeService {
 public:
  VolumeService(DataStore& store, const ServerConfig& config, ExemplarService& exemplars, FieldService& fields,
                MeshService& meshes);
  ~VolumeService();

  Status start(std::vector<std::string>* report);
  Result<nlohmann::json> create(const std::string& spec_json);
  Result<nlohmann::json> get(const std::string& id) const;
  nlohmann::json list() const;
  Status remove(const std::string& id);
  bool uses_exemplar(const std::string& exemplar_id) const;

  // kUnprocessable when the target has more samples than --max-voxels (checked by callers
  // before building big targets too, see check_target_size).
  Result<QueryResult> query(const std::string& id, const std::string& kind, const TargetSet& target,
                            Interrupter& interrupter);
  Status check_target_size(int64_t samples, const std::string& field) const;
  Result<nlohmann::json> stats(const std::string& id) const;

  int64_t cache_bytes() const;
  int64_t voxels_synthesized() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace solidtex::server
