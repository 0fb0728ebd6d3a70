#include "render/checkpoint.h"

#include <penumbra/error.h>
#include <penumbra/version.h>

#include <fmt/core.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace penumbra {

namespace {

constexpr char kMagic[] = "PENUMBRA-CHECKPOINT\n";
constexpr uint32_t kFormat = 1;

// FNV-1a over the file's contents: detects a truncated or damaged file.
uint64_t fnv1a(const char* p, size_t n) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (size_t i = 0; i < n; ++i) h = (h ^ static_cast<unsigned char>(p[i])) * 0x100000001b3ull;
  return h;
}

void put_string(ByteWriter& w, const std::string& s) {
  w.value<uint64_t>(s.size());
  w.write(s.data(), s.size());
}

std::string get_string(ByteReader& r) {
  uint64_t n = r.value<uint64_t>();
  if (n > (uint64_t{1} << 40)) throw Error("implausible length");
  std::string s(n, '\0');
  r.read(s.data(), n);
  return s;
}

std::string folder_of(const std::string& path) {
  fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

}  // namespace

void ByteWriter::write(const void* data, size_t bytes) { bytes_.append(static_cast<const char*>(data), bytes); }

void ByteReader::read(void* data, size_t bytes) {
  if (bytes > bytes_.size() - pos_) throw Error(fmt::format("{}: the data end early (damaged or truncated)", what_));
  std::memcpy(data, bytes_.data() + pos_, bytes);
  pos_ += bytes;
}

void ByteReader::mismatch(uint64_t got, uint64_t expected) {
  throw Error(fmt::format("{}: holds {} values where this render has {} (made by another build or setting)", what_,
                          got, expected));
}

void check_checkpoint_path(const std::string& path, const std::string& option) {
  if (path.empty()) throw Error(fmt::format("{}: empty file name", option));
  std::string folder = folder_of(path);
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throw Error(fmt::format("{} {}: folder '{}' does not exist", option, path, folder));
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    throw Error(fmt::format("{} {}: folder '{}' is not writable", option, path, folder));
  if (fs::is_directory(path, ec)) throw Error(fmt::format("{} {}: is a folder", option, path));
}

void write_checkpoint(const std::string& path, const CheckpointData& d) {
  ByteWriter w;
  w.write(kMagic, sizeof kMagic - 1);
  w.value<uint32_t>(kFormat);
  put_string(w, PENUMBRA_VERSION_STRING);
  put_string(w, d.key.scene_hash);
  w.value<uint64_t>(d.key.fields.size());
  for (const auto& [name, value] : d.key.fields) {
    put_string(w, name);
    put_string(w, value);
  }
  w.value<int32_t>(d.point.spp);
  w.value<int32_t>(d.point.pass_spp);
  w.value<double>(d.seconds);
  w.value<uint64_t>(d.nonfinite);
  w.value<int32_t>(d.first_nonfinite[0]);
  w.value<int32_t>(d.first_nonfinite[1]);
  put_string(w, d.film);
  put_string(w, d.integrator);
  uint64_t sum = fnv1a(w.bytes().data(), w.bytes().size());
  w.value<uint64_t>(sum);

  // Same folder, so rename() replaces the old checkpoint atomically; a symlink is replaced, not followed.
  std::string tmp = fmt::format("{}.tmp-{}", path, static_cast<long>(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(w.bytes().data(), static_cast<std::streamsize>(w.bytes().size()));
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      throw Error(fmt::format("cannot write checkpoint {}: {}", tmp, std::strerror(errno)));
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    int err = errno;
    std::remove(tmp.c_str());
    throw Error(fmt::format("cannot write checkpoint {}: {}", path, std::strerror(err)));
  }
}

CheckpointData read_checkpoint(const std::string& path, const CheckpointKey& expected) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw Error(fmt::format("--resume {}: {}", path, std::strerror(errno)));
  if (!S_ISREG(st.st_mode)) throw Error(fmt::format("--resume {}: not a regular file", path));
  std::ifstream in(path, std::ios::binary);
  std::stringstream buf;
  buf << in.rdbuf();
  std::string bytes = buf.str();
  const std::string what = fmt::format("--resume {}", path);
  if (bytes.compare(0, sizeof kMagic - 1, kMagic) != 0) throw Error(fmt::format("{}: not a Penumbra checkpoint", what));
  if (bytes.size() < sizeof kMagic - 1 + 8) throw Error(fmt::format("{}: truncated", what));
  uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  if (stored != fnv1a(bytes.data(), bytes.size() - 8))
    throw Error(fmt::format("{}: damaged or truncated (its checksum does not match)", what));
  bytes.resize(bytes.size() - 8);

  ByteReader r(bytes, what);
  std::string magic(sizeof kMagic - 1, '\0');
  r.read(magic.data(), magic.size());
  uint32_t format = r.value<uint32_t>();
  if (format != kFormat)
    throw Error(fmt::format("{}: checkpoint format {}, this Penumbra reads format {}", what, format, kFormat));
  std::string version = get_string(r);
  if (version != PENUMBRA_VERSION_STRING)
    throw Error(fmt::format("{}: written by Penumbra {}, this is {}; finish it with that version or start again",
                            what, version, PENUMBRA_VERSION_STRING));
  CheckpointData d;
  d.key.scene_hash = get_string(r);
  uint64_t n = r.value<uint64_t>();
  for (uint64_t i = 0; i < n && i < 1000; ++i) {
    std::string name = get_string(r);
    d.key.fields.emplace_back(name, get_string(r));
  }
  std::string differences;
  for (const auto& [name, value] : expected.fields) {
    std::string theirs = "(not recorded)";
    for (const auto& [n2, v2] : d.key.fields)
      if (n2 == name) theirs = v2;
    if (theirs != value) differences += fmt::format("; {}: checkpoint '{}', this render '{}'", name, theirs, value);
  }
  if (!differences.empty())
    throw Error(fmt::format("{}: the checkpoint belongs to another render{}", what, differences));
  if (d.key.scene_hash != expected.scene_hash)
    throw Error(fmt::format("{}: the checkpoint belongs to another version of the scene (a directive, parameter or "
                            "referenced file changed since it was written)",
                            what));
  d.point.spp = r.value<int32_t>();
  d.point.pass_spp = r.value<int32_t>();
  d.seconds = r.value<double>();
  d.nonfinite = r.value<uint64_t>();
  d.first_nonfinite[0] = r.value<int32_t>();
  d.first_nonfinite[1] = r.value<int32_t>();
  d.film = get_string(r);
  d.integrator = get_string(r);
  if (!r.at_end() || d.point.spp < 0 || d.point.pass_spp < 1)
    throw Error(fmt::format("{}: damaged (unexpected contents)", what));
  return d;
}

}  // namespace penumbra
