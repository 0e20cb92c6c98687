#include "accept_loop.h"

#include <stdexcept>

namespace haarcast::net {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

std::string peerAddress(const tcp::socket& socket) {
  boost::system::error_code ec;
  const auto remote = socket.remote_endpoint(ec);
  return ec ? std::string("?") : clientGroup(remote.address().to_string());
}

AcceptLoop::AcceptLoop(asio::io_context& ioc, std::string what, Log log)
    : ioc_(ioc), what_(std::move(what)), log_(std::move(log)), acceptor_(asio::make_strand(ioc)),
      pause_(acceptor_.get_executor()) {}

void AcceptLoop::listen(const std::string& bindAddress, std::uint16_t port) {
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(bindAddress, ec);
  if (ec) throw std::runtime_error("--bind " + bindAddress + " is not an IP address: " + ec.message());
  const tcp::endpoint endpoint(address, port);
  const bool v6 = bindAddress.find(':') != std::string::npos;
  const std::string where = (v6 ? "[" + bindAddress + "]" : bindAddress) + ":" + std::to_string(port);
  acceptor_.open(endpoint.protocol(), ec);
  if (!ec) acceptor_.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) acceptor_.bind(endpoint, ec);
  if (!ec) acceptor_.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) throw std::runtime_error("cannot listen " + (what_.empty() ? "" : "for " + what_) + "on " + where + ": " + ec.message());
  port_ = acceptor_.local_endpoint(ec).port();
}

void AcceptLoop::start(Handler onConnection) {
  onConnection_ = std::move(onConnection);
  doAccept();
}

void AcceptLoop::close() {
  boost::system::error_code ec;
  pause_.cancel();
  acceptor_.close(ec);
}

void AcceptLoop::doAccept() {
  acceptor_.async_accept(asio::make_strand(ioc_), [this](boost::system::error_code ec, tcp::socket socket) {
    onAccept(ec, std::move(socket));
  });
}

void AcceptLoop::onAccept(boost::system::error_code ec, tcp::socket socket) {
  if (!acceptor_.is_open()) return;
  if (ec) {
    const auto step = backoff_.onError(ec.category() == boost::system::system_category() ? ec.value() : 0);
    if (step.pause.count() == 0) {
      log_(what_ + "accept: " + ec.message());
      doAccept();
      return;
    }
    // Out of descriptors: a retry at once fails again. Pause, and say so
    // once per episode rather than once per retry.
    if (step.episodeStarted) log_(what_ + "accept: " + ec.message() + "; pausing accepts (50 ms, doubling to 1 s) until one succeeds");
    pause_.expires_after(step.pause);
    pause_.async_wait([this](boost::system::error_code waitEc) {
      if (!waitEc) doAccept();
    });
    return;
  }
  if (const int errors = backoff_.errorsInEpisode(); backoff_.onSuccess()) {
    log_(what_ + "accept: recovered after " + std::to_string(errors) + " failed accepts");
  }
  std::string address = peerAddress(socket);
  onConnection_(std::move(socket), std::move(address));
  doAccept();
}

}  // namespace haarcast::net
