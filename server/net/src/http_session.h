// One HTTP connection: GET requests for the client's files, /healthz,
// /readyz, /metrics and /haarcast.proto, and the WebSocket upgrade at /ws
// after its checks (path, Host, Origin, token and its guess limit, draining, the
// pre-Hello budget). Every response is counted by status in /metrics.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

#include "server_impl.h"

namespace haarcast::net {

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(Server::Impl& server, boost::asio::ip::tcp::socket&& socket, Admission::Slot connection,
              std::string address);
  void run();

 private:
  using Request = boost::beast::http::request<boost::beast::http::string_body>;
  using Response = boost::beast::http::response<boost::beast::http::string_body>;

  void doRead();
  void onRead(boost::beast::error_code ec);
  void upgrade(Request request);
  void serve(const Request& request);
  // `refusal`: the /metrics reason of a refused upgrade.
  void refuse(const Request& request, Response res, std::string body, const char* refusal, bool keepAlive = false);
  void respond(const Request& request, boost::beast::http::status status, std::string body, const std::string& type,
               bool keepAlive);
  void respond(const Request& request, Response res, std::string body, const std::string& type, bool keepAlive);

  Server::Impl& server_;
  boost::beast::tcp_stream stream_;
  boost::beast::flat_buffer buffer_;
  std::optional<boost::beast::http::request_parser<boost::beast::http::string_body>> parser_;
  Admission::Slot connectionSlot_;
  std::string address_;
};

}  // namespace haarcast::net
