#include "mesh_service.h"

#include <algorithm>
#include <map>
#include <mutex>

#include "core/json_fields.h"

namespace solidtex::server {

using nlohmann::json;

json mesh_summary(const Mesh& m) {
  const MeshBounds b = m.bounds();
  const MeshDefects& d = m.defects;
  return {{"format", m.format},
          {"vertices", int64_t(m.vertices.size())},
          {"triangles", int64_t(m.triangles.size())},
          {"bounds", {{"min", b.min}, {"max", b.max}}},
          {"defects",
           {{"duplicate_faces", d.duplicate_faces},
            {"degenerate_faces", d.degenerate_faces},
            {"unreferenced_vertices", d.unreferenced_vertices},
            {"boundary_edges", d.boundary_edges},
            {"non_manifold_edges", d.non_manifold_edges},
            {"components", d.components},
            {"polygons_triangulated", d.polygons_triangulated}}}};
}

struct MeshService::Impl {
  Storage& store;
  ServerConfig config;
  mutable std::mutex mutex;
  std::map<std::string, json> meta;
  std::map<std::string, std::shared_ptr<const Mesh>> decoded;
  Impl(Storage& s, const ServerConfig& c) : store(s), config(c) {}

  // Read-through (mutex held; several replicas on one data directory): loads a mesh stored
  // through another replica, drops one deleted through another. False: no such mesh; an
  // error: the store could not be read, unless this replica knows the mesh: then true, and
  // it is served as known (meshes are write-once; at worst one deleted elsewhere answers
  // until the store is back).
  // `listed`: a listing just showed it acknowledged.
  Result<bool> sync_locked(const std::string& id, std::vector<std::string>* report = nullptr, bool listed = false) {
    if (!Storage::valid_id(id)) return false;
    auto it = meta.find(id);
    bool acknowledged = listed;
    if (!acknowledged) {
      Result<bool> stored = store.acknowledged(ResourceKind::kMesh, id);
      if (!stored && stored.status().code() == StatusCode::kUnavailable && it != meta.end()) return true;
      SOLIDTEX_ASSIGN_OR_RETURN(acknowledged, std::move(stored));
    }
    if (!acknowledged) {
      if (it != meta.end()) meta.erase(it);
      decoded.erase(id);
      return false;
    }
    if (it != meta.end()) return true;
    auto text = store.read_text(ResourceKind::kMesh, id, "meta.json");
    auto j = text ? parse_json_text(*text, "meta.json") : Result<json>(text.status());
    if (!j) {
      if (j.status().code() == StatusCode::kUnavailable) return j.status();  // the store's failure
      if (report) report->push_back("skipped mesh " + id + ": " + j.status().to_string());
      return false;
    }
    meta.emplace(id, *j);
    return true;
  }
  // A list shows what this replica knows when the store cannot be read (MeshService::list).
  void sync_all_locked() {
    auto ids = ids_to_sync(store, ResourceKind::kMesh, meta);
    if (!ids) return;
    for (const std::string& id : ids->listed) (void)sync_locked(id, nullptr, true);
    for (const std::string& id : ids->unlisted) (void)sync_locked(id);
  }
};

MeshService::MeshService(Storage& store, const ServerConfig& config) : impl_(std::make_unique<Impl>(store, config)) {}
MeshService::~MeshService() = default;

Status MeshService::start(std::vector<std::string>* report) {
  std::lock_guard<std::mutex> g(impl_->mutex);
  SOLIDTEX_ASSIGN_OR_RETURN(std::vector<std::string> ids, impl_->store.ids(ResourceKind::kMesh));
  for (const std::string& id : ids) SOLIDTEX_RETURN_IF_ERROR(impl_->sync_locked(id, report, true).status());
  return Status::ok();
}

Result<Mesh> MeshService::decode(std::span<const uint8_t> bytes) const { return decode_mesh(bytes, impl_->config.mesh_limits); }

Result<json> MeshService::upload(std::span<const uint8_t> bytes, const std::string& name) {
  SOLIDTEX_ASSIGN_OR_RETURN(Mesh m, decode(bytes));
  const std::string id = Storage::new_id("mesh_");
  json j = mesh_summary(m);
  j["id"] = id;
  j["name"] = name;
  SOLIDTEX_RETURN_IF_ERROR(impl_->store.create(ResourceKind::kMesh, id));
  Status st = impl_->store.create_new(ResourceKind::kMesh, id, "source.mesh", bytes).status();
  if (st.is_ok()) st = impl_->store.create_new_text(ResourceKind::kMesh, id, "meta.json", j.dump()).status();
  if (!st.is_ok()) {
    impl_->store.remove(ResourceKind::kMesh, id);
    return st;
  }
  std::lock_guard<std::mutex> g(impl_->mutex);
  impl_->meta.emplace(id, j);
  impl_->decoded.emplace(id, std::make_shared<const Mesh>(std::move(m)));
  return j;
}

Result<json> MeshService::get(const std::string& id) const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  SOLIDTEX_ASSIGN_OR_RETURN(bool found, impl_->sync_locked(id));
  if (!found) return Status(StatusCode::kNotFound, "no mesh '" + id + "'", "id");
  return impl_->meta.at(id);
}

json MeshService::list() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  impl_->sync_all_locked();
  json out = json::array();
  for (const auto& [id, j] : impl_->meta) out.push_back(j);
  return {{"meshes", out}};
}

Status MeshService::remove(const std::string& id) {
  std::lock_guard<std::mutex> g(impl_->mutex);
  SOLIDTEX_ASSIGN_OR_RETURN(bool found, impl_->sync_locked(id));
  if (!found) return Status(StatusCode::kNotFound, "no mesh '" + id + "'", "id");
  auto it = impl_->meta.find(id);
  SOLIDTEX_RETURN_IF_ERROR(impl_->store.remove(ResourceKind::kMesh, id));
  impl_->meta.erase(it);
  impl_->decoded.erase(id);
  return Status::ok();
}

Result<std::shared_ptr<const Mesh>> MeshService::mesh(const std::string& id) {
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    SOLIDTEX_ASSIGN_OR_RETURN(bool found, impl_->sync_locked(id));
    if (!found) return Status(StatusCode::kNotFound, "no mesh '" + id + "'", "mesh");
    auto it = impl_->decoded.find(id);
    if (it != impl_->decoded.end()) return it->second;
  }
  SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, impl_->store.read(ResourceKind::kMesh, id, "source.mesh"));
  SOLIDTEX_ASSIGN_OR_RETURN(Mesh m, decode(bytes));
  auto shared = std::make_shared<const Mesh>(std::move(m));
  std::lock_guard<std::mutex> g(impl_->mutex);
  impl_->decoded.emplace(id, shared);
  return shared;
}

}  // namespace solidtex::server
