// Log lines for refused requests, at a rate a flood cannot raise: the first
// refusal of an address in each period is written in full; the rest are
// only counted, and once a period that had any left unwritten ends, one
// summary line says how many refusals came from how many addresses. A
// flood of refusals writes at most one line per address per period (the
// addresses remembered are bounded too), plus the summary.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>

namespace haarcast::net {

class RefusalLog {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr double kPeriodSeconds = 60.0;
  static constexpr std::size_t kMaxAddresses = 4096;

  explicit RefusalLog(double periodSeconds = kPeriodSeconds, std::size_t maxAddresses = kMaxAddresses);

  // One refusal from `address`: true when its line should be written.
  bool note(const std::string& address, Clock::time_point now);
  // When the period has ended: its summary line if some refusals were not
  // written one by one ("1200 refusals from 200 addresses in the last
  // 60 s; 1000 not logged one by one"), and a new period starts. nullopt
  // when the period runs on or nothing was held back.
  std::optional<std::string> summary(Clock::time_point now);

 private:
  void rollOver(Clock::time_point now);
  double periodSeconds_;
  std::size_t maxAddresses_;
  std::mutex mutex_;
  bool started_ = false;
  Clock::time_point periodStart_;
  std::unordered_map<std::string, std::uint64_t> perAddress_;  // refusals this period
  std::uint64_t refusals_ = 0, unwritten_ = 0;
  std::uint64_t pastRefusals_ = 0, pastUnwritten_ = 0, pastAddresses_ = 0;  // the period that ended, not yet summarised
};

}  // namespace haarcast::net
