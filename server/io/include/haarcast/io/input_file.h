// What every loader checks before it opens a file to read: that the path
// names a regular file (a symbolic link to one is fine). A FIFO would block
// the open or the read until a writer came (forever, for a server); a
// device may never end; a directory opens and reads as nothing. Each gets
// an error naming what the path is instead.
#pragma once

#include <optional>
#include <string>

namespace haarcast::io {

// nullopt for a regular file; otherwise why it cannot be read, as a phrase
// for "PATH: <phrase>": "is a FIFO (named pipe), not a regular file",
// "is a directory, not a regular file", "does not exist", … The check and
// the open are two steps: this keeps out mistakes and stray paths, not a
// writer racing the reader on the same directory.
std::optional<std::string> whyNotRegularFile(const std::string& path);

// Throws std::runtime_error("PATH: cannot read <what>: <why>") unless the
// path is a regular file; `what` names the kind ("scene file", "MERL BRDF").
void requireRegularFile(const std::string& path, const std::string& what);

}  // namespace haarcast::io
