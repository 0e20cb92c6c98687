// The browser client's files: request targets → files under the web root,
// with no way out of it, and their content types.
#pragma once

#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <string_view>

namespace haarcast::net {

// The path part of a request target ("/a/b.js?x=1" → "/a/b.js"), and a query
// parameter's value, percent-decoded ("" when absent).
std::string_view targetPath(std::string_view target);
std::string queryParameter(std::string_view target, std::string_view name);
std::optional<std::string> percentDecode(std::string_view s);  // nullopt on a bad escape or a NUL

// The regular file a GET of `path` serves from `root` ("/" → index.html), or
// nullopt: not found, not a regular file, or outside the root after
// canonicalising ("..", symlinks out, encoded traversal).
std::optional<std::filesystem::path> resolveStaticFile(const std::filesystem::path& root, std::string_view path);

// The browser client as served: the web root and the files its
// served_files.txt names (one path per line relative to the root, '#'
// comments), so that only the built client goes out — never node_modules,
// package.json or dotfiles that happen to sit in the same folder.
inline constexpr const char* kServedFilesName = "served_files.txt";

struct WebRoot {
  std::filesystem::path root;
  std::set<std::string> files;  // '/'-separated paths relative to the root

  // Reads root/served_files.txt; throws std::invalid_argument naming the
  // file and line when it is missing or names an absolute path, a '..' or a
  // dotfile. A listed file that is absent (vendor/ before `npm ci`) is a 404.
  static WebRoot load(const std::filesystem::path& root);
  // The file a GET of `path` serves ("/" → index.html), or nullopt when it
  // is not on the list (or not a regular file under the root).
  std::optional<std::filesystem::path> resolve(std::string_view path) const;
};

// Content type by extension ("application/octet-stream" when unknown).
std::string_view contentType(const std::filesystem::path& file);

}  // namespace haarcast::net
