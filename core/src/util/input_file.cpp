#include "util/input_file.h"

#include <fmt/core.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace penumbra {

namespace {

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string problem_of(const struct stat& st) {
  return S_ISREG(st.st_mode) ? "" : fmt::format("it is {}, not a regular file", kind_of(st.st_mode));
}

}  // namespace

std::string input_file_problem(const std::string& path) {
  struct stat st{};
  if (stat(path.c_str(), &st) != 0) return std::strerror(errno);
  return problem_of(st);
}

std::string read_input_file(const std::string& path, const std::string& what, const FileLoc& loc) {
  auto fail = [&](const std::string& reason) { return Error(loc, fmt::format("cannot read {} '{}': {}", what, path, reason)); };
  // Checked first by name: opening a device can have effects of its own.
  if (std::string problem = input_file_problem(path); !problem.empty()) throw fail(problem);
  int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw fail(std::strerror(errno));
  struct stat st{};
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    std::string reason = fstat(fd, &st) != 0 ? std::strerror(errno) : problem_of(st);
    close(fd);
    throw fail(reason);
  }
  std::string data(static_cast<size_t>(st.st_size), '\0');
  size_t done = 0;
  while (done < data.size()) {
    ssize_t n = read(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      std::string reason = n < 0 ? std::strerror(errno) : "the file became shorter while it was read";
      close(fd);
      throw fail(reason);
    }
    done += static_cast<size_t>(n);
  }
  close(fd);
  return data;
}

}  // namespace penumbra
