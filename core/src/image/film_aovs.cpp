#include "image/film_aovs.h"

#include <fmt/core.h>

#include <algorithm>
#include <limits>
#include <sstream>

namespace penumbra {

std::string AovSet::names() const {
  std::string out;
  auto add = [&](bool on, const char* name) {
    if (on) out += (out.empty() ? "" : ",") + std::string(name);
  };
  add(albedo, "albedo");
  add(normal, "normal");
  add(depth, "depth");
  add(samples, "samples");
  add(variance, "variance");
  add(nonfinite, "nonfinite");
  return out;
}

AovSet parse_aovs(const std::vector<std::string>& lists, const FileLoc& loc) {
  AovSet set;
  const std::pair<const char*, bool AovSet::*> table[] = {
      {"albedo", &AovSet::albedo},     {"normal", &AovSet::normal},     {"depth", &AovSet::depth},
      {"samples", &AovSet::samples},   {"variance", &AovSet::variance}, {"nonfinite", &AovSet::nonfinite}};
  for (const auto& list : lists) {
    std::stringstream in(list);
    std::string name;
    while (std::getline(in, name, ',')) {
      name.erase(0, name.find_first_not_of(" \t"));
      name.erase(name.find_last_not_of(" \t") + 1);
      if (name.empty()) continue;
      bool known = name == "all";
      for (const auto& [n, flag] : table)
        if (name == n || name == "all") {
          set.*flag = true;
          known = true;
        }
      if (!known) throw Error(loc, fmt::format("unknown AOV '{}'; available: {}", name, kAovNames));
    }
  }
  return set;
}

uint64_t FilmAovs::bytes_per_pixel(const AovSet& set) {
  uint64_t b = 0;
  if (set.samples || set.variance || set.albedo || set.normal) b += sizeof(double);
  if (set.samples || set.variance) b += sizeof(uint32_t);
  if (set.variance) b += sizeof(Moments) + 3 * sizeof(float);
  if (set.albedo) b += 3 * sizeof(double) + 3 * sizeof(float);
  if (set.normal) b += 3 * sizeof(double) + 3 * sizeof(float);
  if (set.depth) b += sizeof(float) + sizeof(float);
  if (set.samples) b += 2 * sizeof(float);
  if (set.nonfinite) b += sizeof(uint32_t) + sizeof(float);
  return b;
}

FilmAovs::FilmAovs(Point2i resolution, AovSet set)
    : set_(set), pixels_(size_t(resolution.x) * size_t(resolution.y)) {
  if (set.samples || set.variance || set.albedo || set.normal) weight_.assign(pixels_, 0.0);
  if (set.samples || set.variance) count_.assign(pixels_, 0);
  if (set.variance) moments_.resize(pixels_);
  if (set.albedo) albedo_.assign(3 * pixels_, 0.0);
  if (set.normal) normal_.assign(3 * pixels_, 0.0);
  if (set.depth) depth_.assign(pixels_, std::numeric_limits<float>::infinity());
  if (set.nonfinite) {
    nonfinite_ = std::make_unique<std::atomic<uint32_t>[]>(pixels_);
    for (size_t i = 0; i < pixels_; ++i) nonfinite_[i].store(0, std::memory_order_relaxed);
  }
}

void FilmAovs::add_sample(size_t i, const Rgb& L, float w) {
  if (weight_.empty()) return;
  weight_[i] += w;
  if (!count_.empty()) ++count_[i];
  if (moments_.empty() || w == 0.f) return;
  // West (1979): weighted Welford, so the mean is the film's weighted pixel mean.
  Moments& m = moments_[i];
  for (int c = 0; c < 3; ++c) {
    double delta = L[c] - m.mean[c];
    m.mean[c] += w / weight_[i] * delta;
    m.m2[c] += w * delta * (L[c] - m.mean[c]);
  }
}

void FilmAovs::add_surface(size_t i, const SurfaceSample& s, float w) {
  if (!s.hit) return;  // a miss adds weight (through add_sample) but no albedo or normal
  for (int c = 0; c < 3; ++c) {
    if (!albedo_.empty()) albedo_[3 * i + c] += double(w) * s.albedo[c];
    if (!normal_.empty()) normal_[3 * i + c] += double(w) * s.normal[c];
  }
  if (!depth_.empty()) depth_[i] = std::min(depth_[i], s.depth);
}

void FilmAovs::add_nonfinite(size_t i) {
  if (nonfinite_) nonfinite_[i].fetch_add(1, std::memory_order_relaxed);
}

std::vector<ImageLayer> FilmAovs::layers() const {
  std::vector<ImageLayer> out;
  auto mean_layer = [&](const char* name, std::vector<std::string> channels, const std::vector<double>& sums) {
    ImageLayer l{name, std::move(channels), std::vector<float>(3 * pixels_)};
    for (size_t i = 0; i < pixels_; ++i)
      for (int c = 0; c < 3; ++c)
        l.pixels[3 * i + c] = weight_[i] != 0.0 ? float(sums[3 * i + c] / weight_[i]) : 0.f;
    out.push_back(std::move(l));
  };
  if (set_.albedo) mean_layer("albedo", {"R", "G", "B"}, albedo_);
  if (set_.normal) mean_layer("normal", {"X", "Y", "Z"}, normal_);
  if (set_.depth) out.push_back(ImageLayer{"depth", {"Z"}, depth_});
  if (set_.samples) {
    ImageLayer l{"samples", {"count", "weight"}, std::vector<float>(2 * pixels_)};
    for (size_t i = 0; i < pixels_; ++i) {
      l.pixels[2 * i] = float(count_[i]);
      l.pixels[2 * i + 1] = float(weight_[i]);
    }
    out.push_back(std::move(l));
  }
  if (set_.variance) {
    // Variance of the pixel estimate (the weighted mean): sample variance over the count; for unit
    // weights m2 / (n (n - 1)).
    ImageLayer l{"variance", {"R", "G", "B"}, std::vector<float>(3 * pixels_)};
    for (size_t i = 0; i < pixels_; ++i)
      for (int c = 0; c < 3; ++c)
        l.pixels[3 * i + c] = count_[i] > 1 && weight_[i] > 0.0
                                  ? float(moments_[i].m2[c] / (weight_[i] * (count_[i] - 1)))
                                  : 0.f;
    out.push_back(std::move(l));
  }
  if (set_.nonfinite) {
    ImageLayer l{"nonfinite", {"count"}, std::vector<float>(pixels_)};
    for (size_t i = 0; i < pixels_; ++i) l.pixels[i] = float(nonfinite_[i].load(std::memory_order_relaxed));
    out.push_back(std::move(l));
  }
  return out;
}

void FilmAovs::save(StateWriter& out) const {
  out.vector(weight_);
  out.vector(count_);
  out.vector(moments_);
  out.vector(albedo_);
  out.vector(normal_);
  out.vector(depth_);
  std::vector<uint32_t> nonfinite(nonfinite_ ? pixels_ : 0);
  for (size_t i = 0; i < nonfinite.size(); ++i) nonfinite[i] = nonfinite_[i].load(std::memory_order_relaxed);
  out.vector(nonfinite);
}

void FilmAovs::load(StateReader& in) {
  in.vector(weight_, weight_.size());
  in.vector(count_, count_.size());
  in.vector(moments_, moments_.size());
  in.vector(albedo_, albedo_.size());
  in.vector(normal_, normal_.size());
  in.vector(depth_, depth_.size());
  std::vector<uint32_t> nonfinite;
  in.vector(nonfinite, nonfinite_ ? pixels_ : 0);
  for (size_t i = 0; i < nonfinite.size(); ++i) nonfinite_[i].store(nonfinite[i], std::memory_order_relaxed);
}

}  // namespace penumbra
