// One listening port's accept loop, shared by the WebSocket port and the
// gRPC port's front: the port bound (an error names the address), each
// connection handed on with its client group, and a pause when descriptors
// run out (AcceptBackoff, access.h) instead of a busy loop, logged once per
// episode. The port stays open until close(); a failed accept never ends it.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>  // before Asio: its awaitable.hpp uses std::exchange

#include <boost/asio.hpp>

#include "haarcast/net/access.h"

namespace haarcast::net {

class AcceptLoop {
 public:
  using Handler = std::function<void(boost::asio::ip::tcp::socket socket, std::string address)>;
  using Log = std::function<void(const std::string& line)>;

  // `what` names the port in errors and log lines ("", or "gRPC ").
  AcceptLoop(boost::asio::io_context& ioc, std::string what, Log log);

  // Binds and listens; throws std::runtime_error naming the address.
  void listen(const std::string& bindAddress, std::uint16_t port);
  std::uint16_t port() const { return port_; }
  // Accepts until close(); each socket is on a strand of its own.
  void start(Handler onConnection);
  // On the loop's executor: no accept after it.
  void close();
  boost::asio::any_io_executor executor() { return acceptor_.get_executor(); }

 private:
  void doAccept();
  void onAccept(boost::system::error_code ec, boost::asio::ip::tcp::socket socket);

  boost::asio::io_context& ioc_;
  std::string what_;
  Log log_;
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer pause_;
  AcceptBackoff backoff_;
  Handler onConnection_;
  std::uint16_t port_ = 0;
};

// The client group of a connected socket's address (clientGroup: an IPv4
// address or an IPv6 /64): the key of per-address limits and the address
// the log names.
std::string peerAddress(const boost::asio::ip::tcp::socket& socket);

}  // namespace haarcast::net
