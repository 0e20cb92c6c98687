// Invariant checks that name their operands (pbrt's CHECK_EQ style): a failed
// check is a bug in haarcast, not bad input, and throws std::logic_error
// "Check failed: a == b (3 vs 4) at file.cpp:12". Bad input gets
// std::invalid_argument with a message for the user instead.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace haarcast::detail {

template <typename A, typename B>
[[noreturn]] void checkFailed(const char* expression, const A& a, const B& b, const char* file, int line) {
  std::ostringstream s;
  s << "Check failed: " << expression << " (" << a << " vs " << b << ") at " << file << ':' << line;
  throw std::logic_error(s.str());
}

}  // namespace haarcast::detail

#define HC_CHECK_OP(a, op, b)                                                                              \
  do {                                                                                                     \
    const auto& hcCheckA = (a);                                                                            \
    const auto& hcCheckB = (b);                                                                            \
    if (!(hcCheckA op hcCheckB)) ::haarcast::detail::checkFailed(#a " " #op " " #b, hcCheckA, hcCheckB, __FILE__, __LINE__); \
  } while (false)

#define HC_CHECK_EQ(a, b) HC_CHECK_OP(a, ==, b)
#define HC_CHECK_NE(a, b) HC_CHECK_OP(a, !=, b)
#define HC_CHECK_LT(a, b) HC_CHECK_OP(a, <, b)
#define HC_CHECK_LE(a, b) HC_CHECK_OP(a, <=, b)
