// The browser app's files (web/, issue #15) read from one directory, the web root: GET / is its
// index.html and GET /web/{file} any other file directly in it (routes.cpp). Contract:
// - A name is served only if it is a plain file name: 1 to 128 characters of [A-Za-z0-9_.-],
//   not starting with '.', so that no name can leave the root ("..", "a/b", "%2e%2e", hidden
//   files) whatever the HTTP layer decoded; and only if it is a regular file, not a symbolic
//   link (a link could point out of the root) nor a directory or FIFO. Anything else, and a file
//   that cannot be opened or read, is kNotFound (never kIo: the web routes answer 404, not 500).
// - Files are read at every request (they are small; edits show at the next reload) through one
//   descriptor opened with O_NOFOLLOW: its fstat decides (regular, size), so nothing can be
//   swapped between the checks and the read. At most kMaxFileBytes are served (kTooLarge beyond,
//   also for a file that grows while read).
// - The content type comes from the extension (text/html, text/javascript for ES modules,
//   text/css, ...; application/octet-stream when unknown); the ETag is strong and made of the
//   bytes (FNV-1a 64), so it is the same across restarts and changes with the file.
#pragma once

#include <cstdint>
#include <string>

#include "core/status.h"

namespace solidtex::server {

struct StaticFile {
  std::string content_type;
  std::string etag;  // quoted
  std::string body;
};

class StaticFiles {
 public:
  static constexpr int64_t kMaxFileBytes = int64_t(8) << 20;

  // `root`: the web root; empty serves nothing (every name is kNotFound, saying so).
  explicit StaticFiles(std::string root);

  Result<StaticFile> read(const std::string& name) const;
  const std::string& root() const { return root_; }

  static bool is_plain_name(const std::string& name);
  static std::string content_type_for(const std::string& name);

 private:
  std::string root_;
};

// The web/ directory of the source tree this binary was built from when it exists (so that
// `solidtex serve` from a build tree serves the app without flags), else "".
std::string default_web_root();

}  // namespace solidtex::server
