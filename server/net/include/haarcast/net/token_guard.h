// Token guesses: a limit per address and one across the server. Per
// address, `maxFailures` wrong tokens within `windowSeconds` lock it out
// (HTTP 429) for `lockoutSeconds`. Across the server, `serverMaxFailures`
// wrong tokens within `windowSeconds`, from any number of addresses, lock
// out every address that has not presented the right token before, for
// `lockoutSeconds`: a guesser with many addresses (a botnet, an IPv6
// range) is slowed as a whole, while known clients go on.
//
// The table of addresses is bounded (`maxAddresses`). When it is full an
// entry whose lock and window are over goes first, then the least recently
// seen one that is not locked, and a locked one only when every entry is
// locked — never by the address's value, so a spray of fresh addresses
// cannot pick which lock it erases, and the server-wide limit stops the
// spray long before the table fills.
#pragma once

#include <chrono>
#include <cstddef>
#include <list>
#include <mutex>
#include <string>
#include <unordered_map>

namespace haarcast::net {

using Clock = std::chrono::steady_clock;

class TokenGuard {
 public:
  struct Options {
    int maxFailures = 5;
    double windowSeconds = 60.0;
    double lockoutSeconds = 60.0;
    int serverMaxFailures = 100;
    std::size_t maxAddresses = 4096;
  };
  enum class Lock { None, Address, Server };

  explicit TokenGuard(Options options);

  // Whether `address` may present a token now, and if not, which limit holds it.
  Lock check(const std::string& address, Clock::time_point now);
  bool locked(const std::string& address, Clock::time_point now) { return check(address, now) != Lock::None; }
  // A wrong token from `address` (a missing one is not a guess).
  void failed(const std::string& address, Clock::time_point now);
  // The right token from `address`: it passes a server-wide lock from now on.
  void succeeded(const std::string& address, Clock::time_point now);

  std::size_t addresses() const;  // entries in the table, for tests
  const Options& options() const { return options_; }

 private:
  struct Entry {
    Clock::time_point windowStart;
    int failures = 0;
    Clock::time_point lockedUntil;
    bool trusted = false;  // presented the right token
    std::list<std::string>::iterator age;  // in order_
  };
  Entry& touch(const std::string& address, Clock::time_point now);  // finds or makes room and inserts
  void makeRoom(Clock::time_point now);

  Options options_;
  mutable std::mutex mutex_;
  std::unordered_map<std::string, Entry> entries_;
  std::list<std::string> order_;  // least recently seen first
  Clock::time_point serverWindowStart_;
  int serverFailures_ = 0;
  Clock::time_point serverLockedUntil_;
};

}  // namespace haarcast::net
