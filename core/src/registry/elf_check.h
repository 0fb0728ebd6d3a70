// A plugin file is checked before dlopen() maps it: a truncated or corrupt shared object would make
// the loader read past the end of its mapping and die with SIGBUS, taking `penumbra plugins` and
// every render with it. The check reads only the ELF headers.
#pragma once

#include <string>

namespace penumbra {

/// Why `path` cannot be a shared object for this process, or "" when its headers are consistent: a
/// regular file with the ELF magic, this machine's class (64-bit), byte order and architecture, type
/// ET_DYN, and program headers, loadable segments, section headers and every section with contents
/// lying inside the file. It does not prove the code sound: only that mapping it stays in the file.
std::string elf_file_problem(const std::string& path);

}  // namespace penumbra
