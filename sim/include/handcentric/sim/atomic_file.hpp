#pragma once
// Atomic file writes: the bytes go to a temporary file beside the target, which is then renamed
// over it, so a reader never sees a half-written demo file or image.
#include <string>

namespace handcentric::sim {

/// Writes `bytes` to `path` atomically. Throws handcentric::Error naming the path and the reason
/// (missing directory, no permission) when it cannot.
void write_file_atomically(const std::string& path, const std::string& bytes);

}  // namespace handcentric::sim
