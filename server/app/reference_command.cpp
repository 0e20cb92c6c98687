// placeholder until the reference renderer lands (step 2)
#include "reference_command.h"
namespace haarcast::app {
std::function<int()> addReferenceCommand(CLI::App&) { return [] { return -1; }; }
}  // namespace haarcast::app
