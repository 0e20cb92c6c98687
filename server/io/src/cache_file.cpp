// The `.hccache` container (format in cache_file.h).
#include "haarcast/io/cache_file.h"

#include "haarcast/io/cache_rebuilds.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <system_error>

namespace haarcast::io {
namespace {

namespace fs = std::filesystem;

constexpr std::array<char, 8> kMagic = {'H', 'C', 'C', 'A', 'C', 'H', 'E', '\0'};

bool isValidKind(std::string_view kind) {
  if (kind.empty() || kind.size() > 64) return false;
  return std::all_of(kind.begin(), kind.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

void checkKind(std::string_view kind) {
  if (!isValidKind(kind)) {
    throw std::invalid_argument("cache kind \"" + std::string(kind) + "\" is not 1 to 64 of [a-z0-9_-]");
  }
}

std::string hex16(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

// Where the payload lies, once the header has been checked.
struct Framing {
  std::size_t payloadOffset = 0;
  std::uint64_t payloadBytes = 0;
};

// Checks `bytes` — the whole file, or only its first bytes when fileSize is
// larger — against `expected`, in the order a reader meets the fields. Returns
// why it is a miss, or "" when everything that `bytes` covers matches. The
// checksum is checked only when `bytes` is the whole file. Reads nothing
// outside `bytes`, whatever its lengths say.
std::string checkCacheBytes(std::string_view bytes, std::uint64_t fileSize, const CacheHeader& expected,
                            Framing& framing) {
  if (fileSize == 0) return "wrong size: empty file";
  if (fileSize < kCacheFileFixedBytes + kCacheFileChecksumBytes || bytes.size() < kCacheFileFixedBytes) {
    return "wrong size: " + std::to_string(fileSize) + " bytes is less than a cache file header";
  }
  if (!std::equal(kMagic.begin(), kMagic.end(), bytes.begin())) return "not a haarcast cache file (bad magic)";
  PayloadReader header(bytes.substr(kMagic.size(), kCacheFileFixedBytes - kMagic.size()));
  const auto format = header.take<std::uint32_t>();
  const auto version = header.take<std::uint32_t>();
  const auto kindBytes = header.take<std::uint32_t>();
  const auto keyBytes = header.take<std::uint32_t>();
  const auto optionsBytes = header.take<std::uint32_t>();
  const auto payloadBytes = header.take<std::uint64_t>();
  if (format != kCacheFileFormat) {
    return "container format version " + std::to_string(format) + ", this build reads " +
           std::to_string(kCacheFileFormat);
  }
  if (kindBytes > kMaxCacheText || keyBytes > kMaxCacheText || optionsBytes > kMaxCacheText) {
    return "corrupt header: a text length is over " + std::to_string(kMaxCacheText) + " bytes";
  }
  const std::size_t textEnd = kCacheFileFixedBytes + kindBytes + keyBytes + optionsBytes;
  if (fileSize < textEnd + kCacheFileChecksumBytes) {
    return "wrong size: " + std::to_string(fileSize) + " bytes is too short for the header it declares";
  }
  if (bytes.size() < textEnd) return "cannot check the header: only " + std::to_string(bytes.size()) + " bytes read";

  PayloadReader text(bytes.substr(kCacheFileFixedBytes, textEnd - kCacheFileFixedBytes));
  const std::string_view kind = text.takeBytes(kindBytes);
  const std::string_view key = text.takeBytes(keyBytes);
  const std::string_view options = text.takeBytes(optionsBytes);
  if (kind != expected.kind) {
    return "kind differs: the file holds \"" + std::string(kind) + "\", not \"" + expected.kind + "\"";
  }
  if (version != expected.version) {
    return "version " + std::to_string(version) + " of the " + expected.kind + " cache, this build reads " +
           std::to_string(expected.version);
  }
  if (key != expected.key) return "the file was built from another key";
  if (options != expected.optionsText) {
    return "options differ: the file has \"" + std::string(options) + "\", asked for \"" + expected.optionsText +
           "\"";
  }
  // textEnd + 8 ≤ fileSize here, so neither side overflows.
  if (payloadBytes != fileSize - textEnd - kCacheFileChecksumBytes) {
    return "wrong size: " + std::to_string(fileSize) + " bytes, the header says " +
           (payloadBytes > fileSize ? std::string("more")
                                    : std::to_string(textEnd + payloadBytes + kCacheFileChecksumBytes));
  }
  framing.payloadOffset = textEnd;
  framing.payloadBytes = payloadBytes;
  if (bytes.size() == fileSize) {
    const std::size_t body = bytes.size() - kCacheFileChecksumBytes;
    PayloadReader tail(bytes.substr(body));
    if (fnv1a64(bytes.substr(0, body)) != tail.take<std::uint64_t>()) return "checksum mismatch (corrupt file)";
  }
  return "";
}

void setWhyNot(std::string* whyNot, std::string reason) {
  if (whyNot) *whyNot = std::move(reason);
}

// Writes `bytes` to `path` through a temporary file in the same directory and
// a rename, which POSIX makes atomic. fsync before the rename so that after a
// power loss the name never points at blocks that were not written. The
// temporary name is unique per process and call, and O_EXCL refuses to share
// it, so concurrent writers never interleave.
void writeAtomically(const fs::path& path, std::string_view bytes) {
  static std::atomic<unsigned> counter{0};
  const fs::path temp = path.string() + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot create " + temp.string() + ": " + std::strerror(errno));
  const auto failWith = [&](const std::string& what, bool closeFirst) {
    const int err = errno;
    if (closeFirst) ::close(fd);
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw std::runtime_error(what + " " + temp.string() + ": " + std::strerror(err));
  };
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      failWith("cannot write", true);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) failWith("cannot sync", true);
  if (::close(fd) != 0) failWith("cannot close", false);
  std::error_code ec;
  fs::rename(temp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw std::runtime_error("cannot rename " + temp.string() + " to " + path.string() + ": " + ec.message());
  }
}

}  // namespace

std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash) {
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ull;
  }
  return hash;
}

std::string encodeCacheFile(const CacheHeader& header, std::string_view payload) {
  checkKind(header.kind);
  for (const std::string* text : {&header.key, &header.optionsText}) {
    if (text->size() > kMaxCacheText) {
      throw std::invalid_argument("cache file: a key or options text of " + std::to_string(text->size()) +
                                  " bytes is over " + std::to_string(kMaxCacheText));
    }
  }
  std::string out;
  out.reserve(kCacheFileFixedBytes + header.kind.size() + header.key.size() + header.optionsText.size() +
              payload.size() + kCacheFileChecksumBytes);
  out.append(kMagic.data(), kMagic.size());
  appendLittleEndian<std::uint32_t>(out, kCacheFileFormat);
  appendLittleEndian<std::uint32_t>(out, header.version);
  appendLittleEndian<std::uint32_t>(out, static_cast<std::uint32_t>(header.kind.size()));
  appendLittleEndian<std::uint32_t>(out, static_cast<std::uint32_t>(header.key.size()));
  appendLittleEndian<std::uint32_t>(out, static_cast<std::uint32_t>(header.optionsText.size()));
  appendLittleEndian<std::uint64_t>(out, payload.size());
  out += header.kind;
  out += header.key;
  out += header.optionsText;
  out += payload;
  appendLittleEndian<std::uint64_t>(out, fnv1a64(out));
  return out;
}

std::optional<std::string_view> decodeCacheFile(std::string_view bytes, const CacheHeader& expected,
                                                std::string* whyNot) {
  Framing framing;
  std::string reason = checkCacheBytes(bytes, bytes.size(), expected, framing);
  if (!reason.empty()) {
    setWhyNot(whyNot, std::move(reason));
    return std::nullopt;
  }
  setWhyNot(whyNot, "");
  return bytes.substr(framing.payloadOffset, static_cast<std::size_t>(framing.payloadBytes));
}

void writeCacheFile(const std::string& path, const CacheHeader& header, std::string_view payload) {
  const std::string bytes = encodeCacheFile(header, payload);
  const fs::path target(path);
  if (target.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(target.parent_path(), ec);
    if (ec) {
      throw std::runtime_error("cannot create the cache directory " + target.parent_path().string() + ": " +
                               ec.message());
    }
  }
  writeAtomically(target, bytes);
}

std::optional<std::string> readCacheFile(const std::string& path, const CacheHeader& expected, std::string* whyNot) {
  const auto miss = [&](std::string reason) -> std::optional<std::string> {
    setWhyNot(whyNot, std::move(reason));
    return std::nullopt;
  };
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) return miss("no cache file");
  if (ec) return miss("cannot look for the cache file: " + ec.message());
  if (status.type() != fs::file_type::regular) return miss("the cache path is not a regular file");

  // The size of the file opened, not of the name: a writer may rename a new
  // file over the name between a stat and the open.
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return miss("cannot open the cache file");
  const std::streamoff end = in.tellg();
  if (end < 0 || !in.seekg(0)) return miss("cannot read the cache file");
  const auto size = static_cast<std::uintmax_t>(end);
  // The header first, against the size on disk: the whole file is read only
  // once it is known to be the entry asked for and of the size it declares.
  const std::uintmax_t headerLimit = kCacheFileFixedBytes + 3 * kMaxCacheText;
  std::string bytes(static_cast<std::size_t>(std::min(size, headerLimit)), '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) return miss("cannot read the cache file");
  Framing framing;
  if (std::string reason = checkCacheBytes(bytes, size, expected, framing); !reason.empty()) return miss(reason);
  if (bytes.size() < size) {
    const std::size_t head = bytes.size();
    bytes.resize(static_cast<std::size_t>(size));
    if (!in.read(bytes.data() + head, static_cast<std::streamsize>(size - head))) {
      return miss("cannot read the cache file");
    }
    if (std::string reason = checkCacheBytes(bytes, size, expected, framing); !reason.empty()) return miss(reason);
  }
  // The payload in place: drop the checksum, then the header.
  bytes.resize(framing.payloadOffset + static_cast<std::size_t>(framing.payloadBytes));
  bytes.erase(0, framing.payloadOffset);
  setWhyNot(whyNot, "");
  return bytes;
}

std::string cacheFileName(std::string_view kind, std::string_view key, std::string_view optionsText) {
  checkKind(kind);
  return std::string(kind) + "-" + hex16(fnv1a64(key)) + "-" + hex16(fnv1a64(optionsText)) + ".hccache";
}

std::optional<std::string> lookUpCacheEntry(const std::string& cacheDir, const CacheHeader& header,
                                            CacheStatus& status) {
  try {
    status.path = (fs::path(cacheDir) / cacheFileName(header.kind, header.key, header.optionsText)).string();
    if (header.key.size() > kMaxCacheText) {
      status.reason = "key too long to store";
      return std::nullopt;
    }
    std::optional<std::string> payload = readCacheFile(status.path, header, &status.reason);
    status.hit = payload.has_value();
    if (const auto rebuild = classifyCacheMiss(status.reason)) noteCacheRebuild(*rebuild, status.path, status.reason);
    return payload;
  } catch (const std::exception& e) {  // a bad kind, or out of memory
    status.reason = e.what();
    return std::nullopt;
  }
}

void storeCacheEntry(const std::string& cacheDir, const CacheHeader& header, std::string_view payload,
                     CacheStatus& status, bool warnOnStderr) {
  try {
    const std::string path = (fs::path(cacheDir) / cacheFileName(header.kind, header.key, header.optionsText)).string();
    writeCacheFile(path, header, payload);
    status.path = path;
    status.written = true;
  } catch (const std::exception& e) {
    reportCacheError(status, warnOnStderr, header.kind, e.what());
  }
}

void reportCacheError(CacheStatus& status, bool warnOnStderr, std::string_view kind, const std::string& error) {
  if (!status.error.empty()) status.error += "; ";
  status.error += error;
  if (warnOnStderr) {
    std::cerr << "haarcast: warning: " << kind << " cache: " << error << " (the result is computed, not cached)\n";
  }
}

}  // namespace haarcast::io
