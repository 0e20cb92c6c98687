#include "haarcast/net/admission.h"

#include <algorithm>
#include <utility>

namespace haarcast::net {
namespace {

// The group of addresses the session reserve is sized against.
constexpr int kReserveGroup = 8;

}  // namespace

std::string_view slotKindName(SlotKind kind) {
  switch (kind) {
    case SlotKind::Connection: return "connection";
    case SlotKind::Pending: return "pending";
    case SlotKind::Session: return "session";
  }
  return "?";
}

Admission::Slot::Slot(Admission* owner, SlotKind kind, std::string address, std::uint64_t id)
    : owner_(owner), kind_(kind), address_(std::move(address)), id_(id) {}

Admission::Slot::Slot(Slot&& other) noexcept
    : owner_(std::exchange(other.owner_, nullptr)), kind_(other.kind_), address_(std::move(other.address_)),
      id_(other.id_) {}

Admission::Slot& Admission::Slot::operator=(Slot&& other) noexcept {
  if (this != &other) {
    release();
    owner_ = std::exchange(other.owner_, nullptr);
    kind_ = other.kind_;
    address_ = std::move(other.address_);
    id_ = other.id_;
  }
  return *this;
}

Admission::Slot::~Slot() { release(); }

void Admission::Slot::release() {
  if (owner_) std::exchange(owner_, nullptr)->give(kind_, address_, id_);
}

bool Admission::Slot::onEvicted(std::function<void()> evicted) {
  if (!owner_ || kind_ != SlotKind::Pending) return true;  // nothing to evict
  std::lock_guard lock(owner_->mutex_);
  const auto it = owner_->pending_.find(id_);
  if (it == owner_->pending_.end()) return false;
  it->second.evicted = std::move(evicted);
  return true;
}

Admission::Admission(Limits limits) : limits_(limits) {
  sessionReserve_ = limits_.sessionReserve >= 0 ? limits_.sessionReserve
                                                : std::min(kReserveGroup, limits_.sessions / 4);
  // A reserve as large as the budget would keep every address to one session.
  sessionReserve_ = std::clamp(sessionReserve_, 0, std::max(0, limits_.sessions - 1));
}

std::optional<std::function<void()>> Admission::evictFor(int mine) {
  int most = 0;
  for (const auto& [address, counts] : perAddress_) most = std::max(most, counts[static_cast<std::size_t>(SlotKind::Pending)]);
  if (most <= mine) return std::nullopt;  // nobody holds more than the newcomer: it waits
  for (auto it = pending_.begin(); it != pending_.end(); ++it) {
    const auto holder = perAddress_.find(it->second.address);
    if (holder == perAddress_.end() || holder->second[static_cast<std::size_t>(SlotKind::Pending)] != most) continue;
    std::function<void()> evicted = std::move(it->second.evicted);
    uncount(SlotKind::Pending, it->second.address);
    pending_.erase(it);
    ++evictions_;
    return evicted ? evicted : [] {};
  }
  return std::nullopt;
}

std::optional<Admission::Slot> Admission::take(SlotKind kind, const std::string& address, Refusal* refusal) {
  const auto k = static_cast<std::size_t>(kind);
  std::optional<std::function<void()>> evicted;
  std::optional<Slot> slot;
  Refusal r;
  {
    std::lock_guard lock(mutex_);
    auto& mine = perAddress_[address];
    const auto perAddress = [&](const char* what, int cap, const char* label) {
      r = {true, std::string("too many ") + what + " from " + address + ": each address may have " + std::to_string(cap),
           label};
    };
    const auto server = [&](const char* what, int cap, const char* label) {
      r = {false, std::string("too many ") + what + ": the server allows " + std::to_string(cap), label};
    };
    switch (kind) {
      case SlotKind::Connection:
        // The listen backlog and the file-descriptor limit bound these server-wide.
        if (mine[k] >= limits_.connectionsPerAddress) {
          perAddress("connections", limits_.connectionsPerAddress, "connections_per_address");
        }
        break;
      case SlotKind::Pending:
        if (mine[k] >= limits_.pendingPerAddress) {
          perAddress("connections waiting for a Hello", limits_.pendingPerAddress, "pending_per_address");
        } else if (total_[k] >= limits_.pending && !(evicted = evictFor(mine[k]))) {
          server("connections waiting for a Hello", limits_.pending, "pending");
        }
        break;
      case SlotKind::Session:
        if (total_[k] >= limits_.sessions) {
          server("sessions", limits_.sessions, "sessions");
        } else if (mine[k] >= limits_.sessionsPerAddress) {
          perAddress("sessions", limits_.sessionsPerAddress, "sessions_per_address");
        } else if (mine[k] > 0 && limits_.sessions - total_[k] <= sessionReserve_) {
          r = {true,
               "too many sessions from " + address + ": it has " + std::to_string(mine[k]) + ", and the last " +
                   std::to_string(sessionReserve_) + " of the server's " + std::to_string(limits_.sessions) +
                   " are kept for other addresses",
               "sessions_reserved"};
        }
        break;
    }
    if (r.label.empty()) {
      ++total_[k];
      ++mine[k];
      const std::uint64_t id = nextId_++;
      if (kind == SlotKind::Pending) pending_.emplace(id, Pending{address, {}});
      slot = Slot(this, kind, address, id);
    } else if (mine == std::array<int, 3>{0, 0, 0}) {
      perAddress_.erase(address);
    }
  }
  if (evicted) (*evicted)();  // outside the lock: it may touch other slots
  if (!slot && refusal) *refusal = std::move(r);
  return slot;
}

void Admission::uncount(SlotKind kind, const std::string& address) {
  const auto k = static_cast<std::size_t>(kind);
  --total_[k];
  const auto it = perAddress_.find(address);
  if (it == perAddress_.end()) return;
  --it->second[k];
  if (it->second == std::array<int, 3>{0, 0, 0}) perAddress_.erase(it);
}

void Admission::give(SlotKind kind, const std::string& address, std::uint64_t id) {
  std::lock_guard lock(mutex_);
  // An evicted pending slot was uncounted when it was evicted.
  if (kind == SlotKind::Pending && pending_.erase(id) == 0) return;
  uncount(kind, address);
}

bool Admission::fullForNewAddress() const {
  std::lock_guard lock(mutex_);
  if (total_[static_cast<std::size_t>(SlotKind::Session)] >= limits_.sessions) return true;
  // Pending: full, and no holder with a slot to give up.
  return total_[static_cast<std::size_t>(SlotKind::Pending)] >= limits_.pending && pending_.empty();
}

std::uint64_t Admission::evictions() const {
  std::lock_guard lock(mutex_);
  return evictions_;
}

int Admission::count(SlotKind kind) const {
  std::lock_guard lock(mutex_);
  return total_[static_cast<std::size_t>(kind)];
}

int Admission::count(SlotKind kind, const std::string& address) const {
  std::lock_guard lock(mutex_);
  const auto it = perAddress_.find(address);
  return it == perAddress_.end() ? 0 : it->second[static_cast<std::size_t>(kind)];
}

}  // namespace haarcast::net
