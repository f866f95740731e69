#include "static_files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "array_etag.h"

#ifndef SOLIDTEX_WEB_ROOT
#error "SOLIDTEX_WEB_ROOT (the source tree's web/ directory) is defined by server/CMakeLists.txt"
#endif

namespace solidtex::server {

namespace fs = std::filesystem;

StaticFiles::StaticFiles(std::string root) : root_(std::move(root)) {}

bool StaticFiles::is_plain_name(const std::string& name) {
  if (name.empty() || name.size() > 128 || name.front() == '.') return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' ||
                    c == '-';
    if (!ok) return false;
  }
  return true;
}

std::string StaticFiles::content_type_for(const std::string& name) {
  const auto dot = name.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : name.substr(dot + 1);
  // Browsers run ES modules only when served with a JavaScript MIME type.
  if (ext == "html") return "text/html; charset=utf-8";
  if (ext == "js" || ext == "mjs") return "text/javascript; charset=utf-8";
  if (ext == "css") return "text/css; charset=utf-8";
  if (ext == "json") return "application/json";
  if (ext == "svg") return "image/svg+xml";
  if (ext == "png") return "image/png";
  if (ext == "txt" || ext == "md") return "text/plain; charset=utf-8";
  return "application/octet-stream";
}

namespace {

// Closes a descriptor on every return path.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

Result<StaticFile> StaticFiles::read(const std::string& name) const {
  if (root_.empty()) return Status(StatusCode::kNotFound, "this server has no web app (--web-root)", "path");
  const auto not_found = [&](const std::string& why) {
    return Status(StatusCode::kNotFound, "no file '" + name + "' in the web app" + why, "path");
  };
  if (!is_plain_name(name)) return not_found("");
  const std::string path = (fs::path(root_) / name).string();
  // One descriptor answers every question, so that what is checked is what is read (no gap for
  // a rename or a new link between them): O_NOFOLLOW refuses a symbolic link (it could point out
  // of the root), O_NONBLOCK keeps a FIFO from blocking this thread until a writer appears, and
  // fstat of the open file says whether it is a regular file and how long it is. A file that
  // cannot be opened or read is answered 404 like a missing one, never 500.
  Fd f{::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK)};
  if (f.fd < 0) return not_found(errno == ENOENT ? "" : std::string(" (") + std::strerror(errno) + ")");
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) return not_found(std::string(" (") + std::strerror(errno) + ")");
  if (!S_ISREG(st.st_mode)) return not_found(" (not a regular file)");
  const auto too_large = [&] {
    return Status(StatusCode::kTooLarge, "'" + name + "' is larger than " + std::to_string(kMaxFileBytes) + " bytes", "path");
  };
  if (int64_t(st.st_size) > kMaxFileBytes) return too_large();
  // At most one byte more than allowed, so that a file that grew since fstat is caught too.
  StaticFile out;
  out.body.resize(size_t(st.st_size) + 1);
  size_t got = 0;
  while (true) {
    if (got == out.body.size()) {
      if (int64_t(got) > kMaxFileBytes) return too_large();
      out.body.resize(std::min<size_t>(out.body.size() * 2, size_t(kMaxFileBytes) + 1));
    }
    const ssize_t n = ::read(f.fd, out.body.data() + got, out.body.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return not_found(std::string(" (") + std::strerror(errno) + ")");
    if (n == 0) break;
    got += size_t(n);
  }
  if (int64_t(got) > kMaxFileBytes) return too_large();
  out.body.resize(got);
  out.content_type = content_type_for(name);
  out.etag = "\"web-" + fnv1a_hex(out.body) + "\"";
  return out;
}

std::string default_web_root() {
  std::error_code ec;
  return fs::is_directory(SOLIDTEX_WEB_ROOT, ec) ? std::string(SOLIDTEX_WEB_ROOT) : std::string();
}

}  // namespace solidtex::server
