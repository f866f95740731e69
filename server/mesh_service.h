// Stored meshes: the uploaded bytes (so a stored mesh and the same bytes sent inline decode to
// the same doubles), a summary with the defects the reader tolerated, and decoded meshes
// cached in memory. Uploads are decoded before anything is stored, so a bad mesh stores
// nothing. Reads go through the store (several replicas on one data directory, README): a mesh
// stored through another replica is loaded, one deleted through another answers 404.
// Thread-safe.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <string>

#include "storage.h"
#include "mesh/mesh.h"
#include "server_config.h"

namespace solidtex::server {

nlohmann::json mesh_summary(const Mesh& mesh);

class MeshService {
 public:
  MeshService(Storage& store, const ServerConfig& config);
  ~MeshService();
  Status start(std::vector<std::string>* report);
  Result<nlohmann::json> upload(std::span<const uint8_t> bytes, const std::string& name);
  Result<nlohmann::json> get(const std::string& id) const;
  nlohmann::json list() const;
  Status remove(const std::string& id);
  Result<std::shared_ptr<const Mesh>> mesh(const std::string& id);
  // Decodes inline mesh bytes with the service's limits.
  Result<Mesh> decode(std::span<const uint8_t> bytes) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace solidtex::server
