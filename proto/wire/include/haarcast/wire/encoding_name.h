// The name of each frame encoding, as the server's log, the CLI client's
// flags and output, and reports print it: the proto enum's value name
// (haarcast.proto, `Encoding`) lower-cased without its "ENCODING_" prefix,
// read from the generated descriptor, so an encoding added to the .proto
// is named without a change here: "unspecified", "jpeg", "png", "exr",
// "h264". One exception: ENCODING_RAW_RGBA8 is "raw", the name the server's
// --encoding flag, the CLI client and the browser's ?encoding= have always
// used (encoding_name.cpp keeps such exceptions in one table, keyed by the
// enum, and tests/unit/wire checks every value of the descriptor).
#pragma once

#include <optional>
#include <string_view>

#include "haarcast/proto/haarcast.pb.h"

namespace haarcast::wire {

// "unknown" for a number the enum does not have (a newer peer's encoding).
std::string_view encodingName(v1::Encoding encoding);

// The encoding of a name encodingName gives, exactly; nullopt otherwise.
std::optional<v1::Encoding> encodingFromName(std::string_view name);

}  // namespace haarcast::wire
