#pragma once
// Atomic file writes: the bytes go to a temporary file beside the target, which is then renamed
// over it, so a reader never sees a half-written demo file, model, report or image, even when
// the writer is killed (SIGKILL, out of memory): the target holds the old file or the new one.
// The data and then the folder entry are fsync'ed, so the new file also survives a power cut
// once the call returns. A killed writer leaves its "<path>.tmp.<pid>" behind (no reader looks
// at those names); the next write of the same path removes those whose process is gone.
// For tests only: HANDCENTRIC_FAULT_WRITE_IN_PLACE_MS=<ms> plants the naive writer (in place,
// with a pause halfway) that tests/reliability/kill_writers.sh must catch.
#include <string>

namespace handcentric {

/// Writes `bytes` to `path` atomically. Throws FileError naming the path, the reason (missing
/// directory, no permission, a directory in the way, disk full) and the fix when it cannot; the
/// target is then left as it was and no temporary file remains.
void write_file_atomically(const std::string& path, const std::string& bytes);

}  // namespace handcentric
