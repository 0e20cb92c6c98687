#include "haarcast/net/static_files.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace haarcast::net {

namespace fs = std::filesystem;

std::string_view targetPath(std::string_view target) {
  const auto q = target.find_first_of("?#");
  return q == std::string_view::npos ? target : target.substr(0, q);
}

std::optional<std::string> percentDecode(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  for (std::size_t i = 0; i < s.size(); ++i) {
    char c = s[i];
    if (c == '%') {
      if (i + 2 >= s.size()) return std::nullopt;  // "%" or "%4" at the end
      const int hi = hex(s[i + 1]), lo = hex(s[i + 2]);
      if (hi < 0 || lo < 0) return std::nullopt;
      c = static_cast<char>(hi * 16 + lo);
      i += 2;
    } else if (c == '+') {
      c = ' ';
    }
    if (c == '\0') return std::nullopt;
    out.push_back(c);
  }
  return out;
}

std::string queryParameter(std::string_view target, std::string_view name) {
  const auto q = target.find('?');
  if (q == std::string_view::npos) return {};
  std::string_view query = target.substr(q + 1);
  if (const auto hash = query.find('#'); hash != std::string_view::npos) query = query.substr(0, hash);
  while (!query.empty()) {
    const auto amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    const auto eq = pair.find('=');
    if (pair.substr(0, eq) == name) {
      if (eq == std::string_view::npos) return {};
      return percentDecode(pair.substr(eq + 1)).value_or(std::string{});
    }
    if (amp == std::string_view::npos) break;
    query = query.substr(amp + 1);
  }
  return {};
}

std::optional<fs::path> resolveStaticFile(const fs::path& root, std::string_view path) {
  const auto decoded = percentDecode(path);
  if (!decoded || decoded->empty() || decoded->front() != '/') return std::nullopt;
  std::string relative = decoded->substr(1);
  if (relative.empty() || relative.back() == '/') relative += "index.html";
  std::error_code ec;
  const fs::path base = fs::canonical(root, ec);
  if (ec) return std::nullopt;
  // canonical() resolves "..", "." and symlinks, so the prefix test below is
  // on the real location of the file.
  const fs::path file = fs::canonical(base / fs::path(relative), ec);
  if (ec) return std::nullopt;
  const auto [rootEnd, fileIt] = std::mismatch(base.begin(), base.end(), file.begin(), file.end());
  if (rootEnd != base.end()) return std::nullopt;
  if (!fs::is_regular_file(file, ec)) return std::nullopt;
  return file;
}

WebRoot WebRoot::load(const fs::path& root) {
  WebRoot web;
  web.root = root;
  const fs::path list = root / kServedFilesName;
  std::ifstream in(list);
  if (!in) {
    throw std::invalid_argument("web root " + root.string() + " has no " + kServedFilesName +
                                " (the list of the client's files to serve, one per line)");
  }
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    if (line.empty() || line.front() == '#') continue;
    const std::string where = list.string() + ":" + std::to_string(number) + ": \"" + line + "\" ";
    const fs::path relative(line);
    if (relative.is_absolute()) throw std::invalid_argument(where + "is absolute (paths are relative to the web root)");
    for (const auto& part : relative) {
      if (part.string().empty() || part.string().front() == '.') {
        throw std::invalid_argument(where + "has a '.'-component (no dotfiles, no '..')");
      }
    }
    web.files.insert(relative.generic_string());
  }
  if (!web.files.count("index.html")) throw std::invalid_argument(list.string() + " does not list index.html");
  return web;
}

std::optional<fs::path> WebRoot::resolve(std::string_view path) const {
  const auto decoded = percentDecode(path);
  if (!decoded || decoded->empty() || decoded->front() != '/') return std::nullopt;
  std::string relative = decoded->substr(1);
  if (relative.empty()) relative = "index.html";
  if (!files.count(relative)) return std::nullopt;
  return resolveStaticFile(root, "/" + relative);
}

std::string_view contentType(const fs::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".html" || ext == ".htm") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json" || ext == ".map") return "application/json";
  if (ext == ".proto" || ext == ".txt" || ext == ".md") return "text/plain; charset=utf-8";
  if (ext == ".png") return "image/png";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".ico") return "image/x-icon";
  if (ext == ".wasm") return "application/wasm";
  return "application/octet-stream";
}

}  // namespace haarcast::net
