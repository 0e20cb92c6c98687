// The gRPC port's front over real sockets: a raw HTTP/2 client that opens
// and resets streams (rapid reset) gets GOAWAY and its address a penalty,
// while an honest gRPC client goes on; the per-address connection cap; a
// compressed message refused before it is inflated.
#include <utility>  // before Asio: its awaitable.hpp uses std::exchange

#include <boost/asio.hpp>

#include "grpc_client_fixture.h"
#include "haarcast/net/http2_guard.h"
#include "haarcast/net/listener_probe.h"
#include "http2_frames.h"
#include "server_fixture.h"

namespace haarcast::net::test {
namespace {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

// A request's headers in HPACK (RFC 7541) without Huffman or the dynamic
// table: what gRPC needs to start a call to Render/Session.
std::string sessionHeaders(std::uint32_t stream) {
  auto literal = [](std::string& b, std::uint8_t prefix, std::string_view value) {
    b.push_back(static_cast<char>(prefix));
    b.push_back(static_cast<char>(value.size()));
    b.append(value);
  };
  std::string block;
  block.push_back('\x83');  // :method POST (static 3)
  block.push_back('\x86');  // :scheme http (static 6)
  literal(block, 0x04, "/haarcast.v1.Render/Session");  // :path (static 4), not indexed
  literal(block, 0x01, "localhost");                     // :authority (static 1)
  block += "\x0f\x10";                                   // content-type (static 31)
  block.push_back(static_cast<char>(16));
  block += "application/grpc";
  block.push_back('\x00');  // te: trailers, a new name, not indexed
  block.push_back('\x02');
  block += "te";
  block.push_back('\x08');
  block += "trailers";
  return http2FrameHeader(block.size(), http2::kHeaders, http2::kEndHeaders, stream) + block;
}

std::string resetStream(std::uint32_t stream) {
  return http2FrameHeader(4, http2::kRstStream, 0, stream) + std::string("\x00\x00\x00\x08", 4);  // CANCEL
}

// A raw TCP connection to the gRPC port from `from` (a loopback address).
struct RawConnection {
  asio::io_context ioc;
  tcp::socket socket{ioc};
  RawConnection(std::uint16_t port, const std::string& from) {
    socket.open(tcp::v4());
    socket.bind(tcp::endpoint(asio::ip::make_address(from), 0));
    socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  }
  // Sends `bytes`; false once the server has closed.
  bool send(const std::string& bytes) {
    boost::system::error_code ec;
    asio::write(socket, asio::buffer(bytes), ec);
    return !ec;
  }
  // Everything the server sends until it closes, or `limit` passes.
  std::string readToEnd(std::chrono::milliseconds limit, bool* closed) {
    std::string got;
    const auto end = Clock::now() + limit;
    *closed = false;
    socket.non_blocking(true);
    char buf[4096];
    while (Clock::now() < end) {
      boost::system::error_code ec;
      const std::size_t n = socket.read_some(asio::buffer(buf), ec);
      if (ec == asio::error::would_block) {
        std::this_thread::sleep_for(5ms);
        continue;
      }
      if (ec) {
        *closed = true;
        break;
      }
      got.append(buf, n);
    }
    return got;
  }
};

// The GOAWAY frames in a server's bytes: {last stream, error code}.
std::vector<std::pair<std::uint32_t, std::uint32_t>> goaways(const std::string& bytes) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> found;
  auto u32 = [&](std::size_t at) {
    return (std::uint32_t{static_cast<std::uint8_t>(bytes[at])} << 24) |
           (std::uint32_t{static_cast<std::uint8_t>(bytes[at + 1])} << 16) |
           (std::uint32_t{static_cast<std::uint8_t>(bytes[at + 2])} << 8) | static_cast<std::uint8_t>(bytes[at + 3]);
  };
  std::size_t at = 0;
  while (at + 9 <= bytes.size()) {
    const std::size_t length = (std::size_t{static_cast<std::uint8_t>(bytes[at])} << 16) |
                               (std::size_t{static_cast<std::uint8_t>(bytes[at + 1])} << 8) |
                               static_cast<std::uint8_t>(bytes[at + 2]);
    if (static_cast<std::uint8_t>(bytes[at + 3]) == http2::kGoaway && at + 9 + 8 <= bytes.size()) {
      found.emplace_back(u32(at + 9) & 0x7fffffffu, u32(at + 13));
    }
    at += 9 + length;
  }
  return found;
}

TEST(GrpcFront, RapidResetGetsGoawayAndAPenaltyWhileAnHonestClientGoesOn) {
  TestServer server(grpcOptions());
  const auto port = server.server().grpcPort();
  GrpcClient honest(port);
  ASSERT_TRUE(honest.send(hello(32, 32, v1::ENCODING_JPEG)));
  ASSERT_TRUE(honest.expect(v1::ServerMessage::kWelcome));
  ASSERT_TRUE(honest.frameFor(0));

  // HEADERS then RST_STREAM, stream after stream, from another address.
  RawConnection attacker(port, "127.0.0.3");
  std::string attack(http2::kPreface);
  attack += http2FrameHeader(0, 0x4, 0, 0);  // SETTINGS
  for (std::uint32_t s = 1; s < 2 * 1000; s += 2) attack += sessionHeaders(s) + resetStream(s);
  attacker.send(attack);  // may fail part way: the server has cut it
  bool closed = false;
  const std::string answer = attacker.readToEnd(3s, &closed);
  EXPECT_TRUE(closed) << "the connection is closed";
  const auto found = goaways(answer);
  ASSERT_EQ(found.size(), 1u) << answer.size() << " bytes, no GOAWAY";
  EXPECT_EQ(found[0].second, http2::kEnhanceYourCalm);
  EXPECT_EQ(found[0].first, 2u * 33 - 1) << "streams up to the 33rd reset's reached gRPC, none after";

  // The address is refused for a while: closed before any SETTINGS.
  RawConnection again(port, "127.0.0.3");
  again.send(std::string(http2::kPreface) + http2FrameHeader(0, 0x4, 0, 0));
  const std::string refused = again.readToEnd(2s, &closed);
  EXPECT_TRUE(closed);
  EXPECT_TRUE(refused.empty()) << refused.size() << " bytes";
  // Another address is not.
  EXPECT_EQ(probeHttp2Listener("127.0.0.1", port, 2000ms), ProbeResult::Answered);

  ASSERT_TRUE(honest.send(pose(1, 40)));
  EXPECT_TRUE(honest.frameFor(1)) << "the honest client is still served";
  EXPECT_EQ(metric(server.port(), "haarcast_refusals_total{reason=\"http2_reset_rate\"}"), 1);
  EXPECT_EQ(metric(server.port(), "haarcast_refusals_total{reason=\"http2_penalty\"}"), 1);
  EXPECT_TRUE(honest.finish().ok());
}

TEST(GrpcFront, ConnectionsPerAddressAreCappedWithTheWebSocketPorts) {
  ServerOptions o = grpcOptions();
  o.admission.connectionsPerAddress = 4;
  TestServer server(o);
  const auto port = server.server().grpcPort();
  // Two WebSocket connections and two gRPC ones from one address fill its
  // four; the fifth, on the gRPC port, is closed unanswered.
  const std::string target = std::string("/ws?token=") + kToken;
  Client ws1(server.port(), target, 0, "127.0.0.5"), ws2(server.port(), target, 0, "127.0.0.5");
  ASSERT_TRUE(ws1.connected() && ws2.connected());
  std::vector<std::unique_ptr<RawConnection>> held;
  for (int i = 0; i < 2; ++i) {
    held.push_back(std::make_unique<RawConnection>(port, "127.0.0.5"));
    held.back()->send(std::string(http2::kPreface) + http2FrameHeader(0, 0x4, 0, 0));
    bool closed = false;
    EXPECT_FALSE(held.back()->readToEnd(300ms, &closed).empty()) << "connection " << i << " gets SETTINGS";
    EXPECT_FALSE(closed);
  }
  RawConnection fifth(port, "127.0.0.5");
  fifth.send(std::string(http2::kPreface) + http2FrameHeader(0, 0x4, 0, 0));
  bool closed = false;
  EXPECT_TRUE(fifth.readToEnd(2s, &closed).empty());
  EXPECT_TRUE(closed);
  EXPECT_EQ(metric(server.port(), "haarcast_refusals_total{reason=\"connections_per_address\"}"), 1);
}

// (That the client's own address reaches the session through the socket
// pair is GrpcServer.StreamsAreLoggedFromTheirHelloOn's "opened from
// 127.0.0.1 (gRPC)".)
TEST(GrpcFront, ACompressedMessageIsRefusedBeforeItIsInflated) {
  TestServer server(grpcOptions());
  // A Hello padded to 60 KB of zeros, gzip-compressed by the client: a few
  // hundred bytes on the wire, refused unread.
  auto stub = v1::Render::NewStub(channelTo(server.server().grpcPort()));
  grpc::ClientContext context;
  context.AddMetadata("authorization", std::string("Bearer ") + kToken);
  context.set_deadline(std::chrono::system_clock::now() + 30s);
  context.set_compression_algorithm(GRPC_COMPRESS_GZIP);
  auto stream = stub->Session(&context);
  auto padded = hello();
  padded.mutable_hello()->set_client_name(std::string(60000, '\0'));
  stream->Write(padded);
  v1::ServerMessage ignored;
  while (stream->Read(&ignored)) {
  }
  const grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNIMPLEMENTED) << status.error_message();
  EXPECT_EQ(server.server().metrics().sessionsTotal.load(), 0u) << "the Hello never reached a session";
}

}  // namespace
}  // namespace haarcast::net::test
