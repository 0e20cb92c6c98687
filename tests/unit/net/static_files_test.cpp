#include "haarcast/net/static_files.h"

#include <fstream>

#include <gtest/gtest.h>

#include "../test_files.h"

namespace haarcast::net {
namespace {

namespace fs = std::filesystem;

TEST(StaticFiles, ServesFilesUnderTheRootOnly) {
  const haarcast::testing::TempDir dir("haarcast-static-");
  const fs::path base = dir.path();
  fs::create_directories(base / "web" / "js");
  std::ofstream(base / "web" / "index.html") << "<html>";
  std::ofstream(base / "web" / "js" / "app.js") << "x";
  std::ofstream(base / "secret.txt") << "secret";
  fs::create_symlink(base / "secret.txt", base / "web" / "link.txt");
  const fs::path root = base / "web";

  EXPECT_EQ(resolveStaticFile(root, "/"), fs::canonical(root / "index.html"));
  EXPECT_EQ(resolveStaticFile(root, "/js/app.js"), fs::canonical(root / "js" / "app.js"));
  EXPECT_EQ(resolveStaticFile(root, "/js/"), std::nullopt);  // no index.html there
  EXPECT_EQ(resolveStaticFile(root, "/../secret.txt"), std::nullopt);
  EXPECT_EQ(resolveStaticFile(root, "/js/../../secret.txt"), std::nullopt);
  EXPECT_EQ(resolveStaticFile(root, "/%2e%2e/secret.txt"), std::nullopt);
  EXPECT_EQ(resolveStaticFile(root, "/link.txt"), std::nullopt);  // a symlink out of the root
  EXPECT_EQ(resolveStaticFile(root, "/missing.js"), std::nullopt);
  EXPECT_EQ(resolveStaticFile(root, "/index.html%00.js"), std::nullopt);
  EXPECT_EQ(resolveStaticFile(root, "relative"), std::nullopt);
}

TEST(StaticFiles, TargetsQueriesAndTypes) {
  EXPECT_EQ(targetPath("/ws?token=a%20b"), "/ws");
  EXPECT_EQ(queryParameter("/ws?x=1&token=a%20b", "token"), "a b");
  EXPECT_EQ(queryParameter("/ws?tokens=1", "token"), "");
  EXPECT_EQ(percentDecode("%zz"), std::nullopt);
  EXPECT_EQ(percentDecode("%4"), std::nullopt);
  EXPECT_EQ(contentType("a/index.HTML"), "text/html; charset=utf-8");
  EXPECT_EQ(contentType("app.js"), "text/javascript; charset=utf-8");
  EXPECT_EQ(contentType("x.css"), "text/css; charset=utf-8");
  EXPECT_EQ(contentType("haarcast.proto"), "text/plain; charset=utf-8");
  EXPECT_EQ(contentType("blob"), "application/octet-stream");
}

}  // namespace
}  // namespace haarcast::net
