#include "haarcast/net/access.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <stdexcept>
#include <utility>

#include <boost/asio/ip/address.hpp>

namespace haarcast::net {
namespace {

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
