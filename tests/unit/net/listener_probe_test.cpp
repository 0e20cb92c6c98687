// The listener probe (listener_probe.h) against sockets that behave as a
// live HTTP/2 server, a dead one (listening, never accepting), a closed
// port and an HTTP/1.1 server; and the watch's verdict from probes.
#include "haarcast/net/listener_probe.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace haarcast::net {
namespace {

using namespace std::chrono_literals;

// A loopback socket listening on a free port; never accepts by itself.
struct Listening {
  int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  std::uint16_t port = 0;
  Listening() {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    EXPECT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    EXPECT_EQ(::listen(fd, 8), 0);
    socklen_t n = sizeof a;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &n);
    port = ntohs(a.sin_port);
  }
  ~Listening() { ::close(fd); }
  // Accepts one connection, reads the client's preface, answers `reply`.
  std::thread answerOnce(std::string reply) {
    return std::thread([this, reply] {
      const int c = ::accept(fd, nullptr, nullptr);
      if (c < 0) return;
      char buffer[64];
      (void)::recv(c, buffer, sizeof buffer, 0);
      (void)::send(c, reply.data(), reply.size(), MSG_NOSIGNAL);
      std::this_thread::sleep_for(200ms);
      ::close(c);
    });
  }
};

TEST(ListenerProbe, AnsweredOnlyByAnHttp2ServersSettings) {
  {
    Listening live;
    std::thread t = live.answerOnce(std::string("\0\0\0\x04\0\0\0\0\0", 9));
    EXPECT_EQ(probeHttp2Listener("127.0.0.1", live.port, 2000ms), ProbeResult::Answered);
    t.join();
  }
  {
    Listening http1;
    std::thread t = http1.answerOnce("HTTP/1.1 400 Bad Request\r\n\r\n");
    EXPECT_EQ(probeHttp2Listener("127.0.0.1", http1.port, 2000ms), ProbeResult::Silent);
    t.join();
  }
  {
    // Listening but never accepting: the kernel completes the handshake,
    // nothing answers.
    Listening dead;
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(probeHttp2Listener("127.0.0.1", dead.port, 300ms), ProbeResult::Silent);
    EXPECT_LT(std::chrono::steady_clock::now() - t0, 2s) << "the timeout holds";
  }
  std::uint16_t closed = 0;
  {
    Listening gone;
    closed = gone.port;
  }
  EXPECT_EQ(probeHttp2Listener("127.0.0.1", closed, 300ms), ProbeResult::Silent) << "refused: nothing listens";
  EXPECT_EQ(probeHttp2Listener("not-an-address", 1, 300ms), ProbeResult::Inconclusive);
}

TEST(ListenerWatch, DeadAfterThreeSilentInARowAliveAtTheFirstAnswer) {
  ListenerWatch w;
  EXPECT_FALSE(w.record(ProbeResult::Silent));
  EXPECT_FALSE(w.record(ProbeResult::Silent));
  EXPECT_FALSE(w.record(ProbeResult::Inconclusive)) << "no descriptor to probe with says nothing";
  EXPECT_FALSE(w.dead());
  EXPECT_TRUE(w.record(ProbeResult::Silent));
  EXPECT_TRUE(w.dead());
  EXPECT_FALSE(w.record(ProbeResult::Silent));
  EXPECT_TRUE(w.record(ProbeResult::Answered));
  EXPECT_FALSE(w.dead());
  // A slow answer once between silences starts the count again.
  w.record(ProbeResult::Silent);
  w.record(ProbeResult::Silent);
  w.record(ProbeResult::Answered);
  w.record(ProbeResult::Silent);
  EXPECT_FALSE(w.dead());
}

}  // namespace
}  // namespace haarcast::net
