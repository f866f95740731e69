#include "static_files.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

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
