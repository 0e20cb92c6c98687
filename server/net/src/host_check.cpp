#include "haarcast/net/host_check.h"

#include <algorithm>
#include <cctype>

#include <boost/asio/ip/address.hpp>

#include "haarcast/net/messages.h"

namespace haarcast::net {
namespace {

bool isIpLiteral(const std::string& name) {
  boost::system::error_code ec;
  boost::asio::ip::make_address(name, ec);
  return !ec;
}

bool validNameByte(char c) {
  const auto u = static_cast<unsigned char>(c);
  return std::isalnum(u) || c == '-' || c == '.' || c == '_' || c == ':' || c == '%';
}

}  // namespace

std::optional<std::string> hostName(std::string_view host) {
  std::string_view name = host;
  std::string_view port;
  if (!host.empty() && host.front() == '[') {
    const auto close = host.find(']');
    if (close == std::string_view::npos) return std::nullopt;
    name = host.substr(1, close - 1);
    const std::string_view rest = host.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':') return std::nullopt;
      port = rest.substr(1);
      if (port.empty()) return std::nullopt;
    }
    if (name.find(':') == std::string_view::npos) return std::nullopt;  // brackets hold IPv6 only
  } else if (const auto colon = host.rfind(':'); colon != std::string_view::npos) {
    name = host.substr(0, colon);
    port = host.substr(colon + 1);
    if (port.empty() || name.find(':') != std::string_view::npos) return std::nullopt;  // unbracketed IPv6
  }
  if (port.size() > 5 || !std::all_of(port.begin(), port.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  if (!name.empty() && name.back() == '.') name.remove_suffix(1);
  if (name.empty() || !std::all_of(name.begin(), name.end(), validNameByte)) return std::nullopt;
  std::string out(name);
  std::transform(out.begin(), out.end(), out.begin(), [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  });
  return out;
}

bool hostAllowed(std::string_view host, const std::vector<std::string>& allowHosts) {
  if (host.empty()) return true;  // HTTP/1.0 without a Host: no name to have been rebound
  const auto name = hostName(host);
  if (!name) return false;
  if (*name == "localhost" || isIpLiteral(*name)) return true;
  return std::any_of(allowHosts.begin(), allowHosts.end(), [&](const std::string& allowed) {
    if (allowed == "*") return true;
    const auto a = hostName(allowed);
    return a && *a == *name;
  });
}

std::string misdirectedBody(std::string_view host) {
  const auto name = hostName(host);
  const std::string shown = sanitizeForLog(name ? std::string_view(*name) : host);
  return "misdirected request: Host \"" + shown + "\" is not a name of this server (allow it with --allow-host " +
         (name ? shown : std::string("NAME")) + ")\n";
}

}  // namespace haarcast::net
