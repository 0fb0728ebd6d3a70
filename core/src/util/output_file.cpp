#include "util/output_file.h"

#include <penumbra/error.h>

#include <fmt/core.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>

namespace fs = std::filesystem;

namespace penumbra {

namespace {

fs::path folder_of(const fs::path& path) {
  fs::path dir = path.parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

// A new, empty, uniquely named file "<folder>/.<name>.tmp-XXXXXX<ext>"; returns its path or sets errno.
std::string make_temporary(const fs::path& path) {
  std::string ext = path.extension().string();
  std::string name = (folder_of(path) / fmt::format(".{}.tmp-XXXXXX{}", path.filename().string(), ext)).string();
  int fd = mkstemps(name.data(), static_cast<int>(ext.size()));
  if (fd < 0) return "";
  close(fd);
  return name;
}

// The permission bits a file created now would get (mkstemp makes 0600).
mode_t new_file_mode() {
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  mode_t mask = umask(0);
  umask(mask);
  return 0666 & ~mask;
}

// Flushes the file's data to the disk, so that a crash after the rename cannot leave an empty file.
bool sync_file(const std::string& path) {
  int fd = open(path.c_str(), O_RDONLY);
  if (fd < 0) return false;
  bool ok = fsync(fd) == 0;
  close(fd);
  return ok;
}

}  // namespace

std::string output_path_problem(const std::string& path_text) {
  if (path_text.empty()) return "the file name is empty";
  fs::path path(path_text);
  fs::path dir = folder_of(path);
  std::error_code ec;
  if (!fs::exists(dir, ec)) return fmt::format("the folder '{}' does not exist", dir.string());
  if (!fs::is_directory(dir, ec)) return fmt::format("'{}' is not a folder", dir.string());
  if (fs::is_directory(path, ec)) return fmt::format("'{}' is a folder", path_text);
  std::string probe = make_temporary(path);
  if (probe.empty())
    return fmt::format("cannot create files in the folder '{}': {}", dir.string(), std::strerror(errno));
  std::remove(probe.c_str());
  return "";
}

void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  std::string temporary = make_temporary(fs::path(path));
  if (temporary.empty())
    throw Error(fmt::format("cannot write '{}': cannot create a file in its folder: {}", path, std::strerror(errno)));
  try {
    write(temporary);
    if (!sync_file(temporary) || chmod(temporary.c_str(), new_file_mode()) != 0 || std::rename(temporary.c_str(), path.c_str()) != 0)
      throw Error(fmt::format("cannot write '{}': {}", path, std::strerror(errno)));
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
}

void write_text_atomically(const std::string& path, const std::string& text) {
  write_atomically(path, [&](const std::string& temporary) {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) throw Error(fmt::format("cannot write '{}': {}", path, std::strerror(errno)));
  });
}

}  // namespace penumbra
