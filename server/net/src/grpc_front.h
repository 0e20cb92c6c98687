// The gRPC port's front: the server's own accept loop on the gRPC port, in
// front of a gRPC server that listens on nothing. gRPC 1.51 (Debian 12)
// cannot hold the line alone: its listener stops for good after an accept
// fails for want of descriptors (CVE-2023-4785), it has no per-address
// connection cap, and it predates the rapid-reset mitigations
// (CVE-2023-44487). So each connection is accepted here (AcceptLoop: the
// WebSocket port's back-off), takes a connection slot from the same
// Admission as a WebSocket connection, and reaches gRPC through a socket
// pair (grpc::AddInsecureChannelFromFd); its bytes pass through an
// Http2Guard (http2_guard.h), which cuts the connection with a GOAWAY when
// it opens or resets streams too fast, and its address is then refused new
// gRPC connections for a while.
//
// Cost: one copy of each byte through a Unix socket pair and two more
// descriptors per connection; the bytes are never parsed past frame headers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include "accept_loop.h"
#include "haarcast/net/http2_guard.h"
#include "server_impl.h"

namespace haarcast::net {

class GrpcFront {
 public:
  // `handOff` gives gRPC one end of a connection's socket pair (it owns
  // the descriptor from then on).
  GrpcFront(Server::Impl& server, Http2Limits limits, std::function<void(int fd)> handOff);
  ~GrpcFront();
  GrpcFront(const GrpcFront&) = delete;
  GrpcFront& operator=(const GrpcFront&) = delete;

  // Binds options.bindAddress:grpcPort (throws naming it), then accepts.
  void start();
  std::uint16_t port() const { return accept_.port(); }
  // No new connection from now on (the open ones end with gRPC's).
  void close();

  // The client group behind a gRPC peer string: "fd:N" is a connection this
  // front handed to gRPC as descriptor N; anything else as grpcPeerGroup.
  std::string peerGroup(std::string_view peer) const;

  struct Shared;

 private:
  void onConnection(boost::asio::ip::tcp::socket socket, std::string address);

  Server::Impl& server_;
  std::shared_ptr<Shared> shared_;
  AcceptLoop accept_;
};

}  // namespace haarcast::net
