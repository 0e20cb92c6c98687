#include "grpc_front.h"

#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

#include "haarcast/net/grpc_rules.h"

namespace haarcast::net {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using unix_stream = asio::local::stream_protocol;

namespace {

// Bytes moved per read, each way: what a connection holds in the front.
constexpr std::size_t kChunk = 16 * 1024;
// After a GOAWAY, how long the client's last bytes are read and dropped
// before the socket closes (a close with unread bytes would send RST, which
// may destroy the GOAWAY before the client reads it).
constexpr auto kLinger = std::chrono::milliseconds(500);

}  // namespace

struct GrpcFront::Shared {
  Shared(Server::Impl& s, Http2Limits l, std::function<void(int)> h) : server(s), rates(l), handOff(std::move(h)) {}
  Server::Impl& server;
  Http2AddressRates rates;
  std::function<void(int)> handOff;
  mutable std::mutex mutex;
  std::map<int, std::string> fdAddress;  // gRPC's descriptor → client group
  bool closed = false;
};

namespace {

// One client connection: client ⇄ front ⇄ gRPC, the client's bytes checked.
class FrontConnection : public std::enable_shared_from_this<FrontConnection> {
 public:
  FrontConnection(std::shared_ptr<GrpcFront::Shared> shared, tcp::socket client, unix_stream::socket inner,
                  Admission::Slot slot, std::string address)
      : shared_(std::move(shared)),
        client_(std::move(client)),
        inner_(std::move(inner)),
        timer_(client_.get_executor()),
        slot_(std::move(slot)),
        address_(std::move(address)),
        guard_(shared_->rates, address_) {}

  ~FrontConnection() { shared_->rates.disconnected(address_); }

  void run() {
    // The preface within the handshake time, as a WebSocket's HTTP request.
    timer_.expires_after(toDuration(shared_->server.options.handshakeSeconds));
    timer_.async_wait([self = shared_from_this()](boost::system::error_code ec) {
      if (!ec && !self->guard_.prefaceDone() && !self->closed_) {
        self->refuse("http2_preface_timeout", "no HTTP/2 preface within the handshake time");
        self->closeAll();
      }
    });
    readClient();
    readServer();
  }

 private:
  Server::Impl& server() { return shared_->server; }

  void refuse(const std::string& label, const std::string& why) {
    server().metrics.addRefusal(label);
    server().logRefusal(address_, "gRPC connection from " + address_ + " cut: " + why);
  }

  // ---------------------------------------------------------------- client → gRPC
  void readClient() {
    client_.async_read_some(asio::buffer(up_), [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
      self->onClientRead(ec, n);
    });
  }

  void onClientRead(boost::system::error_code ec, std::size_t n) {
    if (closed_ || cutting_) return;
    if (ec) {
      // The client is done sending (or gone): gRPC reads the end of its
      // side, finishes, and closes; then the other pump closes everything.
      boost::system::error_code ignored;
      inner_.shutdown(unix_stream::socket::shutdown_send, ignored);
      return;
    }
    if (auto abuse = guard_.feed(std::span<const std::uint8_t>(up_.data(), n), Clock::now())) {
      cut(std::move(*abuse));
      return;
    }
    asio::async_write(inner_, asio::buffer(up_.data(), n),
                      [self = shared_from_this()](boost::system::error_code wec, std::size_t) {
                        if (wec) {
                          self->closeAll();
                        } else {
                          self->readClient();
                        }
                      });
  }

  // ---------------------------------------------------------------- gRPC → client
  void readServer() {
    inner_.async_read_some(asio::buffer(down_), [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
      self->onServerRead(ec, n);
    });
  }

  void onServerRead(boost::system::error_code ec, std::size_t n) {
    if (closed_ || goawaySent_) return;
    if (ec) {
      if (cutting_ && ec == asio::error::operation_aborted) return;  // cut() cancelled this read to send GOAWAY
      closeAll();  // gRPC closed the connection
      return;
    }
    // Cutting: only up to the end of the frame under way, then GOAWAY.
    const std::size_t pass = downFrames_.read(std::span<const std::uint8_t>(down_.data(), n), [](const Http2FrameHeader&) {},
                                              cutting_);
    downWriting_ = true;
    asio::async_write(client_, asio::buffer(down_.data(), pass),
                      [self = shared_from_this()](boost::system::error_code wec, std::size_t) {
                        self->downWriting_ = false;
                        if (wec) {
                          self->closeAll();
                        } else if (self->cutting_ && self->downFrames_.atBoundary()) {
                          self->sendGoaway();
                        } else {
                          self->readServer();
                        }
                      });
  }

  // ---------------------------------------------------------------- the cut
  // Nothing more reaches gRPC; the client gets GOAWAY at the next frame
  // boundary of what gRPC sends, its address a penalty.
  void cut(Http2Abuse abuse) {
    cutting_ = true;
    const auto now = Clock::now();
    if (abuse.code == http2::kEnhanceYourCalm) shared_->rates.penalize(address_, now);
    refuse(abuse.label, abuse.reason + (abuse.code == http2::kEnhanceYourCalm
                                            ? "; GOAWAY, and new gRPC connections from " + address_ + " refused for " +
                                                  std::to_string(static_cast<int>(shared_->rates.limits().penaltySeconds)) + " s"
                                            : ""));
    goaway_ = http2Goaway(guard_.lastStream(), abuse.code, abuse.reason);
    // gRPC's side goes now: its streams end and free what they hold.
    boost::system::error_code ignored;
    timer_.cancel();
    timer_.expires_after(kLinger * 2);
    timer_.async_wait([self = shared_from_this()](boost::system::error_code tec) {
      if (!tec) self->closeAll();  // gRPC never reached a frame boundary in time
    });
    if (!downWriting_ && downFrames_.atBoundary()) {
      inner_.cancel(ignored);
      sendGoaway();
    }
  }

  void sendGoaway() {
    if (goawaySent_ || closed_) return;
    goawaySent_ = true;
    boost::system::error_code ignored;
    inner_.close(ignored);
    asio::async_write(client_, asio::buffer(goaway_), [self = shared_from_this()](boost::system::error_code ec, std::size_t) {
      if (ec) {
        self->closeAll();
        return;
      }
      boost::system::error_code ignored2;
      self->client_.shutdown(tcp::socket::shutdown_send, ignored2);
      self->timer_.cancel();
      self->timer_.expires_after(kLinger);
      self->timer_.async_wait([self](boost::system::error_code tec) {
        if (!tec) self->closeAll();
      });
      self->drainClient();
    });
  }

  // After GOAWAY: the client's bytes read and dropped until it closes.
  void drainClient() {
    client_.async_read_some(asio::buffer(up_), [self = shared_from_this()](boost::system::error_code ec, std::size_t) {
      if (ec) {
        self->closeAll();
      } else if (!self->closed_) {
        self->drainClient();
      }
    });
  }

  void closeAll() {
    if (closed_) return;
    closed_ = true;
    boost::system::error_code ignored;
    timer_.cancel();
    client_.close(ignored);
    inner_.close(ignored);
  }

  std::shared_ptr<GrpcFront::Shared> shared_;
  tcp::socket client_;
  unix_stream::socket inner_;
  asio::steady_timer timer_;
  Admission::Slot slot_;
  std::string address_;
  Http2Guard guard_;
  Http2FrameReader downFrames_;  // gRPC's frames: where a GOAWAY may go
  std::array<std::uint8_t, kChunk> up_{}, down_{};
  std::string goaway_;
  bool cutting_ = false, goawaySent_ = false, downWriting_ = false, closed_ = false;
};

}  // namespace

GrpcFront::GrpcFront(Server::Impl& server, Http2Limits limits, std::function<void(int fd)> handOff)
    : server_(server),
      shared_(std::make_shared<Shared>(server, limits, std::move(handOff))),
      accept_(server.ioc, "gRPC ", [&server](const std::string& line) { server.log("%s", line.c_str()); }) {}

GrpcFront::~GrpcFront() = default;

void GrpcFront::start() {
  accept_.listen(server_.options.bindAddress, *server_.options.grpcPort);
  accept_.start([this](tcp::socket socket, std::string address) { onConnection(std::move(socket), std::move(address)); });
}

void GrpcFront::close() {
  {
    std::lock_guard lock(shared_->mutex);
    shared_->closed = true;
  }
  asio::post(accept_.executor(), [this] { accept_.close(); });
}

std::string GrpcFront::peerGroup(std::string_view peer) const {
  if (peer.starts_with("fd:")) {
    int fd = -1;
    try {
      fd = std::stoi(std::string(peer.substr(3)));
    } catch (const std::exception&) {
      return std::string(peer);
    }
    std::lock_guard lock(shared_->mutex);
    if (const auto it = shared_->fdAddress.find(fd); it != shared_->fdAddress.end()) return it->second;
    return std::string(peer);
  }
  return grpcPeerGroup(peer);
}

void GrpcFront::onConnection(tcp::socket socket, std::string address) {
  boost::system::error_code ignored;
  const auto now = Clock::now();
  if (const double left = shared_->rates.penaltyLeft(address, now); left > 0) {
    // Closed unanswered, as a connection past its address's cap.
    server_.metrics.addRefusal("http2_penalty");
    server_.logRefusal(address, "gRPC connection from " + address + " refused: its connection was cut for HTTP/2 abuse (" +
                                    std::to_string(static_cast<int>(left + 0.5)) + " s left)");
    socket.close(ignored);
    return;
  }
  Admission::Refusal refusal;
  auto slot = server_.admission.take(SlotKind::Connection, address, &refusal);
  if (!slot) {
    server_.metrics.addRefusal(refusal.label);
    socket.close(ignored);
    return;
  }
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, fds) != 0) {
    const int err = errno;
    server_.metrics.addRefusal("descriptors");
    server_.logRefusal(address, std::string("gRPC connection from ") + address +
                                    " closed: no descriptors for its channel to gRPC (" + std::strerror(err) + ")");
    socket.close(ignored);
    return;
  }
  socket.set_option(tcp::no_delay(true), ignored);  // as the WebSocket port (listener.cpp)
  {
    std::lock_guard lock(shared_->mutex);
    if (shared_->closed) {
      ::close(fds[0]);
      ::close(fds[1]);
      socket.close(ignored);
      return;
    }
    shared_->fdAddress[fds[1]] = address;
  }
  shared_->rates.connected(address, now);
  unix_stream::socket inner(socket.get_executor(), unix_stream(), fds[0]);
  auto connection =
      std::make_shared<FrontConnection>(shared_, std::move(socket), std::move(inner), std::move(*slot), address);
  shared_->handOff(fds[1]);
  connection->run();
}

}  // namespace haarcast::net
