// The Host rule, against DNS rebinding. The Origin check compares the
// Origin with the request's Host; both come from the browser, so a page at
// http://evil.example:P whose name the attacker has rebound to this
// server's address sends a matching pair and passes it. What the attacker
// cannot choose is the Host: it is the name in the page's URL. So the
// server answers only Host values that name it: any IP literal (a rebinding
// attack needs a name; a Kubernetes probe or a scrape by pod IP sends one),
// "localhost" (browsers resolve it to loopback themselves), and the names
// the operator lists with --allow-host ("*" lists every name, turning the
// rule off). A request without a Host (HTTP/1.0) names nothing and passes.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace haarcast::net {

// The name in a Host header value: lower case, without the port, the
// brackets of an IPv6 literal or a trailing dot ("Render.Example.:8080" →
// "render.example", "[::1]:80" → "::1"). nullopt when the value is not a
// host[:port] (a port that is not 1-5 digits, an unclosed bracket, spaces).
std::optional<std::string> hostName(std::string_view host);

// True when a request with this Host header may be answered (see above).
// `allowHosts`: the operator's names, with or without a port (ignored).
bool hostAllowed(std::string_view host, const std::vector<std::string>& allowHosts);

// The one-line body of a 421 for `host`: names it and the way to allow it.
std::string misdirectedBody(std::string_view host);

}  // namespace haarcast::net
