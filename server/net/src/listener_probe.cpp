#include "haarcast/net/listener_probe.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

namespace haarcast::net {
namespace {

using Clock = std::chrono::steady_clock;

// Closes the descriptor on every path out.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

int millisecondsLeft(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left > 0 ? static_cast<int>(left) : 0;
}

}  // namespace

ProbeResult probeHttp2Listener(const std::string& host, std::uint16_t port, std::chrono::milliseconds timeout) {
  sockaddr_storage address{};
  socklen_t length = 0;
  auto* v4 = reinterpret_cast<sockaddr_in*>(&address);
  auto* v6 = reinterpret_cast<sockaddr_in6*>(&address);
  if (::inet_pton(AF_INET, host.c_str(), &v4->sin_addr) == 1) {
    v4->sin_family = AF_INET;
    v4->sin_port = htons(port);
    length = sizeof(sockaddr_in);
  } else if (::inet_pton(AF_INET6, host.c_str(), &v6->sin6_addr) == 1) {
    v6->sin6_family = AF_INET6;
    v6->sin6_port = htons(port);
    length = sizeof(sockaddr_in6);
  } else {
    return ProbeResult::Inconclusive;
  }
  Fd s{::socket(address.ss_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0)};
  if (s.fd < 0) return ProbeResult::Inconclusive;  // no descriptor to probe with
  const auto deadline = Clock::now() + timeout;
  if (::connect(s.fd, reinterpret_cast<const sockaddr*>(&address), length) != 0) {
    if (errno == ECONNREFUSED) return ProbeResult::Silent;  // nothing listens
    if (errno != EINPROGRESS) return ProbeResult::Inconclusive;
    pollfd p{s.fd, POLLOUT, 0};
    if (::poll(&p, 1, millisecondsLeft(deadline)) <= 0) return ProbeResult::Silent;
    int error = 0;
    socklen_t size = sizeof error;
    ::getsockopt(s.fd, SOL_SOCKET, SO_ERROR, &error, &size);
    if (error == ECONNREFUSED) return ProbeResult::Silent;
    if (error != 0) return ProbeResult::Inconclusive;
  }
  // The client preface, then an empty SETTINGS frame (length 0, type 4,
  // flags 0, stream 0).
  static constexpr char kPreface[] = "PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n";
  std::array<char, sizeof kPreface - 1 + 9> hello{};
  std::memcpy(hello.data(), kPreface, sizeof kPreface - 1);
  hello[sizeof kPreface - 1 + 3] = 0x4;
  if (::send(s.fd, hello.data(), hello.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(hello.size())) return ProbeResult::Silent;
  // The server's first frame must be SETTINGS (RFC 9113 §3.4).
  std::array<unsigned char, 9> header{};
  std::size_t got = 0;
  while (got < header.size()) {
    pollfd p{s.fd, POLLIN, 0};
    if (::poll(&p, 1, millisecondsLeft(deadline)) <= 0) return ProbeResult::Silent;
    const ssize_t n = ::recv(s.fd, header.data() + got, header.size() - got, 0);
    if (n <= 0) return ProbeResult::Silent;
    got += static_cast<std::size_t>(n);
  }
  return header[3] == 0x4 ? ProbeResult::Answered : ProbeResult::Silent;
}

bool ListenerWatch::record(ProbeResult result) {
  const bool was = dead_;
  if (result == ProbeResult::Answered) {
    silentInARow_ = 0;
    dead_ = false;
  } else if (result == ProbeResult::Silent) {
    dead_ = ++silentInARow_ >= silentToDie_;
  }
  return dead_ != was;
}

}  // namespace haarcast::net
