#include "static_files.h"

#include <filesystem>
#include <fstream>
#include <iterator>
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

Result<StaticFile> StaticFiles::read(const std::string& name) const {
  if (root_.empty()) return Status(StatusCode::kNotFound, "this server has no web app (--web-root)", "path");
  if (!is_plain_name(name)) return Status(StatusCode::kNotFound, "no file '" + name + "' in the web app", "path");
  const fs::path path = fs::path(root_) / name;
  std::error_code ec;
  // symlink_status: a link is not followed, so it is not a regular file here.
  const fs::file_status st = fs::symlink_status(path, ec);
  if (ec || !fs::is_regular_file(st)) return Status(StatusCode::kNotFound, "no file '" + name + "' in the web app", "path");
  const auto size = fs::file_size(path, ec);
  if (ec) return Status(StatusCode::kIo, "cannot read '" + name + "': " + ec.message(), "path");
  if (int64_t(size) > kMaxFileBytes)
    return Status(StatusCode::kTooLarge, "'" + name + "' is larger than " + std::to_string(kMaxFileBytes) + " bytes", "path");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status(StatusCode::kIo, "cannot open '" + name + "'", "path");
  StaticFile f;
  f.body.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) return Status(StatusCode::kIo, "cannot read '" + name + "'", "path");
  f.content_type = content_type_for(name);
  f.etag = "\"web-" + fnv1a_hex(f.body) + "\"";
  return f;
}

std::string default_web_root() {
  std::error_code ec;
  return fs::is_directory(SOLIDTEX_WEB_ROOT, ec) ? std::string(SOLIDTEX_WEB_ROOT) : std::string();
}

}  // namespace solidtex::server
