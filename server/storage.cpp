#include "storage.h"

#include <random>

#include "data_store.h"
#include "s3_storage.h"

namespace solidtex::server {

const char* kind_dir(ResourceKind kind) {
  switch (kind) {
    case ResourceKind::kExemplar: return "exemplars";
    case ResourceKind::kField: return "fields";
    case ResourceKind::kVolume: return "volumes";
    case ResourceKind::kMesh: return "meshes";
  }
  return "unknown";
}

const char* acknowledging_file(ResourceKind kind) {
  switch (kind) {
    case ResourceKind::kExemplar: return "meta.json";
    case ResourceKind::kField: return "r1.json";
    case ResourceKind::kVolume: return "volume.json";
    case ResourceKind::kMesh: return "meta.json";
  }
  return "";
}

std::span<const uint8_t> as_bytes(const std::string& text) {
  return {reinterpret_cast<const uint8_t*>(text.data()), text.size()};
}

Status Storage::write_text(ResourceKind kind, const std::string& id, const std::string& file, const std::string& text) {
  return write(kind, id, file, as_bytes(text));
}

Result<std::string> Storage::create_new_text(ResourceKind kind, const std::string& id, const std::string& file,
                                             const std::string& text) {
  return create_new(kind, id, file, as_bytes(text));
}

Result<std::string> Storage::read_text(ResourceKind kind, const std::string& id, const std::string& file) const {
  SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, read(kind, id, file, int64_t(64) << 20));
  return std::string(bytes.begin(), bytes.end());
}

Result<bool> Storage::acknowledged(ResourceKind kind, const std::string& id) const {
  return exists(kind, id, acknowledging_file(kind));
}

std::string Storage::new_id(const char* prefix) {
  static thread_local std::random_device rd;
  uint64_t v = (uint64_t(rd()) << 32) ^ uint64_t(rd());
  static const char* hex = "0123456789abcdef";
  std::string id = prefix;
  for (int i = 0; i < 16; ++i) id += hex[(v >> (4 * (15 - i))) & 15];
  return id;
}

bool Storage::valid_id(const std::string& id) {
  if (id.size() < 4 || id.size() > 64) return false;
  return std::all_of(id.begin(), id.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

Result<std::unique_ptr<Storage>> open_storage(const StorageConfig& config, std::vector<std::string>* report) {
  if (config.storage.empty()) {
    if (!config.s3_endpoint.empty())
      return Status(StatusCode::kInvalidArgument, "is only used with --storage s3://bucket/prefix", "--s3-endpoint");
    SOLIDTEX_ASSIGN_OR_RETURN(auto local, DataStore::open(config.data_dir, report));
    return std::unique_ptr<Storage>(std::move(local));
  }
  SOLIDTEX_ASSIGN_OR_RETURN(S3Params params, S3Params::from_environment(config.storage, config.s3_endpoint));
  SOLIDTEX_ASSIGN_OR_RETURN(auto s3, S3Storage::open(params, report));
  return std::unique_ptr<Storage>(std::move(s3));
}

}  // namespace solidtex::server
