#include "haarcast/net/token_guard.h"

#include <stdexcept>

namespace haarcast::net {
namespace {

std::chrono::nanoseconds seconds(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s));
}

}  // namespace

TokenGuard::TokenGuard(Options options) : options_(options) {
  if (options_.maxFailures < 1) throw std::invalid_argument("TokenGuard: maxFailures must be at least 1");
  if (options_.serverMaxFailures < 1) throw std::invalid_argument("TokenGuard: serverMaxFailures must be at least 1");
  if (options_.maxAddresses < 1) throw std::invalid_argument("TokenGuard: maxAddresses must be at least 1");
}

TokenGuard::Lock TokenGuard::check(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(address);
  if (it != entries_.end() && now < it->second.lockedUntil) return Lock::Address;
  const bool trusted = it != entries_.end() && it->second.trusted;
  if (now < serverLockedUntil_ && !trusted) return Lock::Server;
  return Lock::None;
}

void TokenGuard::failed(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  if (serverFailures_ == 0 || now - serverWindowStart_ > seconds(options_.windowSeconds)) {
    serverWindowStart_ = now;
    serverFailures_ = 0;
  }
  if (++serverFailures_ >= options_.serverMaxFailures) {
    serverLockedUntil_ = now + seconds(options_.lockoutSeconds);
    serverFailures_ = 0;
  }
  Entry& e = touch(address, now);
  if (e.failures == 0 || now - e.windowStart > seconds(options_.windowSeconds)) {
    e.windowStart = now;
    e.failures = 0;
  }
  if (++e.failures >= options_.maxFailures) {
    e.lockedUntil = now + seconds(options_.lockoutSeconds);
    e.failures = 0;
  }
}

void TokenGuard::succeeded(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  touch(address, now).trusted = true;
}

std::size_t TokenGuard::addresses() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

TokenGuard::Entry& TokenGuard::touch(const std::string& address, Clock::time_point now) {
  if (const auto it = entries_.find(address); it != entries_.end()) {
    order_.splice(order_.end(), order_, it->second.age);  // now the most recently seen
    return it->second;
  }
  if (entries_.size() >= options_.maxAddresses) makeRoom(now);
  order_.push_back(address);
  Entry& e = entries_[address];
  e.age = std::prev(order_.end());
  return e;
}

void TokenGuard::makeRoom(Clock::time_point now) {
  const auto forget = [&](std::list<std::string>::iterator at) {
    entries_.erase(*at);
    order_.erase(at);
  };
  // Entries that hold nothing any more: no lock, no open window, no trust.
  for (auto at = order_.begin(); at != order_.end();) {
    const Entry& e = entries_.at(*at);
    const auto next = std::next(at);
    if (!e.trusted && now >= e.lockedUntil && now - e.windowStart > seconds(options_.windowSeconds)) forget(at);
    at = next;
  }
  if (entries_.size() < options_.maxAddresses) return;
  // Still full: the least recently seen entry that is not a lock in force.
  for (auto at = order_.begin(); at != order_.end(); ++at) {
    if (now >= entries_.at(*at).lockedUntil) {
      forget(at);
      return;
    }
  }
  forget(order_.begin());  // every entry is a lock: the oldest
}

}  // namespace haarcast::net
