#include "data_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/byte_io.h"
#include "core/image_io.h"

namespace fs = std::filesystem;

namespace solidtex::server {
namespace {

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
    const fs::path dir = fs::path(store->root_) / kind_dir(kind);
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
  fs::path p = fs::path(root_) / kind_dir(kind) / id;
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
  if (!valid_id(id)) return Status(StatusCode::kInvalidArgument, "malformed id '" + id + "'", "id");
  return write_file_atomic(path(kind, id, file), bytes);
}

namespace {

Status errno_status(const std::string& what, const std::string& path) {
  return Status(StatusCode::kIo, what + " '" + path + "': " + std::strerror(errno));
}

Result<std::vector<uint8_t>> read_fd(int fd, const std::string& path, int64_t max_bytes) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return errno_status("cannot stat", path);
  if (st.st_size > max_bytes)
    return Status(StatusCode::kTooLarge, "'" + path + "' has " + std::to_string(st.st_size) + " bytes, more than " +
                                             std::to_string(max_bytes));
  std::vector<uint8_t> out(size_t(st.st_size));
  size_t off = 0;
  while (off < out.size()) {
    const ssize_t n = ::pread(fd, out.data() + off, out.size() - off, off_t(off));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return errno_status("cannot read", path);
    if (n == 0) break;
    off += size_t(n);
  }
  out.resize(off);
  return out;
}

// The current file at `path`, opened and exclusively flock()ed, verified to still be the one
// the name refers to (a replace renames a new file over the name; a remove unlinks it).
// Closing the descriptor releases the lock. kNotFound when there is no file.
class LockedFile {
 public:
  ~LockedFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  Status lock(const std::string& path) {
    for (;;) {
      fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
      if (fd_ < 0) {
        if (errno == ENOENT) return Status(StatusCode::kNotFound, "no file '" + path + "'");
        return errno_status("cannot open", path);
      }
      while (::flock(fd_, LOCK_EX) != 0)
        if (errno != EINTR) return errno_status("cannot lock", path);
      struct stat held {}, named {};
      if (::fstat(fd_, &held) != 0) return errno_status("cannot stat", path);
      if (::stat(path.c_str(), &named) == 0 && named.st_ino == held.st_ino && named.st_dev == held.st_dev)
        return Status::ok();
      ::close(fd_);  // replaced or removed while we waited: look again
      fd_ = -1;
    }
  }
  int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

Status etag_mismatch(const std::string& path) {
  return Status(StatusCode::kFailedPrecondition, "'" + path + "' was changed by another writer");
}

}  // namespace

std::string DataStore::etag_of(std::span<const uint8_t> bytes) {
  uint64_t h = 1469598103934665603ull;  // FNV-1a
  for (uint8_t b : bytes) h = (h ^ b) * 1099511628211ull;
  static const char* hex = "0123456789abcdef";
  std::string out(16, '0');
  for (int i = 0; i < 16; ++i) out[size_t(i)] = hex[(h >> (4 * (15 - i))) & 15];
  return out;
}

Result<std::string> DataStore::create_new(ResourceKind kind, const std::string& id, const std::string& file,
                                          std::span<const uint8_t> bytes) {
  if (!valid_id(id)) return Status(StatusCode::kInvalidArgument, "malformed id '" + id + "'", "id");
  const std::string target = path(kind, id, file);
  SOLIDTEX_ASSIGN_OR_RETURN(std::string tmp, write_temporary_file(target, bytes));
  // link() never replaces: the name appears with its whole content, or not at all.
  const int rc = ::link(tmp.c_str(), target.c_str());
  const int err = errno;
  ::unlink(tmp.c_str());
  if (rc != 0) {
    if (err == EEXIST) return Status(StatusCode::kAlreadyExists, "'" + target + "' exists");
    errno = err;
    return errno_status("cannot create", target);
  }
  sync_parent_directory(target);
  return etag_of(bytes);
}

Result<std::string> DataStore::replace_if_match(ResourceKind kind, const std::string& id, const std::string& file,
                                                std::span<const uint8_t> bytes, const std::string& etag) {
  if (!valid_id(id)) return Status(StatusCode::kInvalidArgument, "malformed id '" + id + "'", "id");
  const std::string target = path(kind, id, file);
  LockedFile current;
  if (Status st = current.lock(target); !st.is_ok())
    return st.code() == StatusCode::kNotFound ? etag_mismatch(target) : st;
  SOLIDTEX_ASSIGN_OR_RETURN(auto old, read_fd(current.fd(), target, int64_t(1) << 32));
  if (etag_of(old) != etag) return etag_mismatch(target);
  SOLIDTEX_ASSIGN_OR_RETURN(std::string tmp, write_temporary_file(target, bytes));
  if (::rename(tmp.c_str(), target.c_str()) != 0) {
    Status st = errno_status("cannot replace", target);
    ::unlink(tmp.c_str());
    return st;
  }
  sync_parent_directory(target);
  return etag_of(bytes);
}

Status DataStore::remove_if_match(ResourceKind kind, const std::string& id, const std::string& file,
                                  const std::string& etag) {
  if (!valid_id(id)) return Status(StatusCode::kNotFound, "no such resource '" + id + "'", "id");
  const std::string target = path(kind, id, file);
  LockedFile current;
  SOLIDTEX_RETURN_IF_ERROR(current.lock(target));
  SOLIDTEX_ASSIGN_OR_RETURN(auto old, read_fd(current.fd(), target, int64_t(1) << 32));
  if (etag_of(old) != etag) return etag_mismatch(target);
  if (::unlink(target.c_str()) != 0) return errno_status("cannot remove", target);
  sync_parent_directory(target);
  return Status::ok();
}

Result<std::vector<uint8_t>> DataStore::read(ResourceKind kind, const std::string& id, const std::string& file,
                                             int64_t max_bytes) const {
  if (!valid_id(id)) return Status(StatusCode::kNotFound, "no such resource '" + id + "'", "id");
  return read_file_bytes(path(kind, id, file), max_bytes);
}

Result<VersionedObject> DataStore::read_versioned(ResourceKind kind, const std::string& id, const std::string& file,
                                                  int64_t max_bytes) const {
  if (!valid_id(id)) return Status(StatusCode::kNotFound, "no such resource '" + id + "'", "id");
  const std::string p = path(kind, id, file);
  const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) return Status(StatusCode::kNotFound, "no file '" + p + "'");
    return errno_status("cannot open", p);
  }
  VersionedObject out;
  auto bytes = read_fd(fd, p, max_bytes);
  struct stat st {};
  const bool stat_ok = ::fstat(fd, &st) == 0;
  ::close(fd);
  if (!bytes) return bytes.status();
  out.bytes = std::move(*bytes);
  out.etag = etag_of(out.bytes);
  if (stat_ok) {
    const auto now = std::chrono::system_clock::now().time_since_epoch();
    out.age_seconds = std::chrono::duration<double>(now).count() - (double(st.st_mtim.tv_sec) + 1e-9 * double(st.st_mtim.tv_nsec));
  }
  return out;
}

Result<bool> DataStore::exists(ResourceKind kind, const std::string& id, const std::string& file) const {
  std::error_code ec;
  if (!valid_id(id)) return false;
  const bool there = fs::exists(path(kind, id, file), ec);
  if (ec) return Status(StatusCode::kIo, "cannot look at '" + path(kind, id, file) + "': " + ec.message());
  return there;
}

Result<std::vector<std::string>> DataStore::files(ResourceKind kind, const std::string& id) const {
  std::vector<std::string> out;
  if (!valid_id(id)) return out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(path(kind, id), ec)) {
    const std::string name = e.path().filename().string();
    if (!is_temporary(name)) out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

Result<std::vector<std::string>> DataStore::ids(ResourceKind kind) const {
  std::vector<std::string> out;
  std::error_code ec;
  const fs::path dir = fs::path(root_) / kind_dir(kind);
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (valid_id(name) && fs::exists(e.path() / acknowledging_file(kind))) out.push_back(name);
  }
  if (ec) return Status(StatusCode::kIo, "cannot list '" + dir.string() + "': " + ec.message());
  std::sort(out.begin(), out.end());
  return out;
}

Status DataStore::remove(ResourceKind kind, const std::string& id) {
  if (!valid_id(id)) return Status(StatusCode::kNotFound, "no such resource '" + id + "'", "id");
  const fs::path from = path(kind, id);
  const fs::path trash = fs::path(root_) / kind_dir(kind) / (".trash-" + id);
  std::error_code ec;
  fs::rename(from, trash, ec);  // the acknowledging file goes with the directory, atomically
  if (ec) return Status(StatusCode::kIo, "cannot delete '" + from.string() + "': " + ec.message());
  fs::remove_all(trash, ec);  // a failure here leaves a .trash- leftover that open() removes
  return Status::ok();
}

}  // namespace solidtex::server
