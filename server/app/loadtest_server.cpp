#include "loadtest_server.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

namespace haarcast::app {
namespace {

// The child to stop on Ctrl-C: read by the signal handler, so a plain
// sig_atomic_t (pid_t fits: both are int on Linux).
volatile std::sig_atomic_t gChildPid = 0;

extern "C" void onInterrupt(int signal) {
  const pid_t child = static_cast<pid_t>(gChildPid);
  if (child > 0) ::kill(child, SIGTERM);
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return {};
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

constexpr std::string_view kListening = "listening on http://127.0.0.1:";

}  // namespace

double parseProcStatCpuSeconds(std::string_view stat, long ticksPerSecond) {
  // Field 2 (comm) is in parentheses and may hold spaces: count from the
  // last ')'. Field 3 is the first after it; utime and stime are 14 and 15.
  const std::size_t close = stat.rfind(')');
  if (close == std::string_view::npos) throw std::invalid_argument("/proc/PID/stat: no \")\" after the command name");
  std::istringstream rest{std::string(stat.substr(close + 1))};
  std::string field;
  double utime = -1.0, stime = -1.0;
  for (int index = 3; index <= 15 && rest >> field; ++index) {
    if (index == 14) utime = std::stod(field);
    if (index == 15) stime = std::stod(field);
  }
  if (utime < 0.0 || stime < 0.0) throw std::invalid_argument("/proc/PID/stat: fewer than 15 fields (utime, stime)");
  if (ticksPerSecond <= 0) throw std::invalid_argument("clock ticks per second must be positive");
  return (utime + stime) / static_cast<double>(ticksPerSecond);
}

std::optional<std::uint64_t> parseProcStatusKb(std::string_view status, std::string_view field) {
  std::istringstream in{std::string(status)};
  std::string line;
  const std::string key = std::string(field) + ":";
  while (std::getline(in, line)) {
    if (line.compare(0, key.size(), key) != 0) continue;
    std::istringstream value(line.substr(key.size()));
    std::uint64_t kb = 0;
    std::string unit;
    if (!(value >> kb >> unit) || unit != "kB") {
      throw std::invalid_argument("/proc/PID/status: " + std::string(field) + " is not \"N kB\": " + line);
    }
    return kb * 1024;
  }
  return std::nullopt;  // kernel threads and zombies have no VmRSS
}

ProcessFigures procFigures(pid_t pid) {
  ProcessFigures f;
  const std::string base = "/proc/" + std::to_string(pid);
  const std::string stat = readFile(base + "/stat");
  if (!stat.empty()) f.cpuSeconds = parseProcStatCpuSeconds(stat, ::sysconf(_SC_CLK_TCK));
  const std::string status = readFile(base + "/status");
  if (!status.empty()) {
    f.rssBytes = parseProcStatusKb(status, "VmRSS");
    f.peakRssBytes = parseProcStatusKb(status, "VmHWM");
  }
  return f;
}

ProcessFigures parseMetricsFigures(std::string_view text) {
  ProcessFigures f;
  std::istringstream in{std::string(text)};
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string name;
    double value = 0.0;
    if (!(words >> name >> value)) continue;
    if (name == "process_cpu_seconds_total") f.cpuSeconds = value;
    if (name == "process_resident_memory_bytes") f.rssBytes = static_cast<std::uint64_t>(value);
  }
  return f;
}

ProcessFigures fetchMetricsFigures(const std::string& host, const std::string& port) {
  namespace beast = boost::beast;
  namespace http = beast::http;
  try {
    boost::asio::io_context io;
    boost::asio::ip::tcp::resolver resolver(io);
    beast::tcp_stream stream(io);
    stream.expires_after(std::chrono::seconds(5));
    stream.connect(resolver.resolve(host, port));
    http::request<http::empty_body> request(http::verb::get, "/metrics", 11);
    request.set(http::field::host, host + ":" + port);
    http::write(stream, request);
    beast::flat_buffer buffer;
    http::response<http::string_body> response;
    http::read(stream, buffer, response);
    beast::error_code ignored;
    stream.socket().shutdown(boost::asio::ip::tcp::socket::shutdown_both, ignored);
    if (response.result() != http::status::ok) return {};
    return parseMetricsFigures(response.body());
  } catch (const std::exception&) {
    return {};  // no /metrics: the figures are unknown, which the report says (null)
  }
}

LocalServer::LocalServer(const std::vector<std::string>& extraArgs, double startSeconds) {
  std::vector<std::string> args = {"/proc/self/exe", "serve", "--port", "0", "--bind", "127.0.0.1", "--quiet"};
  args.insert(args.end(), extraArgs.begin(), extraArgs.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  int pipeFds[2];
  if (::pipe2(pipeFds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("loadtest: pipe: ") + std::strerror(errno));
  const pid_t parent = ::getpid();
  pid_t pid = ::fork();
  if (pid < 0) {
    ::close(pipeFds[0]);
    ::close(pipeFds[1]);
    throw std::runtime_error(std::string("loadtest: fork: ") + std::strerror(errno));
  }
  if (pid == 0) {
    // Only async-signal-safe calls between fork and exec. The server dies
    // with us, even when we are killed without a chance to stop it.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(127);
    ::dup2(pipeFds[1], STDOUT_FILENO);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(pipeFds[1]);
  pid_ = pid;
  stdoutFd_ = pipeFds[0];
  gChildPid = static_cast<std::sig_atomic_t>(pid);

  // The one line the server prints on stdout once its socket listens.
  std::string line;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(startSeconds);
  while (line.find('\n') == std::string::npos) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p{stdoutFd_, POLLIN, 0};
    const int ready = left.count() > 0 ? ::poll(&p, 1, static_cast<int>(left.count())) : 0;
    if (ready < 0 && errno == EINTR) continue;
    char buffer[256];
    const ssize_t n = ready > 0 ? ::read(stdoutFd_, buffer, sizeof buffer) : 0;
    if (n <= 0) {
      const int code = stop(5.0);
      throw std::runtime_error("loadtest: `haarcast serve` " +
                               std::string(ready == 0 ? "did not listen within " + std::to_string(startSeconds) + " s"
                                                      : "closed its output before listening") +
                               " and ended with status " + std::to_string(code) + " (128 + N: signal N; its messages are above)");
    }
    line.append(buffer, static_cast<std::size_t>(n));
  }
  const std::size_t at = line.find(kListening);
  if (at == std::string::npos) {
    stop(5.0);
    throw std::runtime_error("loadtest: `haarcast serve` printed \"" + line.substr(0, line.find('\n')) +
                             "\", not \"" + std::string(kListening) + "PORT/\"");
  }
  port_ = static_cast<std::uint16_t>(std::stoul(line.substr(at + kListening.size())));
}

LocalServer::~LocalServer() { stop(); }

int LocalServer::stop(double graceSeconds) {
  if (pid_ <= 0) return exitStatus_;
  ::kill(pid_, SIGTERM);
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(graceSeconds);
  bool killed = false;
  for (;;) {
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_ || (r < 0 && errno != EINTR)) break;
    if (!killed && std::chrono::steady_clock::now() > deadline) {
      // It finishes the frame it renders before exiting; past the grace
      // period something is wrong, and it must not outlive us.
      ::kill(pid_, SIGKILL);
      killed = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  gChildPid = 0;
  pid_ = -1;
  if (stdoutFd_ >= 0) ::close(stdoutFd_);
  stdoutFd_ = -1;
  exitStatus_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return exitStatus_;
}

void installInterruptHandler() {
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

}  // namespace haarcast::app
