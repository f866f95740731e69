#include "core/byte_io.h"

#include <atomic>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>

#include "core/hash.h"

namespace solidtex {

uint64_t checksum64(std::span<const uint8_t> data) {
  uint64_t h = mix64(data.size() ^ 0x5354584348454b53ull);
  size_t i = 0;
  for (; i + 8 <= data.size(); i += 8) {
    uint64_t w = 0;
    for (int b = 0; b < 8; ++b) w |= uint64_t(data[i + b]) << (8 * b);
    h = mix64(h ^ w) + 0x9e3779b97f4a7c15ull;
  }
  uint64_t w = 0;
  for (int b = 0; i < data.size(); ++i, ++b) w |= uint64_t(data[i]) << (8 * b);
  return mix64(h ^ w);
}

Result<std::string> write_temporary_file(const std::string& target, std::span<const uint8_t> bytes) {
  namespace fs = std::filesystem;
  static std::atomic<uint64_t> counter{0};
  const fs::path t(target);
  const fs::path dir = t.has_parent_path() ? t.parent_path() : fs::path(".");
  std::string name = ".";  // built by appending: GCC 12 warns falsely (-Wrestrict) about "." + std::string
  name += t.filename().string();
  name += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
  const std::string tmp = (dir / name).string();
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return Status(StatusCode::kIo, "cannot create '" + tmp + "': " + std::strerror(errno));
  size_t off = 0;
  while (off < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + off, bytes.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      Status st(StatusCode::kIo, "cannot write '" + tmp + "': " + std::strerror(errno));
      ::close(fd);
      ::unlink(tmp.c_str());
      return st;
    }
    off += size_t(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    ::unlink(tmp.c_str());
    return Status(StatusCode::kIo, "cannot sync '" + tmp + "'");
  }
  return tmp;
}

void sync_parent_directory(const std::string& file) {
  namespace fs = std::filesystem;
  const fs::path f(file);
  const fs::path dir = f.has_parent_path() ? f.parent_path() : fs::path(".");
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

Status write_file_atomic(const std::string& path, std::span<const uint8_t> bytes) {
  Result<std::string> tmp = write_temporary_file(path, bytes);
  if (!tmp) return Status(tmp.status().code(), tmp.status().message(), "output");
  if (::rename(tmp->c_str(), path.c_str()) != 0) {
    Status st(StatusCode::kIo, "cannot rename to '" + path + "': " + std::strerror(errno), "output");
    ::unlink(tmp->c_str());
    return st;
  }
  sync_parent_directory(path);
  return Status::ok();
}

}  // namespace solidtex
