#include "static_files.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>

#include "server_config.h"

namespace fs = std::filesystem;

namespace solidtex::server {
namespace {

// A web root with an index, a module, a hidden file, a subdirectory and, outside the root, a
// secret that a traversal or a symbolic link would reach.
struct WebRoot {
  fs::path base = fs::temp_directory_path() / ("solidtex_static_" + std::to_string(::getpid()));
  fs::path root = base / "web";
  WebRoot() {
    fs::remove_all(base);
    fs::create_directories(root / "sub");
    write(root / "index.html", "<!doctype html><title>t</title>");
    write(root / "app.js", "export const x = 1;\n");
    write(root / ".hidden", "h");
    write(root / "sub" / "inner.js", "inner");
    write(base / "secret.txt", "secret");
    fs::create_symlink(base / "secret.txt", root / "link.txt");
  }
  ~WebRoot() { fs::remove_all(base); }
  static void write(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }
};

TEST(StaticFiles, ServesPlainFilesWithTheirTypeAndAContentETag) {
  WebRoot w;
  StaticFiles files(w.root.string());
  auto index = files.read("index.html");
  ASSERT_TRUE(index.is_ok()) << index.status().to_string();
  EXPECT_EQ(index->body, "<!doctype html><title>t</title>");
  EXPECT_EQ(index->content_type, "text/html; charset=utf-8");
  auto app = files.read("app.js");
  ASSERT_TRUE(app.is_ok());
  EXPECT_EQ(app->content_type, "text/javascript; charset=utf-8");
  // Strong, quoted, different per content, the same on a second read.
  EXPECT_EQ(app->etag.front(), '"');
  EXPECT_EQ(app->etag.back(), '"');
  EXPECT_NE(app->etag, index->etag);
  EXPECT_EQ(files.read("app.js")->etag, app->etag);
  WebRoot::write(w.root / "app.js", "export const x = 2;\n");
  auto edited = files.read("app.js");
  ASSERT_TRUE(edited.is_ok());
  EXPECT_EQ(edited->body, "export const x = 2;\n");
  EXPECT_NE(edited->etag, app->etag);
}

TEST(StaticFiles, RefusesNamesThatCouldLeaveTheRoot) {
  WebRoot w;
  StaticFiles files(w.root.string());
  for (const char* name : {"..", "../secret.txt", "sub/inner.js", "sub", "%2e%2e", "..%2fsecret.txt", ".hidden", "",
                           "/etc/passwd", "a\\b", "index.html/", "index.html?x", "link.txt"}) {
    auto r = files.read(name);
    ASSERT_FALSE(r.is_ok()) << name;
    EXPECT_EQ(r.status().code(), StatusCode::kNotFound) << name;
    EXPECT_EQ(r.status().field(), "path") << name;
  }
  EXPECT_FALSE(StaticFiles::is_plain_name(std::string(129, 'a')));
  EXPECT_TRUE(StaticFiles::is_plain_name(std::string(128, 'a')));
}

TEST(StaticFiles, MissingFilesAndNoRootAreNotFound) {
  WebRoot w;
  EXPECT_EQ(StaticFiles(w.root.string()).read("missing.js").status().code(), StatusCode::kNotFound);
  auto none = StaticFiles("").read("index.html");
  ASSERT_FALSE(none.is_ok());
  EXPECT_EQ(none.status().code(), StatusCode::kNotFound);
  EXPECT_NE(none.status().message().find("--web-root"), std::string::npos);
}

TEST(StaticFiles, LinksAndFilesThatCannotBeReadAreNotFoundNot500) {
  WebRoot w;
  StaticFiles files(w.root.string());
  // A link to a file inside the root is refused too (it could be re-pointed), and a dangling one.
  fs::create_symlink(w.root / "app.js", w.root / "alias.js");
  fs::create_symlink(w.base / "gone.txt", w.root / "dangling.txt");
  // A FIFO: opened without blocking (no writer ever comes), then refused as not a regular file.
  ASSERT_EQ(::mkfifo((w.root / "pipe.js").c_str(), 0644), 0);
  for (const char* name : {"alias.js", "dangling.txt", "link.txt", "pipe.js", "sub"}) {
    auto r = std::async(std::launch::async, [&] { return files.read(name); });
    if (r.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
      ::close(::open((w.root / "pipe.js").c_str(), O_WRONLY | O_NONBLOCK));  // let a blocked open return
      FAIL() << name << ": the read blocked";
    }
    const auto got = r.get();
    ASSERT_FALSE(got.is_ok()) << name;
    EXPECT_EQ(got.status().code(), StatusCode::kNotFound) << name << ": " << got.status().to_string();
    EXPECT_EQ(got.status().field(), "path") << name;
  }
  // A file without read permission (root reads it anyway: checked only for other users).
  WebRoot::write(w.root / "secret.js", "s");
  fs::permissions(w.root / "secret.js", fs::perms::none);
  if (::geteuid() != 0) EXPECT_EQ(files.read("secret.js").status().code(), StatusCode::kNotFound);
  else EXPECT_TRUE(files.read("secret.js").is_ok());
}

TEST(StaticFiles, FilesOverTheLimitAreTooLarge) {
  WebRoot w;
  StaticFiles files(w.root.string());
  WebRoot::write(w.root / "big.bin", "");
  fs::resize_file(w.root / "big.bin", StaticFiles::kMaxFileBytes + 1);  // sparse: no disk written
  EXPECT_EQ(files.read("big.bin").status().code(), StatusCode::kTooLarge);
  fs::resize_file(w.root / "big.bin", StaticFiles::kMaxFileBytes);
  auto at_limit = files.read("big.bin");
  ASSERT_TRUE(at_limit.is_ok()) << at_limit.status().to_string();
  EXPECT_EQ(int64_t(at_limit->body.size()), StaticFiles::kMaxFileBytes);
  WebRoot::write(w.root / "empty.txt", "");
  auto empty = files.read("empty.txt");
  ASSERT_TRUE(empty.is_ok());
  EXPECT_EQ(empty->body, "");
}

TEST(StaticFiles, StartupRefusesAWebRootWhoseIndexIsALink) {
  // ServerConfig::validate agrees with serving: an index.html that serving would refuse (a
  // symbolic link, even to a regular file) stops the server, naming --web-root.
  WebRoot w;
  ServerConfig config;
  config.web_root = w.root.string();
  EXPECT_TRUE(config.validate().is_ok()) << config.validate().to_string();
  fs::rename(w.root / "index.html", w.base / "index.html");
  fs::create_symlink(w.base / "index.html", w.root / "index.html");
  ASSERT_EQ(StaticFiles(w.root.string()).read("index.html").status().code(), StatusCode::kNotFound);
  const Status s = config.validate();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(s.field(), "--web-root");
  EXPECT_NE(s.message().find("symbolic link"), std::string::npos) << s.message();
  fs::remove(w.root / "index.html");
  fs::create_directory(w.root / "index.html");
  EXPECT_EQ(config.validate().field(), "--web-root");
}

TEST(StaticFiles, ContentTypesByExtension) {
  EXPECT_EQ(StaticFiles::content_type_for("style.css"), "text/css; charset=utf-8");
  EXPECT_EQ(StaticFiles::content_type_for("mod.mjs"), "text/javascript; charset=utf-8");
  EXPECT_EQ(StaticFiles::content_type_for("shot.png"), "image/png");
  EXPECT_EQ(StaticFiles::content_type_for("icon.svg"), "image/svg+xml");
  EXPECT_EQ(StaticFiles::content_type_for("data.json"), "application/json");
  EXPECT_EQ(StaticFiles::content_type_for("blob.bin"), "application/octet-stream");
  EXPECT_EQ(StaticFiles::content_type_for("README"), "application/octet-stream");
}

TEST(StaticFiles, DefaultRootIsTheSourceTreesWebDirectory) {
  // Built from this repository, whose web/ holds the app.
  const std::string root = default_web_root();
  ASSERT_FALSE(root.empty());
  EXPECT_TRUE(StaticFiles(root).read("index.html").is_ok());
}

}  // namespace
}  // namespace solidtex::server
