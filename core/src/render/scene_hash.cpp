#include "render/scene_hash.h"

#include "util/input_file.h"

#include <penumbra/rng.h>

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace penumbra {

namespace {

// FNV-1a, 64 bits: the fingerprint guards against mistakes, not adversaries.
class Hasher {
 public:
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ull;
  }
  void str(const std::string& s) {
    u64(s.size());
    bytes(s.data(), s.size());
  }
  void u64(uint64_t v) { bytes(&v, sizeof v); }
  void f64(double v) { bytes(&v, sizeof v); }
  uint64_t value() const { return mix_bits(h_); }

 private:
  uint64_t h_ = 0xcbf29ce484222325ull;
};

void hash_file(Hasher& h, const fs::path& path) {
  // Missing and non-regular files (a link to /dev/zero, a FIFO) are left to the builder to report;
  // the name is hashed anyway. A regular file is read up to the size it has now.
  if (!input_file_problem(path.string()).empty()) return;
  std::error_code ec;
  uintmax_t left = fs::file_size(path, ec);
  std::ifstream in(path, std::ios::binary);
  if (ec || !in) return;
  char buf[1 << 16];
  while (left > 0 && (in.read(buf, std::streamsize(std::min<uintmax_t>(sizeof buf, left))) || in.gcount() > 0)) {
    h.bytes(buf, size_t(in.gcount()));
    left -= uintmax_t(in.gcount());
  }
}

void hash_entity(Hasher& h, const SceneEntity& e, bool is_film) {
  h.str(e.type);
  for (const Param& p : e.params.params()) {
    if (is_film && (p.name == "filename" || p.name == "aovs")) continue;
    h.str(p.type);
    h.str(p.name);
    h.u64(p.numbers.size());
    for (double v : p.numbers) h.f64(v);
    h.u64(p.strings.size());
    for (const auto& s : p.strings) h.str(s);
    h.u64(p.bools.size());
    for (bool b : p.bools) h.u64(b);
    if (!is_film && p.name == "filename" && p.strings.size() == 1) {
      fs::path f = fs::path(p.strings[0]).is_absolute() ? fs::path(p.strings[0]) : fs::path(e.base_dir) / p.strings[0];
      hash_file(h, f);
    }
  }
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) h.f64(e.to_world[c][r]);
  h.u64(e.reverse_orientation);
}

}  // namespace

std::string scene_hash(const SceneDescription& desc) {
  Hasher h;
  for (const SceneEntity* e : {&desc.camera, &desc.film, &desc.filter, &desc.sampler, &desc.integrator})
    hash_entity(h, *e, e == &desc.film);
  for (const auto* list : {&desc.materials, &desc.lights, &desc.area_lights}) {
    h.u64(list->size());
    for (const auto& e : *list) hash_entity(h, e, false);
  }
  h.u64(desc.named_materials.size());
  for (const auto& [name, index] : desc.named_materials) {
    h.str(name);
    h.u64(uint64_t(index));
  }
  h.u64(desc.shapes.size());
  for (const auto& s : desc.shapes) {
    hash_entity(h, s, false);
    h.u64(uint64_t(int64_t(s.material)));
    h.str(s.material_name);
    h.u64(uint64_t(int64_t(s.area_light)));
  }
  return fmt::format("{:016x}", h.value());
}

}  // namespace penumbra
