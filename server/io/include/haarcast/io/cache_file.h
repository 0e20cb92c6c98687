// haarcast's on-disk cache file: one container for everything that is slow to
// compute and cheap to read back (BRDF slice tables, per-vertex visibility).
// Each cache says what it stores in the payload; this file says how a payload
// is framed, checked and written.
//
// File format `.hccache`, container version kCacheFileFormat, little-endian:
//   offset    size
//   0         8    magic "HCCACHE\0"
//   8         4    u32 container format version (kCacheFileFormat)
//   12        4    u32 the cache's own version (CacheHeader::version)
//   16        4    u32 kind length A (≤ kMaxCacheText)
//   20        4    u32 key length K (≤ kMaxCacheText)
//   24        4    u32 options length O (≤ kMaxCacheText)
//   28        8    u64 payload length P
//   36        A    kind ("slices", "visibility")
//   36+A      K    key: what the result was computed from
//   36+A+K    O    options text: a canonical description of the options
//   36+A+K+O  P    payload
//   end−8     8    u64 FNV-1a 64 of every byte before it
// A file is a hit only if magic, container version, kind, version, key and
// options all equal what the caller asks for, its size is exactly what the
// header says, and the checksum matches; anything else is a miss with a
// reason. Key and options are stored whole and compared, so a collision of
// the hashed file name is a miss, never a wrong result.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

namespace haarcast::io {

inline constexpr std::uint32_t kCacheFileFormat = 1;
inline constexpr std::size_t kMaxCacheText = 1 << 16;  // bytes of kind, key or options text
inline constexpr std::size_t kCacheFileFixedBytes = 36;  // magic … payload length
inline constexpr std::size_t kCacheFileChecksumBytes = 8;

// What a cache file holds, apart from its payload.
struct CacheHeader {
  std::string kind;            // which cache: [a-z0-9_-]+, also the file name's prefix
  std::uint32_t version = 0;   // the cache's payload format; bump when it, or what computes it, changes
  std::string key;             // what the result was computed from (a file's identity, a content hash)
  std::string optionsText;     // canonical description of the options that produced it
};

// What a load-or-compute call did, for callers that log or test it.
struct CacheStatus {
  bool hit = false;      // read from the cache; nothing was computed
  bool written = false;  // a computed result was stored for next time
  std::string path;      // the cache file consulted
  std::string reason;    // why it was not a hit ("no cache file", "checksum mismatch", …); empty on a hit
  std::string error;     // an I/O failure the user should know of (directory not creatable, write failed)
};

// FNV-1a, 64-bit (Fowler, Noll, Vo): one multiply per byte, no table, and any
// single flipped byte changes the result. Not cryptographic: it guards against
// torn and corrupted files and names entries, not against an adversary.
inline constexpr std::uint64_t kFnv1a64Basis = 0xcbf29ce484222325ull;
std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash = kFnv1a64Basis);

// The file's bytes. Throws std::invalid_argument for a kind that is not
// [a-z0-9_-]+ or a text over kMaxCacheText.
std::string encodeCacheFile(const CacheHeader& header, std::string_view payload);
// The payload inside `bytes` (a view into them) if they are a valid file for
// exactly `expected`; otherwise nullopt, and *whyNot (if given) says what did
// not match. Never throws for any bytes.
std::optional<std::string_view> decodeCacheFile(std::string_view bytes, const CacheHeader& expected,
                                                std::string* whyNot = nullptr);

// Writes encodeCacheFile(header, payload) to `path`, creating its directory,
// through a temporary file in the same directory that is fsync'd and then
// renamed over `path`: a reader sees the old file or the whole new one, and
// after a crash the name never points at unwritten blocks. Throws
// std::runtime_error saying what failed (std::invalid_argument as encode).
void writeCacheFile(const std::string& path, const CacheHeader& header, std::string_view payload);
// The payload of the file at `path` if it is valid for exactly `expected`
// (as decodeCacheFile); otherwise nullopt with the reason in *whyNot ("no
// cache file", a read error, or what did not match). The header is checked
// against the file's size before the rest is read, so a stray huge file is
// never loaded. Never throws for any file contents.
std::optional<std::string> readCacheFile(const std::string& path, const CacheHeader& expected,
                                         std::string* whyNot = nullptr);

// The file name (no directory) for an entry: "<kind>-<hash of key>-<hash of
// options>.hccache". Entries of one key share a prefix; other options of the
// same key sit beside them. Throws std::invalid_argument for a bad kind.
std::string cacheFileName(std::string_view kind, std::string_view key, std::string_view optionsText);

// The two halves of a load-or-compute cache, for the caches built on this file:
// The payload stored in cacheDir for `header`, or nullopt with status.reason
// set (status.path is set either way). Never throws.
std::optional<std::string> lookUpCacheEntry(const std::string& cacheDir, const CacheHeader& header,
                                            CacheStatus& status);
// Stores `payload` for `header` in cacheDir and sets status.written. A failure
// is added to status.error and, when warnOnStderr, printed as one line naming
// the cache; it never throws, so a cache can never fail the work it saves.
void storeCacheEntry(const std::string& cacheDir, const CacheHeader& header, std::string_view payload,
                     CacheStatus& status, bool warnOnStderr);
// Adds `error` to status.error, and prints it as one stderr line when warnOnStderr.
void reportCacheError(CacheStatus& status, bool warnOnStderr, std::string_view kind, const std::string& error);

// ---- Little-endian numbers in payloads -------------------------------------

template <typename T>
  requires std::is_arithmetic_v<T>
void appendLittleEndian(std::string& out, T value) {
  std::array<char, sizeof(T)> raw{};
  std::memcpy(raw.data(), &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw.begin(), raw.end());
  out.append(raw.data(), raw.size());
}

// Reads a payload front to back; every read is bounds-checked and throws
// std::runtime_error("truncated payload …") past the end, so a decoder built
// on it cannot read outside the bytes whatever they say.
class PayloadReader {
 public:
  explicit PayloadReader(std::string_view bytes) : bytes_(bytes) {}

  template <typename T>
    requires std::is_arithmetic_v<T>
  T take() {
    std::array<char, sizeof(T)> raw{};
    const std::string_view b = takeBytes(sizeof(T));
    std::memcpy(raw.data(), b.data(), sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(raw.begin(), raw.end());
    T value;
    std::memcpy(&value, raw.data(), sizeof(T));
    return value;
  }

  std::string_view takeBytes(std::size_t n) {
    if (n > remaining()) {
      throw std::runtime_error("truncated payload: " + std::to_string(n) + " bytes wanted at offset " +
                               std::to_string(offset_) + ", " + std::to_string(remaining()) + " left");
    }
    const std::string_view b = bytes_.substr(offset_, n);
    offset_ += n;
    return b;
  }

  std::size_t remaining() const { return bytes_.size() - offset_; }
  std::size_t offset() const { return offset_; }

 private:
  std::string_view bytes_;
  std::size_t offset_ = 0;
};

}  // namespace haarcast::io
