#include "haarcast/io/input_file.h"

#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace haarcast::io {

namespace fs = std::filesystem;

std::optional<std::string> whyNotRegularFile(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);  // follows symbolic links
  switch (status.type()) {
    case fs::file_type::regular: return std::nullopt;
    case fs::file_type::not_found: return std::string("does not exist");
    case fs::file_type::directory: return std::string("is a directory, not a regular file");
    case fs::file_type::fifo: return std::string("is a FIFO (named pipe), not a regular file");
    case fs::file_type::character: return std::string("is a character device, not a regular file");
    case fs::file_type::block: return std::string("is a block device, not a regular file");
    case fs::file_type::socket: return std::string("is a socket, not a regular file");
    default: break;
  }
  if (ec) return "cannot be looked at: " + ec.message();
  return std::string("is not a regular file");
}

void requireRegularFile(const std::string& path, const std::string& what) {
  if (auto why = whyNotRegularFile(path)) throw std::runtime_error(path + ": cannot read " + what + ": " + *why);
}

}  // namespace haarcast::io
