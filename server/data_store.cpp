#include "data_store.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>

#include "core/byte_io.h"
#include "core/image_io.h"

namespace fs = std::filesystem;

namespace solidtex::server {
namespace {

const char* subdir(ResourceKind kind) {
  switch (kind) {
    case ResourceKind::kExemplar: return "exemplars";
    case ResourceKind::kField: return "fields";
    case ResourceKind::kVolume: return "volumes";
    case ResourceKind::kMesh: return "meshes";
  }
  return "unknown";
}

constexpr ResourceKind kKinds[] = {ResourceKind::kExemplar, ResourceKind::kField, ResourceKind::kVolume, ResourceKind::kMesh};

bool is_temporary(const std::string& name) { return name.find(".tmp-") != std::string::npos; }

// Seconds since the newest modification of `p` (and of the entries of a directory, one level:
// a resource directory being written gets new files).
double age_seconds(const fs::path& p) {
  std::error_code ec;
  auto newest = fs::last_write_time(p, ec);
  if (ec) return 1e30;
  if (fs::is_directory(p, ec))
    for (const auto& e : fs::directory_iterator(p, ec)) {
      std::error_code ec2;
      const auto t = fs::last_write_time(e.path(), ec2);
      if (!ec2 && t > newest) newest = t;
    }
  return std::chrono::duration<double>(fs::file_time_type::clock::now() - newest).count();
}

}  // namespace

const char* acknowledging_file(ResourceKind kind) {
  switch (kind) {
    case ResourceKind::kExemplar: return "meta.json";
    case ResourceKind::kField: return "r1.json";
    case ResourceKind::kVolume: return "volume.json";
    case ResourceKind::kMesh: return "meta.json";
  }
  return "";
}

Result<std::unique_ptr<DataStore>> DataStore::open(const std::string& root, std::vector<std::string>* report,
                                                   double grace_seconds) {
  std::error_code ec;
  fs::create_directories(root, ec);
  if (ec) return Status(StatusCode::kIo, "cannot create data directory '" + root + "': " + ec.message(), "--data");
  std::unique_ptr<DataStore> store(new DataStore(fs::absolute(root).string()));
  auto note = [&](const std::string& s) {
    if (report) report->push_back(s);
  };
  // Another replica on the same directory may be writing a young leftover right now.
  auto old_enough = [&](const fs::path& p) {
    if (age_seconds(p) >= grace_seconds) return true;
    note("skipped young leftover " + p.string() + " (modified within " + std::to_string(int(grace_seconds)) +
         " s: another replica may be writing it)");
    return false;
  };
  for (ResourceKind kind : kKinds) {
    const fs::path dir = fs::path(store->root_) / subdir(kind);
    fs::create_directories(dir, ec);
    if (ec) return Status(StatusCode::kIo, "cannot create '" + dir.string() + "': " + ec.message(), "--data");
    std::vector<fs::path> entries;
    for (const auto& e : fs::directory_iterator(dir, ec)) entries.push_back(e.path());
    std::sort(entries.begin(), entries.end());
    for (const fs::path& p : entries) {
      const std::string name = p.filename().string();
      const bool leftover = is_temporary(name) || name.rfind(".trash-", 0) == 0 || !fs::is_directory(p) ||
                            !valid_id(name) || !fs::exists(p / acknowledging_file(kind));
      if (leftover) {
        if (!old_enough(p)) continue;
        note("removed half-written leftover " + p.string());
        fs::remove_all(p, ec);
        continue;
      }
      for (const auto& f : fs::directory_iterator(p, ec)) {
        if (is_temporary(f.path().filename().string()) && old_enough(f.path())) {
          note("removed half-written leftover " + f.path().string());
          fs::remove(f.path(), ec);
        }
      }
    }
  }
  return store;
}

std::string DataStore::path(ResourceKind kind, const std::string& id, const std::string& file) const {
  fs::path p = fs::path(root_) / subdir(kind) / id;
  if (!file.empty()) p /= file;
  return p.string();
}

Status DataStore::create(ResourceKind kind, const std::string& id) {
  if (!valid_id(id)) return Status(StatusCode::kInvalidArgument, "malformed id '" + id + "'", "id");
  std::error_code ec;
  fs::create_directories(path(kind, id), ec);
  if (ec) return Status(StatusCode::kIo, "cannot create '" + path(kind, id) + "': " + ec.message());
  return Status::ok();
}

Status DataStore::write(ResourceKind kind, const std::string& id, const std::string& file,
                        std::span<const uint8_t> bytes) {
  return write_file_atomic(path(kind, id, file), bytes);
}

Status DataStore::write_text(ResourceKind kind, const std::string& id, const std::string& file,
                             const std::string& text) {
  return write(kind, id, file, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(text.data()), text.size()));
}

Result<std::vector<uint8_t>> DataStore::read(ResourceKind kind, const std::string& id, const std::string& file,
                                             int64_t max_bytes) const {
  return read_file_bytes(path(kind, id, file), max_bytes);
}

Result<std::string> DataStore::read_text(ResourceKind kind, const std::string& id, const std::string& file) const {
  SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, read(kind, id, file, int64_t(64) << 20));
  return std::string(bytes.begin(), bytes.end());
}

bool DataStore::exists(ResourceKind kind, const std::string& id, const std::string& file) const {
  std::error_code ec;
  return valid_id(id) && fs::exists(path(kind, id, file), ec);
}

bool DataStore::acknowledged(ResourceKind kind, const std::string& id) const {
  return exists(kind, id, acknowledging_file(kind));
}

std::vector<std::string> DataStore::files(ResourceKind kind, const std::string& id) const {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(path(kind, id), ec)) {
    const std::string name = e.path().filename().string();
    if (!is_temporary(name)) out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::string> DataStore::ids(ResourceKind kind) const {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(root_) / subdir(kind), ec)) {
    const std::string name = e.path().filename().string();
    if (valid_id(name) && fs::exists(e.path() / acknowledging_file(kind))) out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

Status DataStore::remove(ResourceKind kind, const std::string& id) {
  if (!valid_id(id)) return Status(StatusCode::kNotFound, "no such resource '" + id + "'", "id");
  const fs::path from = path(kind, id);
  const fs::path trash = fs::path(root_) / subdir(kind) / (".trash-" + id);
  std::error_code ec;
  fs::rename(from, trash, ec);
  if (ec) return Status(StatusCode::kIo, "cannot delete '" + from.string() + "': " + ec.message());
  fs::remove_all(trash, ec);  // a failure here leaves a .trash- leftover that open() removes
  return Status::ok();
}

std::string DataStore::new_id(const char* prefix) {
  static thread_local std::random_device rd;
  uint64_t v = (uint64_t(rd()) << 32) ^ uint64_t(rd());
  static const char* hex = "0123456789abcdef";
  std::string id = prefix;
  for (int i = 0; i < 16; ++i) id += hex[(v >> (4 * (15 - i))) & 15];
  return id;
}

bool DataStore::valid_id(const std::string& id) {
  if (id.size() < 4 || id.size() > 64) return false;
  return std::all_of(id.begin(), id.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

}  // namespace solidtex::server
