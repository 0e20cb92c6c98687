// Slots, counted server-wide and per client address (clientGroup: an IPv4
// address or an IPv6 /64). A connection slot is held from accept to close;
// a pending slot from the upgrade to the Hello (the pre-Hello budget); a
// session slot from a valid Hello to close — only then does a client count
// toward --max-sessions.
//
// The server-wide budgets are shared so that a few addresses cannot take
// them all and keep everyone else out:
//   pending   when the budget is full, a new upgrade from an address that
//             holds fewer pending slots than the largest holder evicts that
//             holder's oldest silent connection (its owner is told through
//             the slot's eviction callback and closes it). A new address
//             (none held) is therefore never refused for the budget.
//   sessions  the last `sessionReserve` free slots are kept for addresses
//             that hold no session: an address with one stops there. A
//             group of G addresses can then fill at most
//             sessions − reserve + (G − 1) slots, so with the default
//             reserve of min(8, sessions / 4) no 8 addresses fill a budget
//             of 64 (at most 60).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

namespace haarcast::net {

enum class SlotKind { Connection, Pending, Session };
std::string_view slotKindName(SlotKind kind);  // "connection", "pending", "session"

class Admission {
 public:
  struct Limits {
    int connectionsPerAddress = 32;
    int pending = 64;
    int pendingPerAddress = 8;
    int sessions = 64;
    int sessionsPerAddress = 16;
    // Session slots kept for addresses that hold none; -1: min(8, sessions / 4).
    int sessionReserve = -1;
  };

  // Releases its slot when destroyed. Move-only; an empty Slot holds none.
  class Slot {
   public:
    Slot() = default;
    Slot(Slot&& other) noexcept;
    Slot& operator=(Slot&& other) noexcept;
    ~Slot();
    explicit operator bool() const { return owner_ != nullptr; }
    void release();
    // A pending slot: `evicted` is called (once, on the thread that takes
    // the slot that evicts it) when a newcomer takes its place; the slot no
    // longer counts from then on. Returns false, without keeping `evicted`,
    // when that has already happened: close the connection now.
    bool onEvicted(std::function<void()> evicted);

   private:
    friend class Admission;
    Slot(Admission* owner, SlotKind kind, std::string address, std::uint64_t id);
    Admission* owner_ = nullptr;
    SlotKind kind_ = SlotKind::Connection;
    std::string address_;
    std::uint64_t id_ = 0;
  };

  // Why a slot was refused.
  struct Refusal {
    bool perAddress = false;  // the address's own cap or share (429), else the server's (503)
    std::string reason;       // names the limit and its value
    std::string label;        // for /metrics: "pending", "sessions_per_address", "sessions_reserved" …
  };

  explicit Admission(Limits limits);
  // The slot, or why not. The Admission must outlive its slots.
  std::optional<Slot> take(SlotKind kind, const std::string& address, Refusal* refusal = nullptr);

  // True when a client from an address that holds nothing would be refused
  // a pending or a session slot now (/readyz answers 503).
  bool fullForNewAddress() const;
  int sessionReserve() const { return sessionReserve_; }
  std::uint64_t evictions() const;

  int count(SlotKind kind) const;                                   // server-wide
  int count(SlotKind kind, const std::string& address) const;       // one address
  const Limits& limits() const { return limits_; }

 private:
  struct Pending {
    std::string address;
    std::function<void()> evicted;
  };
  void give(SlotKind kind, const std::string& address, std::uint64_t id);
  void uncount(SlotKind kind, const std::string& address);  // under mutex_
  // Under mutex_: frees the oldest pending slot of the largest holder when
  // `mine` holds fewer; returns its callback (to call outside the lock).
  std::optional<std::function<void()>> evictFor(int mine);

  Limits limits_;
  int sessionReserve_ = 0;
  mutable std::mutex mutex_;
  int total_[3] = {0, 0, 0};
  std::map<std::string, std::array<int, 3>> perAddress_;
  std::map<std::uint64_t, Pending> pending_;  // by id: oldest first
  std::uint64_t nextId_ = 1;
  std::uint64_t evictions_ = 0;
};

}  // namespace haarcast::net
