// How the reports write a number: fixed point with a given count of
// digits after the point ("%.*f"), one definition for every table of
// eval and its sections.
#pragma once

#include <cstdio>
#include <string>

namespace haarcast::app {

inline std::string fmt(double v, int digits = 2) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

}  // namespace haarcast::app
