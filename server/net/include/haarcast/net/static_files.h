// The browser client's files: request targets → files under the web root,
// with no way out of it, and their content types.
#pragma once

#include <filesystem>
#include <optional>
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

// Content type by extension ("application/octet-stream" when unknown).
std::string_view contentType(const std::filesystem::path& file);

}  // namespace haarcast::net
