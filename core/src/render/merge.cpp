#include "render/merge.h"

#include "render/render_outputs.h"

#include <penumbra/error.h>

#include <fmt/core.h>

#include <algorithm>
#include <limits>
#include <tuple>

namespace penumbra {

namespace {

struct Part {
  std::string path;
  LayeredImage image;
  std::vector<std::pair<int, int>> ranges;
  const std::vector<float>* weight = nullptr;  // samples.weight, one per pixel
};

// Everything two parts must agree on, with the words for the message when they do not.
void check_compatible(const Part& a, const Part& b) {
  auto differ = [&](const char* key, const char* what) {
    std::string x = a.image.meta(key), y = b.image.meta(key);
    if (x != y)
      throw Error(fmt::format("cannot merge {} and {}: {} differs ({} vs {})", a.path, b.path, what,
                              x.empty() ? "none" : x, y.empty() ? "none" : y));
  };
  differ("penumbra:version", "the Penumbra version");
  if (a.image.width != b.image.width || a.image.height != b.image.height)
    throw Error(fmt::format("cannot merge {} and {}: resolution differs ({}x{} vs {}x{})", a.path, b.path,
                            a.image.width, a.image.height, b.image.width, b.image.height));
  differ("penumbra:spp_total", "the total sample count (--spp-total)");
  differ("penumbra:seed", "the seed");
  differ("penumbra:integrator", "the integrator");
  differ("penumbra:sampler", "the sampler");
  differ("penumbra:scene_hash", "the scene (scene hash)");
}

Part read_part(const std::string& path) {
  Part p{path, read_layered_exr(path), {}, nullptr};
  if (p.image.meta("penumbra:scene_hash").empty() || p.image.meta("penumbra:version").empty())
    throw Error(fmt::format("{} was not written by `penumbra render` (its header has no penumbra:version "
                            "and penumbra:scene_hash)",
                            path));
  const ImageLayer* beauty = p.image.find("");
  if (!beauty || beauty->channels != std::vector<std::string>{"R", "G", "B"})
    throw Error(fmt::format("{} has no R, G, B beauty channels", path));
  const ImageLayer* samples = p.image.find("samples");
  if (!samples || samples->channels != std::vector<std::string>{"count", "weight"})
    throw Error(fmt::format("{} has no 'samples' layer (count, weight) to weight it by; render parts with "
                            "--spp-total, which adds it, or --aov samples",
                            path));
  p.ranges = parse_ranges(p.image.meta("penumbra:sample_range"));
  return p;
}

float channel(const ImageLayer& l, size_t pixel, size_t c) { return l.pixels[pixel * l.channels.size() + c]; }

}  // namespace

MergeResult merge_parts(const std::vector<std::string>& paths) {
  if (paths.empty()) throw Error("merge: no parts given");
  std::vector<Part> parts;
  for (const auto& path : paths) {
    parts.push_back(read_part(path));
    check_compatible(parts.front(), parts.back());
  }

  // Parts must hold disjoint sample ranges: an overlap would count the same samples twice.
  std::vector<std::tuple<int, int, size_t>> all;
  for (size_t k = 0; k < parts.size(); ++k)
    for (auto [a, b] : parts[k].ranges) all.emplace_back(a, b, k);
  std::sort(all.begin(), all.end());
  std::vector<std::pair<int, int>> merged;
  for (size_t i = 0; i < all.size(); ++i) {
    auto [a, b, k] = all[i];
    if (i > 0 && a < std::get<1>(all[i - 1]))
      throw Error(fmt::format("cannot merge {} and {}: both contain samples {}-{}", parts[std::get<2>(all[i - 1])].path,
                              parts[k].path, a, std::min(b, std::get<1>(all[i - 1]))));
    if (!merged.empty() && merged.back().second == a)
      merged.back().second = b;
    else
      merged.emplace_back(a, b);
  }

  MergeResult out;
  out.spp_total = std::stoi(parts.front().image.meta("penumbra:spp_total"));
  for (auto [a, b] : merged) out.samples += b - a;
  if (merged != std::vector<std::pair<int, int>>{{0, out.spp_total}})
    out.notes.push_back(fmt::format("the parts hold samples {} of 0-{}: the image is an estimate with {} of {} "
                                    "samples per pixel",
                                    format_ranges(merged), out.spp_total, out.samples, out.spp_total));

  const LayeredImage& first = parts.front().image;
  size_t npix = size_t(first.width) * size_t(first.height);
  // The same layer in every part, looked up once rather than per pixel.
  auto in_parts = [&](const std::string& name) {
    std::vector<const ImageLayer*> out;
    for (const Part& p : parts) out.push_back(p.image.find(name));
    return out;
  };
  std::vector<const ImageLayer*> samples = in_parts("samples"), beauty = in_parts("");
  std::vector<double> W(npix, 0.0);  // merged filter-weight sum
  for (const ImageLayer* s : samples)
    for (size_t i = 0; i < npix; ++i) W[i] += channel(*s, i, 1);

  LayeredImage& img = out.image;
  img.width = first.width;
  img.height = first.height;
  img.metadata = first.metadata;
  for (const ImageLayer& layer : first.layers) {
    std::vector<const ImageLayer*> src = in_parts(layer.name);
    if (!std::all_of(src.begin(), src.end(), [&](const ImageLayer* l) { return l && l->channels == layer.channels; })) {
      out.notes.push_back(fmt::format("layer '{}' is not in every part: left out", layer.name));
      continue;
    }
    size_t nc = layer.channels.size();
    ImageLayer result{layer.name, layer.channels, std::vector<float>(npix * nc)};
    bool sum = layer.name == "samples" || layer.name == "nonfinite", nearest = layer.name == "depth";
    for (size_t i = 0; i < npix; ++i)
      for (size_t c = 0; c < nc; ++c) {
        double v = nearest ? std::numeric_limits<double>::infinity() : 0.0;
        for (size_t k = 0; k < parts.size(); ++k) {
          double x = channel(*src[k], i, c);
          if (sum)
            v += x;
          else if (nearest)
            v = std::min(v, x);
          else
            v += double(channel(*samples[k], i, 1)) * x;  // means, weighted by W_k
        }
        if (!sum && !nearest) v = W[i] > 0.0 ? v / W[i] : 0.0;
        result.pixels[i * nc + c] = float(v);
      }
    img.layers.push_back(std::move(result));
  }

  // Variance of the merged pixel estimate. Each part stores m2_k / (W_k (n_k - 1)); the sums of
  // squared deviations combine as m2 = sum m2_k + sum W_k (mean_k - mean)^2 (Chan et al. 1979).
  for (ImageLayer& var : img.layers) {
    if (var.name != "variance") continue;
    std::vector<const ImageLayer*> src = in_parts("variance");
    std::vector<float> mean = img.find("")->pixels, count = img.find("samples")->pixels;
    for (size_t i = 0; i < npix; ++i)
      for (size_t c = 0; c < 3; ++c) {
        double m2 = 0.0, n = count[2 * i];
        for (size_t k = 0; k < parts.size(); ++k) {
          double wk = channel(*samples[k], i, 1), nk = channel(*samples[k], i, 0);
          double d = double(channel(*beauty[k], i, c)) - mean[3 * i + c];
          m2 += channel(*src[k], i, c) * wk * std::max(nk - 1.0, 0.0) + wk * d * d;
        }
        var.pixels[3 * i + c] = n > 1.0 && W[i] > 0.0 ? float(m2 / (W[i] * (n - 1.0))) : 0.f;
      }
  }

  img.set_meta("penumbra:spp", std::to_string(out.samples));
  img.set_meta("penumbra:sample_range", format_ranges(merged));
  img.set_meta("penumbra:merged_parts", std::to_string(parts.size()));
  return out;
}

}  // namespace penumbra
