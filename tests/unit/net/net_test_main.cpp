// The net tests' main: GoogleTest's, then the exit `serve` takes. Some tests
// leave a render or a build behind on purpose (the frame deadline's, the
// stop grace's), and one left behind by a slow build can still be inside
// Embree when the tests end: the process then leaves without running the
// static destructors that would pull Embree's state from under it
// (net/left_behind.h), with the tests' status.
#include <gtest/gtest.h>

#include "haarcast/net/left_behind.h"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  const int status = RUN_ALL_TESTS();
  haarcast::net::exitNowIfThreadsLeftBehind(status);
  return status;
}
