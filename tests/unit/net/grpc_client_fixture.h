// What the gRPC tests share: a server with a gRPC port on loopback, a
// client of the generated stub (haarcast.v1.Render) on a connection of its
// own, the health check through gRPC's generic stub with the two tiny
// messages encoded by hand (Debian ships no health.proto), and a wait.
#pragma once

#include <future>
#include <thread>

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include "haarcast/proto/haarcast.grpc.pb.h"
#include "server_fixture.h"

namespace haarcast::net::test {

inline ServerOptions grpcOptions() {
  ServerOptions o = testOptions();
  o.grpcPort = 0;  // any free port
  return o;
}

// How a client's transport takes data its application has not read.
enum class Window {
  kGrows,  // gRPC's default: the window grows with the measured bandwidth
  kFixed,  // no bandwidth probe: once the window is full the server's write waits
};

inline std::shared_ptr<grpc::Channel> channelTo(std::uint16_t port, Window window = Window::kGrows) {
  // A connection of its own per client: gRPC would otherwise share one
  // between channels with the same target, and the tests want clients
  // that are independent on the wire.
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  // Without the probe a client that never reads stops the server's write
  // for good; with it the transport keeps buffering unread frames, ~1 a
  // second, for tens of seconds before the write stalls (measured: 15–19
  // frames of 256 KiB), and whether that fits a test's time is luck.
  if (window == Window::kFixed) args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  args.SetMaxReceiveMessageSize(64 << 20);
  return grpc::CreateCustomChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials(), args);
}

class GrpcClient {
 public:
  explicit GrpcClient(std::uint16_t port, const std::string& authorization = std::string("Bearer ") + kToken,
                      Window window = Window::kGrows)
      : stub_(v1::Render::NewStub(channelTo(port, window))) {
    if (!authorization.empty()) context_.AddMetadata("authorization", authorization);
    context_.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    stream_ = stub_->Session(&context_);
  }

  bool send(const v1::ClientMessage& m) { return stream_->Write(m); }
  std::optional<v1::ServerMessage> read() {
    v1::ServerMessage m;
    if (!stream_->Read(&m)) return std::nullopt;
    return m;
  }
  // The next message of this kind (Stats and others are skipped).
  std::optional<v1::ServerMessage> expect(v1::ServerMessage::BodyCase body) {
    while (auto m = read()) {
      if (m->body_case() == body) return m;
    }
    return std::nullopt;
  }
  // The next frame answering pose `sequence` or a later one.
  std::optional<v1::Frame> frameFor(std::uint64_t sequence) {
    while (auto m = expect(v1::ServerMessage::kFrame)) {
      if (m->frame().pose_sequence() >= sequence) return m->frame();
    }
    return std::nullopt;
  }
  // Half-closes, reads what is left, and returns the status.
  grpc::Status finish() {
    stream_->WritesDone();
    while (read()) {
    }
    return stream_->Finish();
  }
  grpc::Status statusAfterReading() {
    while (read()) {
    }
    return stream_->Finish();
  }
  grpc::ClientContext& context() { return context_; }

 private:
  std::unique_ptr<v1::Render::Stub> stub_;
  grpc::ClientContext context_;
  std::unique_ptr<grpc::ClientReaderWriter<v1::ClientMessage, v1::ServerMessage>> stream_;
};

// grpc.health.v1.Health/Check: HealthCheckRequest{string service = 1} in,
// HealthCheckResponse{ServingStatus status = 1} out (SERVING = 1,
// NOT_SERVING = 2). Returns the status, or -1 when the call failed.
inline int healthStatus(std::uint16_t port, const std::string& service = "") {
  grpc::GenericStub stub(channelTo(port));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  std::string request;
  if (!service.empty()) {
    request.push_back('\x0a');
    request.push_back(static_cast<char>(service.size()));
    request += service;
  }
  grpc::Slice slice(request);
  grpc::ByteBuffer in(&slice, 1), out;
  std::promise<grpc::Status> done;
  stub.UnaryCall(&context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &in, &out,
                 [&](grpc::Status s) { done.set_value(std::move(s)); });
  if (!done.get_future().get().ok()) return -1;
  std::vector<grpc::Slice> slices;
  (void)out.Dump(&slices);
  std::string bytes;
  for (const auto& s : slices) bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  return bytes.size() >= 2 && bytes[0] == '\x08' ? bytes[1] : 0;  // absent: UNKNOWN (0)
}

inline bool eventually(const std::function<bool()>& condition, std::chrono::milliseconds timeout = 10s) {
  const auto end = Clock::now() + timeout;
  while (Clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(20ms);
  }
  return condition();
}

}  // namespace haarcast::net::test
