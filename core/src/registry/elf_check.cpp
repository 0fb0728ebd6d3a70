#include "registry/elf_check.h"

#include <fmt/core.h>

#include <elf.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <vector>

namespace penumbra {

namespace {

#if defined(__x86_64__)
constexpr uint16_t kMachine = EM_X86_64;
#elif defined(__aarch64__)
constexpr uint16_t kMachine = EM_AARCH64;
#else
#error "elf_check: add this architecture's ELF machine number"
#endif
static_assert(sizeof(void*) == 8, "elf_check reads 64-bit ELF files");

// Reads `n` bytes at `offset`; false when the file has fewer.
bool read_at(int fd, uint64_t offset, void* out, size_t n) {
  size_t done = 0;
  while (done < n) {
    ssize_t r = pread(fd, static_cast<char*>(out) + done, n - done, static_cast<off_t>(offset + done));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    done += static_cast<size_t>(r);
  }
  return true;
}

// [offset, offset + count * size) inside a file of `file_size` bytes, without overflow.
bool inside(uint64_t offset, uint64_t count, uint64_t size, uint64_t file_size) {
  if (size != 0 && count > (UINT64_MAX - offset) / size) return false;
  return offset + count * size <= file_size;
}

std::string truncated(uint64_t file_size, const std::string& what, uint64_t end) {
  return fmt::format("the file is {} bytes, but its {} end at byte {}: it is truncated or corrupt", file_size, what,
                     end);
}

std::string check_headers(int fd, uint64_t size) {
  Elf64_Ehdr eh{};
  if (size < SELFMAG || !read_at(fd, 0, &eh, SELFMAG) || std::memcmp(eh.e_ident, ELFMAG, SELFMAG) != 0)
    return "it is not an ELF file (no ELF magic number)";
  if (size < sizeof eh || !read_at(fd, 0, &eh, sizeof eh))
    return fmt::format("the file is {} bytes, too short for an ELF header", size);
  if (eh.e_ident[EI_CLASS] != ELFCLASS64) return "it is not a 64-bit ELF file";
  bool little = std::endian::native == std::endian::little;
  if (eh.e_ident[EI_DATA] != (little ? ELFDATA2LSB : ELFDATA2MSB)) return "its byte order is not this machine's";
  if (eh.e_machine != kMachine) return fmt::format("it is built for another architecture (ELF machine {})", eh.e_machine);
  if (eh.e_type != ET_DYN) return "it is not a shared object (ELF type is not ET_DYN)";
  if (eh.e_phnum == 0 || eh.e_phentsize != sizeof(Elf64_Phdr)) return "it has no valid program header table";
  if (!inside(eh.e_phoff, eh.e_phnum, sizeof(Elf64_Phdr), size))
    return truncated(size, "program headers", eh.e_phoff + uint64_t(eh.e_phnum) * sizeof(Elf64_Phdr));
  std::vector<Elf64_Phdr> ph(eh.e_phnum);
  if (!read_at(fd, eh.e_phoff, ph.data(), ph.size() * sizeof(Elf64_Phdr))) return "its program headers cannot be read";
  for (const Elf64_Phdr& p : ph)
    if ((p.p_type == PT_LOAD || p.p_type == PT_DYNAMIC) && !inside(p.p_offset, 1, p.p_filesz, size))
      return truncated(size, p.p_type == PT_LOAD ? "loadable segments" : "dynamic section", p.p_offset + p.p_filesz);
  if (eh.e_shnum != 0) {
    if (eh.e_shentsize != sizeof(Elf64_Shdr)) return "its section header table is malformed";
    if (!inside(eh.e_shoff, eh.e_shnum, sizeof(Elf64_Shdr), size))
      return truncated(size, "section headers", eh.e_shoff + uint64_t(eh.e_shnum) * sizeof(Elf64_Shdr));
    std::vector<Elf64_Shdr> sh(eh.e_shnum);
    if (!read_at(fd, eh.e_shoff, sh.data(), sh.size() * sizeof(Elf64_Shdr))) return "its section headers cannot be read";
    for (const Elf64_Shdr& s : sh)
      if (s.sh_type != SHT_NOBITS && s.sh_type != SHT_NULL && !inside(s.sh_offset, 1, s.sh_size, size))
        return truncated(size, "sections", s.sh_offset + s.sh_size);
  }
  return "";
}

}  // namespace

std::string elf_file_problem(const std::string& path) {
  int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return std::strerror(errno);
  struct stat st{};
  std::string problem;
  if (fstat(fd, &st) != 0)
    problem = std::strerror(errno);
  else if (!S_ISREG(st.st_mode))
    problem = "it is not a regular file";
  else
    problem = check_headers(fd, static_cast<uint64_t>(st.st_size));
  close(fd);
  return problem;
}

}  // namespace penumbra
