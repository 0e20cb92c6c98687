#include "haarcast/net/refusal_log.h"

#include <stdexcept>

namespace haarcast::net {

RefusalLog::RefusalLog(double periodSeconds, std::size_t maxAddresses)
    : periodSeconds_(periodSeconds), maxAddresses_(maxAddresses) {
  if (!(periodSeconds_ > 0.0)) throw std::invalid_argument("RefusalLog: the period must be positive");
  if (maxAddresses_ < 1) throw std::invalid_argument("RefusalLog: maxAddresses must be at least 1");
}

void RefusalLog::rollOver(Clock::time_point now) {
  if (!started_) {
    started_ = true;
    periodStart_ = now;
    return;
  }
  if (std::chrono::duration<double>(now - periodStart_).count() < periodSeconds_) return;
  // Kept for summary(); a later period with nothing in it does not erase them.
  if (refusals_ > 0) {
    pastRefusals_ += refusals_;
    pastUnwritten_ += unwritten_;
    pastAddresses_ += perAddress_.size();
  }
  perAddress_.clear();
  refusals_ = unwritten_ = 0;
  periodStart_ = now;
}

bool RefusalLog::note(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  rollOver(now);
  ++refusals_;
  const auto it = perAddress_.find(address);
  if (it != perAddress_.end()) {
    ++it->second;
    ++unwritten_;
    return false;
  }
  // Past the bound every new address is only counted: a spray of addresses
  // must not grow the table or the log.
  if (perAddress_.size() >= maxAddresses_) {
    ++unwritten_;
    return false;
  }
  perAddress_.emplace(address, 1);
  return true;
}

std::optional<std::string> RefusalLog::summary(Clock::time_point now) {
  std::lock_guard lock(mutex_);
  rollOver(now);
  const std::uint64_t refusals = pastRefusals_, unwritten = pastUnwritten_, addresses = pastAddresses_;
  pastRefusals_ = pastUnwritten_ = pastAddresses_ = 0;
  if (unwritten == 0) return std::nullopt;
  return std::to_string(refusals) + " refusals from " + std::to_string(addresses) + " address" +
         (addresses == 1 ? "" : "es") + " in the last " + std::to_string(static_cast<long long>(periodSeconds_)) +
         " s; " + std::to_string(unwritten) + " not logged one by one";
}

}  // namespace haarcast::net
