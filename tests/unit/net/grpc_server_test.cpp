// The gRPC transport end to end: the server in process with a gRPC port on
// loopback, driven by the generated stub (haarcast.v1.Render) and, for the
// health service, by gRPC's generic stub with the two tiny messages
// encoded by hand (Debian ships no health.proto).
#include <future>
#include <thread>

#include <google/protobuf/descriptor.pb.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include "haarcast/proto/grpc/reflection/v1/reflection.grpc.pb.h"
#include "haarcast/proto/haarcast.grpc.pb.h"
#include "haarcast/net/listener_probe.h"
#include "grpc_client_fixture.h"
#include "server_fixture.h"

namespace haarcast::net::test {
namespace {

TEST(GrpcServer, HelloWelcomePoseFrameAndTheGrpcMetrics) {
  TestServer server(grpcOptions());
  ASSERT_NE(server.server().grpcPort(), 0);
  ASSERT_NE(server.server().grpcPort(), server.port());
  GrpcClient client(server.server().grpcPort());
  ASSERT_TRUE(client.send(hello(32, 32, v1::ENCODING_PNG)));
  const auto welcome = client.expect(v1::ServerMessage::kWelcome);
  ASSERT_TRUE(welcome) << client.statusAfterReading().error_message();
  EXPECT_EQ(welcome->welcome().width(), 32u);
  EXPECT_EQ(welcome->welcome().encoding(), v1::ENCODING_PNG);
  EXPECT_EQ(welcome->welcome().session_id().front(), 'g') << "gRPC sessions are named g1, g2 …";

  const auto first = client.frameFor(0);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->pose_sequence(), 0u);
  ASSERT_TRUE(client.send(pose(1, 40)));
  const auto turned = client.frameFor(1);
  ASSERT_TRUE(turned);
  EXPECT_EQ(turned->pose_sequence(), 1u);
  EXPECT_EQ(turned->width(), 32u);
  EXPECT_EQ(turned->client_time_ms(), 1001.0) << "echoed from the pose";
  ASSERT_GT(turned->data().size(), 8u);
  EXPECT_EQ(turned->data().substr(1, 3), "PNG");
  EXPECT_NE(turned->data(), first->data()) << "the turned object is another picture";

  const auto& m = server.server().metrics();
  EXPECT_EQ(m.grpcSessions.load(), 1);
  EXPECT_EQ(m.sessions.load(), 1) << "the server-wide gauge counts gRPC sessions too";
  EXPECT_TRUE(client.finish().ok()) << "a client that half-closes gets OK";
  EXPECT_GE(m.grpcFramesTotal.load(), 2u);
  EXPECT_EQ(m.grpcFramesTotal.load(), m.framesTotal.load());
  EXPECT_EQ(m.grpcSessionsTotal.load(), 1u);
  EXPECT_TRUE(eventually([&] { return m.grpcSessions.load() == 0 && m.sessions.load() == 0; }));
  const std::string text = httpGet(server.port(), "/metrics");
  EXPECT_NE(text.find("haarcast_transport_frames_total{transport=\"grpc\"} " + std::to_string(m.grpcFramesTotal.load())),
            std::string::npos);
}

TEST(GrpcServer, AWrongOrMissingTokenIsUnauthenticated) {
  TestServer server(grpcOptions());
  const auto port = server.server().grpcPort();
  {
    GrpcClient client(port, "Bearer not-the-token");
    client.send(hello());
    const auto status = client.statusAfterReading();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
    EXPECT_EQ(status.error_message(), "wrong token");
  }
  {
    GrpcClient client(port, "");
    client.send(hello());
    const auto status = client.statusAfterReading();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  }
  {
    // The right metadata but another token in Hello: the protocol's Error,
    // then the status that says the same.
    GrpcClient client(port);
    auto h = hello();
    h.mutable_hello()->set_auth_token("other");
    client.send(h);
    const auto error = client.expect(v1::ServerMessage::kError);
    ASSERT_TRUE(error);
    EXPECT_EQ(error->error().code(), v1::ERROR_CODE_UNAUTHORIZED);
    EXPECT_TRUE(error->error().fatal());
    EXPECT_EQ(client.statusAfterReading().error_code(), grpc::StatusCode::UNAUTHENTICATED);
  }
  EXPECT_EQ(server.server().metrics().sessionsTotal.load(), 0u);
}

TEST(GrpcServer, HealthIsServingUntilTheSessionBudgetIsFull) {
  ServerOptions o = grpcOptions();
  o.admission.sessions = 1;
  TestServer server(o);
  const auto port = server.server().grpcPort();
  EXPECT_EQ(healthStatus(port), 1) << "SERVING";
  EXPECT_EQ(healthStatus(port, "haarcast.v1.Render"), 1);
  {
    GrpcClient client(port);
    client.send(hello());
    ASSERT_TRUE(client.expect(v1::ServerMessage::kWelcome));
    EXPECT_TRUE(eventually([&] { return healthStatus(port) == 2; })) << "NOT_SERVING at capacity, as /readyz";
    EXPECT_EQ(healthStatus(port, "haarcast.v1.Render"), 2);
    client.finish();
  }
  EXPECT_TRUE(eventually([&] { return healthStatus(port) == 1; })) << "SERVING again once the slot is free";
}

// The port's own probe (listener_probe.h): a live gRPC server answers the
// HTTP/2 preface with SETTINGS, so its /healthz stays 200.
TEST(GrpcServer, ItsListenerProbeIsAnsweredAndHealthzIsOk) {
  TestServer server(grpcOptions());
  EXPECT_EQ(probeHttp2Listener("127.0.0.1", server.server().grpcPort(), std::chrono::milliseconds(2000)),
            ProbeResult::Answered);
  EXPECT_NE(httpGet(server.port(), "/healthz").find("ok"), std::string::npos);
}

// Reflection v1 (server/net/src/grpc_reflection.h), through its generated
// stub: the services listed, a symbol's file with its imports, each file
// once per stream, and errors that say what was not found.
TEST(GrpcServer, ReflectionV1ListsAndDescribesTheServices) {
  namespace r = grpc::reflection::v1;
  TestServer server(grpcOptions());
  const auto stub = r::ServerReflection::NewStub(channelTo(server.server().grpcPort()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));
  const auto stream = stub->ServerReflectionInfo(&context);
  auto ask = [&](const r::ServerReflectionRequest& request) {
    r::ServerReflectionResponse response;
    EXPECT_TRUE(stream->Write(request));
    EXPECT_TRUE(stream->Read(&response));
    return response;
  };
  r::ServerReflectionRequest list;
  list.set_list_services("");
  const r::ServerReflectionResponse listed = ask(list);
  ASSERT_TRUE(listed.has_list_services_response());
  std::vector<std::string> names;
  for (const auto& service : listed.list_services_response().service()) names.push_back(service.name());
  EXPECT_EQ(names, (std::vector<std::string>{"haarcast.v1.Render", "grpc.health.v1.Health",
                                             "grpc.reflection.v1.ServerReflection",
                                             "grpc.reflection.v1alpha.ServerReflection"}));

  r::ServerReflectionRequest symbol;
  symbol.set_file_containing_symbol("haarcast.v1.Render.Session");
  const r::ServerReflectionResponse described = ask(symbol);
  ASSERT_TRUE(described.has_file_descriptor_response());
  ASSERT_GE(described.file_descriptor_response().file_descriptor_proto_size(), 1);
  google::protobuf::FileDescriptorProto file;
  ASSERT_TRUE(file.ParseFromString(described.file_descriptor_response().file_descriptor_proto(0)));
  EXPECT_EQ(file.name(), "haarcast.proto") << "the file that declares the symbol comes first";
  ASSERT_EQ(file.service_size(), 1);
  EXPECT_EQ(file.service(0).name(), "Render");
  EXPECT_EQ(file.service(0).method(0).name(), "Session");
  EXPECT_TRUE(file.service(0).method(0).client_streaming() && file.service(0).method(0).server_streaming());
  EXPECT_EQ(described.original_request().file_containing_symbol(), "haarcast.v1.Render.Session");
  // The same file again on this stream: already sent, so not again.
  symbol.set_file_containing_symbol("haarcast.v1.ClientMessage");
  const r::ServerReflectionResponse again = ask(symbol);
  ASSERT_TRUE(again.has_file_descriptor_response());
  EXPECT_EQ(again.file_descriptor_response().file_descriptor_proto_size(), 0);

  r::ServerReflectionRequest byName;
  byName.set_file_by_filename("grpc/reflection/v1/reflection.proto");
  const r::ServerReflectionResponse own = ask(byName);
  ASSERT_TRUE(own.has_file_descriptor_response());
  ASSERT_EQ(own.file_descriptor_response().file_descriptor_proto_size(), 1);
  ASSERT_TRUE(file.ParseFromString(own.file_descriptor_response().file_descriptor_proto(0)));
  EXPECT_EQ(file.package(), "grpc.reflection.v1");

  symbol.set_file_containing_symbol("haarcast.v1.NoSuchThing");
  const r::ServerReflectionResponse missing = ask(symbol);
  ASSERT_TRUE(missing.has_error_response());
  EXPECT_EQ(missing.error_response().error_code(), static_cast<int>(grpc::StatusCode::NOT_FOUND));
  EXPECT_NE(missing.error_response().error_message().find("haarcast.v1.NoSuchThing"), std::string::npos);
  const r::ServerReflectionResponse empty = ask(r::ServerReflectionRequest{});
  ASSERT_TRUE(empty.has_error_response());
  EXPECT_EQ(empty.error_response().error_code(), static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT));
  r::ServerReflectionRequest numbers;
  numbers.set_all_extension_numbers_of_type("haarcast.v1.ClientMessage");
  const r::ServerReflectionResponse none = ask(numbers);
  ASSERT_TRUE(none.has_all_extension_numbers_response());
  EXPECT_EQ(none.all_extension_numbers_response().base_type_name(), "haarcast.v1.ClientMessage");
  EXPECT_EQ(none.all_extension_numbers_response().extension_number_size(), 0) << "proto3: no extensions";

  stream->WritesDone();
  EXPECT_TRUE(stream->Finish().ok());
}

// The pre-Hello budget holds for gRPC streams: when a newcomer from another
// address takes a silent stream's slot, that stream ends (it used to stay
// open, uncounted) with RESOURCE_EXHAUSTED, and the live pending count
// stays within the budget.
TEST(GrpcServer, AnEvictedSilentStreamIsEnded) {
  ServerOptions o = grpcOptions();
  o.admission.pending = 2;
  o.admission.pendingPerAddress = 2;
  TestServer server(o);
  const auto grpcPort = server.server().grpcPort();
  // Silent streams, no Hello. Each client has its own channel, so two opened
  // back to back may reach the server in either order: the second is opened
  // only once the first is counted, which makes `first` the oldest.
  GrpcClient first(grpcPort);
  ASSERT_TRUE(eventually([&] { return metric(server.port(), "haarcast_pending_connections") == 1; }));
  GrpcClient second(grpcPort);
  ASSERT_TRUE(eventually([&] { return metric(server.port(), "haarcast_pending_connections") == 2; }));
  Client newcomer(server.port(), std::string("/ws?token=") + kToken, 0, "127.0.0.7");
  ASSERT_TRUE(newcomer.connected());
  newcomer.handshake();
  const grpc::Status ended = first.statusAfterReading();  // the oldest of the largest holder
  EXPECT_EQ(ended.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << ended.error_message();
  EXPECT_NE(ended.error_message().find("pre-Hello budget is full"), std::string::npos) << ended.error_message();
  EXPECT_EQ(metric(server.port(), "haarcast_session_cuts_total{reason=\"pending_evicted\"}"), 1);
  EXPECT_TRUE(eventually([&] { return metric(server.port(), "haarcast_pending_connections") <= 2; }));
  second.send(hello());
  EXPECT_TRUE(second.expect(v1::ServerMessage::kWelcome)) << "the other silent stream is still served";
  second.finish();
}

// A stream writes no log line before its Hello: a thousand streams opened
// and reset (HTTP/2 rapid reset) must not write two thousand lines. One
// that says Hello is logged from "opened" to "closed".
TEST(GrpcServer, StreamsAreLoggedFromTheirHelloOn) {
  TestServer server(grpcOptions());
  const auto grpcPort = server.server().grpcPort();
  testing::internal::CaptureStderr();
  for (int i = 0; i < 5; ++i) {
    GrpcClient silent(grpcPort);
    ASSERT_TRUE(eventually([&] { return metric(server.port(), "haarcast_pending_connections") == 1; }));
    silent.context().TryCancel();
    ASSERT_TRUE(eventually([&] { return metric(server.port(), "haarcast_pending_connections") == 0; }));
  }
  const std::string silentLog = testing::internal::GetCapturedStderr();
  EXPECT_EQ(silentLog.find("[serve]"), std::string::npos) << silentLog;
  testing::internal::CaptureStderr();
  {
    GrpcClient client(grpcPort);
    client.send(hello());
    ASSERT_TRUE(client.expect(v1::ServerMessage::kWelcome));
    client.finish();
  }
  ASSERT_TRUE(eventually([&] { return metric(server.port(), "haarcast_sessions") == 0; }));
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("opened from 127.0.0.1 (gRPC)"), std::string::npos) << log;
  EXPECT_NE(log.find(": closed ("), std::string::npos) << log;
}

TEST(GrpcServer, SessionSlotsAreSharedWithWebSocketSessions) {
  ServerOptions o = grpcOptions();
  o.admission.sessionsPerAddress = 1;
  TestServer server(o);
  Client ws(server.port());
  ASSERT_TRUE(ws.connected());
  ws.handshake();
  GrpcClient client(server.server().grpcPort());
  client.send(hello());
  const auto error = client.expect(v1::ServerMessage::kError);
  ASSERT_TRUE(error);
  EXPECT_EQ(error->error().code(), v1::ERROR_CODE_TOO_MANY_SESSIONS);
  EXPECT_NE(error->error().message().find("each address may have 1"), std::string::npos) << error->error().message();
  EXPECT_EQ(client.statusAfterReading().error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
}

TEST(GrpcServer, StopSendsShuttingDownAndReturnsPromptly) {
  TestServer server(grpcOptions());
  GrpcClient client(server.server().grpcPort());
  client.send(hello());
  ASSERT_TRUE(client.frameFor(0));
  const auto start = Clock::now();
  std::jthread stopper([&] {  // joined also when an assertion returns early
    server.server().stop();
    server.server().wait();
  });
  const auto error = client.expect(v1::ServerMessage::kError);
  ASSERT_TRUE(error);
  EXPECT_EQ(error->error().code(), v1::ERROR_CODE_SHUTTING_DOWN);
  const auto status = client.statusAfterReading();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE) << status.error_message();
  stopper.join();
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_LT(seconds, 1.5) << "the session closed at once, so the drain did not wait for its deadline";
}

TEST(GrpcServer, AClientThatStopsReadingIsCutAndAnotherGoesOn) {
  TestServer server(grpcOptions());
  const auto port = server.server().grpcPort();
  GrpcClient stalled(port, std::string("Bearer ") + kToken, Window::kFixed);
  stalled.send(hello(256, 256, v1::ENCODING_RAW_RGBA8, 30));
  ASSERT_TRUE(stalled.expect(v1::ServerMessage::kWelcome));
  GrpcClient other(port);
  other.send(hello(32, 32));
  ASSERT_TRUE(other.frameFor(0));
  // The stalled client sends poses and never reads: its first 256 KiB frame
  // fills the HTTP/2 window, the server's write stops completing, and after
  // writeStallSeconds (1.5 s here) the server cuts it.
  const auto& m = server.server().metrics();
  std::uint64_t sequence = 0;
  int otherFrames = 0;
  const auto end = Clock::now() + 20s;
  while (m.grpcSessions.load() == 2 && Clock::now() < end) {
    ++sequence;
    stalled.send(pose(sequence, static_cast<double>(sequence)));
    other.send(pose(sequence, static_cast<double>(sequence)));
    if (other.frameFor(sequence)) ++otherFrames;
  }
  EXPECT_EQ(m.grpcSessions.load(), 1) << "the stalled session was cut";
  EXPECT_NE(httpGet(server.port(), "/metrics").find("haarcast_session_cuts_total{reason=\"write_stall\"} 1"),
            std::string::npos);
  EXPECT_GE(otherFrames, 10) << "the other client got frames meanwhile";
  other.send(pose(++sequence, 5));
  EXPECT_TRUE(other.frameFor(sequence)) << "and goes on after the cut";
  EXPECT_EQ(stalled.statusAfterReading().error_code(), grpc::StatusCode::CANCELLED);
}

// Both transports carry a build's progress: the same RenderSession, the
// same submitPrepare (session_jobs.h). Each client asks for a renderer of
// its own (another level), so each sees a build from its start.
TEST(GrpcServer, BuildProgressReachesBothTransportsBeforeWelcome) {
  const RendererBuilder real = testBuilder();
  AbandonableRendererBuilder builder = [real](const SessionConfig& c, const std::function<bool()>&,
                                              const render::RenderProgress& progress) {
    for (std::size_t i = 0; i <= 10; ++i) {
      progress("visibility /srv/meshes/ball", i, 10);
      std::this_thread::sleep_for(30ms);
    }
    return real(c);
  };
  TestServer server(grpcOptions(), builder);
  // The messages before the first frame: BuildProgress …, then Welcome.
  const auto check = [](const std::vector<v1::ServerMessage>& messages, const char* transport) {
    ASSERT_GE(messages.size(), 2u) << transport;
    EXPECT_TRUE(messages.back().has_welcome()) << transport;
    for (std::size_t i = 0; i + 1 < messages.size(); ++i) {
      ASSERT_TRUE(messages[i].has_build_progress()) << transport << ": " << messages[i].DebugString();
      EXPECT_EQ(messages[i].build_progress().stage(), "visibility ball") << transport;
    }
  };
  auto untilWelcome = [](auto& client) {
    std::vector<v1::ServerMessage> messages;
    while (auto m = client.read()) {
      if (m->has_stats()) continue;
      messages.push_back(*m);
      if (m->has_welcome() || m->has_error()) break;
    }
    return messages;
  };
  GrpcClient grpcClient(server.server().grpcPort());
  v1::ClientMessage h = hello();
  h.mutable_hello()->mutable_settings()->set_level(3);
  ASSERT_TRUE(grpcClient.send(h));
  check(untilWelcome(grpcClient), "gRPC");
  Client wsClient(server.port());
  ASSERT_TRUE(wsClient.connected());
  h.mutable_hello()->mutable_settings()->set_level(5);
  wsClient.send(h);
  check(untilWelcome(wsClient), "WebSocket");
  EXPECT_TRUE(grpcClient.finish().ok());
}

}  // namespace
}  // namespace haarcast::net::test
