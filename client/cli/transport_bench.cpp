// haarcast-transport-bench: the WebSocket and the gRPC transport side by
// side against one running server (`haarcast serve --grpc-port N`). Each
// round plays the same closed-loop turn of the scene's first object on each
// transport in turn (the order alternating per round, so that drift in the
// machine's load hits both alike): a pose, then wait for the frame that
// answers it, then the next pose. Reported per transport: frames per second
// and the pose-sent → frame-received latency (p50, p99), over every round.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>  // before Asio: its awaitable.hpp uses std::exchange
#include <vector>

#include <CLI/CLI.hpp>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <grpcpp/grpcpp.h>

#include "haarcast/proto/haarcast.grpc.pb.h"

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string host = "127.0.0.1", token;
  int wsPort = 8080, grpcPort = 50051, size = 256, frames = 60, warmup = 2, rounds = 3;
  double turnDegrees = 90.0, fps = 60.0;
};

// One session on either transport: send a message, read the next one.
class Transport {
 public:
  virtual ~Transport() = default;
  virtual void send(const haarcast::v1::ClientMessage& m) = 0;
  virtual haarcast::v1::ServerMessage read() = 0;
  virtual void close() = 0;
};

class WsTransport final : public Transport {
 public:
  explicit WsTransport(const Options& o) : ws_(ioc_) {
    ws_.next_layer().connect(asio::ip::tcp::endpoint(asio::ip::make_address(o.host), static_cast<unsigned short>(o.wsPort)));
    ws_.next_layer().set_option(asio::ip::tcp::no_delay(true));
    ws_.set_option(websocket::stream_base::decorator([t = o.token](websocket::request_type& req) {
      if (!t.empty()) req.set(beast::http::field::authorization, "Bearer " + t);
    }));
    ws_.read_message_max(64u << 20);
    ws_.handshake(o.host + ":" + std::to_string(o.wsPort), "/ws");
    ws_.binary(true);
  }
  void send(const haarcast::v1::ClientMessage& m) override { ws_.write(asio::buffer(m.SerializeAsString())); }
  haarcast::v1::ServerMessage read() override {
    beast::flat_buffer buffer;
    ws_.read(buffer);
    haarcast::v1::ServerMessage m;
    if (!m.ParseFromString(beast::buffers_to_string(buffer.data()))) throw std::runtime_error("WebSocket: not a ServerMessage");
    return m;
  }
  void close() override { ws_.close(websocket::close_code::normal); }

 private:
  asio::io_context ioc_;
  websocket::stream<asio::ip::tcp::socket> ws_;
};

class GrpcTransport final : public Transport {
 public:
  explicit GrpcTransport(const Options& o) {
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(64 << 20);
    args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);  // a connection of its own, as the WebSocket has
    stub_ = haarcast::v1::Render::NewStub(grpc::CreateCustomChannel(
        o.host + ":" + std::to_string(o.grpcPort), grpc::InsecureChannelCredentials(), args));
    if (!o.token.empty()) context_.AddMetadata("authorization", "Bearer " + o.token);
    stream_ = stub_->Session(&context_);
  }
  void send(const haarcast::v1::ClientMessage& m) override {
    if (!stream_->Write(m)) throw std::runtime_error("gRPC: the stream ended: " + status().error_message());
  }
  haarcast::v1::ServerMessage read() override {
    haarcast::v1::ServerMessage m;
    if (!stream_->Read(&m)) throw std::runtime_error("gRPC: the stream ended: " + status().error_message());
    return m;
  }
  void close() override {
    stream_->WritesDone();
    haarcast::v1::ServerMessage m;
    while (stream_->Read(&m)) {
    }
    (void)stream_->Finish();
  }

 private:
  grpc::Status status() { return stream_->Finish(); }
  std::unique_ptr<haarcast::v1::Render::Stub> stub_;
  grpc::ClientContext context_;
  std::unique_ptr<grpc::ClientReaderWriter<haarcast::v1::ClientMessage, haarcast::v1::ServerMessage>> stream_;
};

struct Round {
  double fps = 0.0;
  std::vector<double> latenciesMs;
};

// The next frame answering pose `sequence` (Stats and the like are skipped;
// an Error ends the run).
haarcast::v1::Frame frameFor(Transport& t, std::uint64_t sequence) {
  for (;;) {
    auto m = t.read();
    if (m.has_error()) throw std::runtime_error("Error " + haarcast::v1::ErrorCode_Name(m.error().code()) + ": " + m.error().message());
    if (m.has_frame() && m.frame().pose_sequence() >= sequence) return m.frame();
  }
}

Round play(Transport& t, const Options& o) {
  haarcast::v1::ClientMessage hello;
  auto* h = hello.mutable_hello();
  h->set_protocol_version(haarcast::v1::PROTOCOL_VERSION_1);
  h->set_auth_token(o.token);
  h->set_width(static_cast<std::uint32_t>(o.size));
  h->set_height(static_cast<std::uint32_t>(o.size));
  h->set_encoding(haarcast::v1::ENCODING_JPEG);
  h->set_fps_cap(o.fps);
  h->set_client_name("transport-bench");
  t.send(hello);
  frameFor(t, 0);  // Welcome, then the scene's own view
  Round r;
  Clock::time_point measuredFrom;
  const int total = o.warmup + o.frames;
  for (int i = 1; i <= total; ++i) {
    if (i == o.warmup + 1) measuredFrom = Clock::now();
    haarcast::v1::ClientMessage pose;
    auto* p = pose.mutable_pose();
    p->set_sequence(static_cast<std::uint64_t>(i));
    auto* obj = p->add_objects();
    obj->set_object(0);
    obj->mutable_rotate_degrees()->set_y(o.turnDegrees * i / total);
    const auto sent = Clock::now();
    t.send(pose);
    frameFor(t, static_cast<std::uint64_t>(i));
    if (i > o.warmup) r.latenciesMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - sent).count());
  }
  r.fps = o.frames / std::chrono::duration<double>(Clock::now() - measuredFrom).count();
  t.close();
  return r;
}

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"The WebSocket and gRPC transports side by side against one `haarcast serve --grpc-port N`"};
  app.add_option("--host", o.host, "Server address")->capture_default_str();
  app.add_option("--ws-port", o.wsPort, "The server's --port")->capture_default_str();
  app.add_option("--grpc-port", o.grpcPort, "The server's --grpc-port")->capture_default_str();
  app.add_option("--token", o.token, "The server's token, if any");
  app.add_option("--size", o.size, "Frame width and height")->capture_default_str();
  app.add_option("--frames", o.frames, "Measured frames per round and transport")->capture_default_str();
  app.add_option("--warmup", o.warmup, "Frames first, left out")->capture_default_str();
  app.add_option("--rounds", o.rounds, "Rounds (each plays both transports)")->capture_default_str();
  app.add_option("--turn", o.turnDegrees, "Degrees the object turns over a round")->capture_default_str();
  app.add_option("--fps", o.fps, "Hello.fps_cap")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const char* names[2] = {"websocket", "grpc"};
  std::vector<double> fps[2], latencies[2];
  try {
    for (int round = 0; round < o.rounds; ++round) {
      for (int k = 0; k < 2; ++k) {
        const int which = (round % 2 == 0) ? k : 1 - k;
        std::unique_ptr<Transport> t;
        if (which == 0) {
          t = std::make_unique<WsTransport>(o);
        } else {
          t = std::make_unique<GrpcTransport>(o);
        }
        Round r = play(*t, o);
        std::fprintf(stderr, "round %d %-9s %.1f fps, p50 %.1f ms\n", round + 1, names[which], r.fps,
                     percentile(r.latenciesMs, 0.5));
        fps[which].push_back(r.fps);
        latencies[which].insert(latencies[which].end(), r.latenciesMs.begin(), r.latenciesMs.end());
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "haarcast-transport-bench: %s\n", e.what());
    return 1;
  }
  std::printf("| transport | fps (median of %d rounds) | latency p50 / p99 (ms) |\n|---|---|---|\n", o.rounds);
  for (int k = 0; k < 2; ++k) {
    std::printf("| %s | %.1f | %.1f / %.1f |\n", names[k], percentile(fps[k], 0.5), percentile(latencies[k], 0.5),
                percentile(latencies[k], 0.99));
  }
  const double fpsRatio = percentile(fps[1], 0.5) / percentile(fps[0], 0.5);
  const double latencyRatio = percentile(latencies[1], 0.5) / percentile(latencies[0], 0.5);
  std::printf("grpc / websocket: fps %.3f, p50 latency %.3f\n", fpsRatio, latencyRatio);
  return 0;
}
