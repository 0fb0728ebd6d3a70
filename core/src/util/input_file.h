// Files a scene pulls in (scene files, PLY and glTF meshes and their buffers, images): read only
// when they are regular files, and never more than their size. A device or a FIFO named by a scene
// (a link to /dev/zero, a pipe nobody writes to) would otherwise make a reader run or wait forever.
#pragma once

#include <penumbra/error.h>

#include <string>

namespace penumbra {

/// Why `path` cannot be read as a data file, or "" when it can: it must exist and be a regular file
/// once symbolic links are followed (folders, devices, FIFOs and sockets are refused).
std::string input_file_problem(const std::string& path);

/// The bytes of regular file `path`, read through one descriptor that is checked before reading (so
/// the file cannot be swapped for a device in between) and opened without blocking (a FIFO cannot
/// stall the open). At most the size the file had when opened is read. Throws Error at `loc`:
/// "cannot read <what> '<path>': <reason>".
std::string read_input_file(const std::string& path, const std::string& what, const FileLoc& loc = {});

}  // namespace penumbra
