// Threads of this process that a server left behind: a render or a
// renderer build still inside a call past its deadline or the stop grace
// (render_service.h), detached rather than waited for. The process's exit
// consults the count: static destructors (Embree's, the Vulkan loader's)
// must not run under a thread that may still be inside those libraries, so
// a process that has one leaves with std::_Exit, its output flushed.
#pragma once

#include <cstddef>

namespace haarcast::net {

// A thread was left behind / one left behind has returned and ends.
void noteThreadLeftBehind();
void noteLeftThreadReturned();
// Threads left behind that have not returned.
std::size_t threadsLeftBehind();
// With threads left behind: flushes stdout and stderr and ends the process
// now with `status`, running no static destructor. Else returns.
void exitNowIfThreadsLeftBehind(int status);

}  // namespace haarcast::net
