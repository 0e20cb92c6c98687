#include "haarcast/net/access.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <stdexcept>
#include <utility>

#include <boost/asio/ip/address.hpp>

namespace haarcast::net {
namespace {

// Addresses remembered by the token guard before expired entries are pruned.
constexpr std::size_t kMaxGuardEntries = 4096;

bool equalNoCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '/')) s.remove_suffix(1);
  return s;
}

std::chrono::nanoseconds seconds(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s));
}

}  // namespace

bool originAllowed(std::string_view origin, std::string_view host, const std::vector<std::string>& allowList) {
  origin = trimmed(origin);
  if (origin.empty()) return true;  // not a browser: nothing to hijack
  for (const auto& allowed : allowList) {
    if (equalNoCase(origin, trimmed(allowed))) return true;
  }
  const auto scheme = origin.find("://");
  if (scheme == std::string_view::npos) return false;  // "null", or not an origin
  const std::string_view authority = origin.substr(scheme + 3);
  host = trimmed(host);
  return !host.empty() && equalNoCase(authority, host);
}

std::string bearerToken(std::string_view authorization) {
  authorization = trimmed(authorization);
  constexpr std::string_view scheme = "bearer";
  if (authorization.size() <= scheme.size() || !equalNoCase(authorization.substr(0, scheme.size()), scheme)) return {};
  const std::string_view rest = authorization.substr(scheme.size());
  if (rest.front() != ' ' && rest.front() != '\t') return {};  // "Bearerx…": another scheme
  return std::string(trimmed(rest));
}

bool tokensEqual(std::string_view given, std::string_view expected) {
  if (given.size() != expected.size() || expected.empty()) return false;
  unsigned diff = 0;
  for (std::size_t i = 0; i < given.size(); ++i) {
    diff |= static_cast<unsigned>(static_cast<unsigned char>(given[i]) ^ static_cast<unsigned char>(expected[i]));
  }
  return diff == 0;
}

bool isLoopbackAddress(std::string_view address) {
  boost::system::error_code ec;
  const auto a = boost::asio::ip::make_address(std::string(address), ec);
  if (ec) return false;
  if (a.is_v6() && a.to_v6().is_v4_mapped()) {
    return boost::asio::ip::make_address_v4(boost::asio::ip::v4_mapped, a.to_v6()).is_loopback();
  }
  return a.is_loopback();
}

std::string clientGroup(std::string_view address) {
  namespace ip = boost::asio::ip;
  boost::system::error_code ec;
  const auto a = ip::make_address(std::string(address), ec);
  if (ec) return std::string(address);
  if (a.is_v4()) return a.to_string();
  const ip::address_v6 v6 = a.to_v6();
  if (v6.is_v4_mapped()) return ip::make_address_v4(ip::v4_mapped, v6).to_string();
  if (v6.is_loopback()) return v6.to_string();
  // One host is routinely given a whole /64 (SLAAC, privacy addresses): its
  // interface half is the host's to choose, so limits count the prefix.
  ip::address_v6::bytes_type bytes = v6.to_bytes();
  std::fill(bytes.begin() + 8, bytes.end(), static_cast<unsigned char>(0));
  return ip::address_v6(bytes).to_string() + "/64";
}

// ------------------------------------------------------------------ TokenGuard

TokenGuard::TokenGuard(Options options) : options_(options) {
  if (options_.maxFailures < 1) throw std::invalid_argument("TokenGuard: maxFailures must be at least 1");
}

bool TokenGuard::locked(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(address);
  return it != entries_.end() && now < it->second.lockedUntil;
}

void TokenGuard::failed(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  if (entries_.size() >= kMaxGuardEntries) prune(now);
  Entry& e = entries_[address];
  if (e.failures == 0 || now - e.windowStart > seconds(options_.windowSeconds)) {
    e.windowStart = now;
    e.failures = 0;
  }
  if (++e.failures >= options_.maxFailures) {
    e.lockedUntil = now + seconds(options_.lockoutSeconds);
    e.failures = 0;
  }
}

void TokenGuard::prune(Clock::time_point now) {
  std::erase_if(entries_, [&](const auto& kv) {
    const Entry& e = kv.second;
    return now >= e.lockedUntil && now - e.windowStart > seconds(options_.windowSeconds);
  });
  // Still full (a spray of fresh addresses): forget the oldest windows.
  while (entries_.size() >= kMaxGuardEntries) entries_.erase(entries_.begin());
}

// ------------------------------------------------------------------ Admission

std::string_view slotKindName(SlotKind kind) {
  switch (kind) {
    case SlotKind::Connection: return "connection";
    case SlotKind::Pending: return "pending";
    case SlotKind::Session: return "session";
  }
  return "?";
}

Admission::Slot::Slot(Admission* owner, SlotKind kind, std::string address)
    : owner_(owner), kind_(kind), address_(std::move(address)) {}

Admission::Slot::Slot(Slot&& other) noexcept
    : owner_(std::exchange(other.owner_, nullptr)), kind_(other.kind_), address_(std::move(other.address_)) {}

Admission::Slot& Admission::Slot::operator=(Slot&& other) noexcept {
  if (this != &other) {
    release();
    owner_ = std::exchange(other.owner_, nullptr);
    kind_ = other.kind_;
    address_ = std::move(other.address_);
  }
  return *this;
}

Admission::Slot::~Slot() { release(); }

void Admission::Slot::release() {
  if (owner_) std::exchange(owner_, nullptr)->give(kind_, address_);
}

Admission::Admission(Limits limits) : limits_(limits) {}

std::optional<Admission::Slot> Admission::take(SlotKind kind, const std::string& address, Refusal* refusal) {
  const auto k = static_cast<std::size_t>(kind);
  int serverCap = 0, addressCap = 0;
  const char* what = "";
  switch (kind) {
    case SlotKind::Connection:
      serverCap = -1;  // the listen backlog and the file-descriptor limit bound these
      addressCap = limits_.connectionsPerAddress;
      what = "connections";
      break;
    case SlotKind::Pending:
      serverCap = limits_.pending;
      addressCap = limits_.pendingPerAddress;
      what = "connections waiting for a Hello";
      break;
    case SlotKind::Session:
      serverCap = limits_.sessions;
      addressCap = limits_.sessionsPerAddress;
      what = "sessions";
      break;
  }
  std::lock_guard lock(mutex_);
  auto& mine = perAddress_[address];
  Refusal r;
  if (serverCap >= 0 && total_[k] >= serverCap) {
    r = {false, std::string("too many ") + what + ": the server allows " + std::to_string(serverCap)};
  } else if (mine[k] >= addressCap) {
    r = {true, std::string("too many ") + what + " from " + address + ": each address may have " +
                   std::to_string(addressCap)};
  } else {
    ++total_[k];
    ++mine[k];
    return Slot(this, kind, address);
  }
  if (mine == std::array<int, 3>{0, 0, 0}) perAddress_.erase(address);
  if (refusal) *refusal = std::move(r);
  return std::nullopt;
}

void Admission::give(SlotKind kind, const std::string& address) {
  const auto k = static_cast<std::size_t>(kind);
  std::lock_guard lock(mutex_);
  --total_[k];
  const auto it = perAddress_.find(address);
  if (it == perAddress_.end()) return;
  --it->second[k];
  if (it->second == std::array<int, 3>{0, 0, 0}) perAddress_.erase(it);
}

int Admission::count(SlotKind kind) const {
  std::lock_guard lock(mutex_);
  return total_[static_cast<std::size_t>(kind)];
}

int Admission::count(SlotKind kind, const std::string& address) const {
  std::lock_guard lock(mutex_);
  const auto it = perAddress_.find(address);
  return it == perAddress_.end() ? 0 : it->second[static_cast<std::size_t>(kind)];
}

// ------------------------------------------------------------------ AcceptBackoff

AcceptBackoff::Step AcceptBackoff::onError(int e) {
  const bool exhausted = e == EMFILE || e == ENFILE || e == ENOBUFS || e == ENOMEM;
  if (!exhausted) return {};
  Step step;
  step.episodeStarted = errors_ == 0;
  ++errors_;
  pause_ = pause_.count() == 0 ? kFirst : std::min(kMost, pause_ * 2);
  step.pause = pause_;
  return step;
}

bool AcceptBackoff::onSuccess() {
  const bool ended = errors_ > 0;
  errors_ = 0;
  pause_ = std::chrono::milliseconds{0};
  return ended;
}

}  // namespace haarcast::net
