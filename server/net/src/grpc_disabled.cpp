// The Server without its gRPC transport (configured with -DHAARCAST_GRPC=OFF):
// a gRPC port is refused at start, naming why.
#include <stdexcept>

#include "grpc_server.h"

namespace haarcast::net {

struct GrpcServer::State {};

GrpcServer::GrpcServer(Server::Impl&) {
  throw std::runtime_error("this haarcast was built without gRPC (-DHAARCAST_GRPC=OFF): --grpc-port is not available");
}
GrpcServer::~GrpcServer() = default;
std::uint16_t GrpcServer::port() const { return 0; }
std::optional<std::string> GrpcServer::listenerProblem() const { return std::nullopt; }
std::size_t GrpcServer::sessionCount() const { return 0; }
void GrpcServer::stopSessions() {}
void GrpcServer::shutdownThen(std::function<void()> then) {
  if (then) then();
}
void GrpcServer::join() {}
void GrpcServer::add(const GrpcSession*, std::weak_ptr<GrpcSession>) {}
void GrpcServer::remove(const GrpcSession*) {}

}  // namespace haarcast::net
