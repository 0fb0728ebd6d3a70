// Files a render writes (images, stats, reports): checked before any work is done, and written so
// that a failure never destroys what was there. A file is written to a temporary file in the same
// folder and renamed over the destination: rename() is atomic within a file system, so readers see
// either the old file or the complete new one, and a symbolic link at the destination is replaced
// by the new file rather than followed.
#pragma once

#include <functional>
#include <string>

namespace penumbra {

/// Why `path` cannot be written, or "" when it can. Its folder must exist, be a folder and accept a
/// new file (probed by creating and removing a temporary file there: permission bits alone do not
/// tell root about read-only mounts or /proc); `path` itself must not be a folder.
std::string output_path_problem(const std::string& path);

/// Writes `path` by calling `write(temporary)` with a fresh file name in the same folder that keeps
/// the extension (writers choose the format by it), then renames the temporary into place with the
/// permissions a newly created file would have. If `write` throws, the temporary is removed, the
/// old file is untouched and the exception propagates; a failed rename is an Error naming `path`.
void write_atomically(const std::string& path, const std::function<void(const std::string& temporary)>& write);

/// write_atomically() for text.
void write_text_atomically(const std::string& path, const std::string& text);

}  // namespace penumbra
