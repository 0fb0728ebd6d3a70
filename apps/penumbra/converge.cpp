#include "converge.h"
#include "converge_report.h"

#include "image/image_io.h"
#include "render/image_metrics.h"
#include "render/render_session.h"

#include <penumbra/error.h>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "parser/scene_description.h"
#include "render/scene_hash.h"
#include "util/output_file.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <algorithm>
#include <map>

#include <penumbra/rng.h>

namespace fs = std::filesystem;

namespace penumbra::cli {

namespace {

struct Row {
  std::string config;
  int run = 0, snapshot = 0;
  double seconds = 0;
  int spp = 0;
  ImageErrors errors;
};

bool making_reference(const ConvergeSettings& s) { return s.make_reference > 0.0 || s.make_reference_spp > 0; }

RenderSettings base_settings(const ConvergeSettings& s, const ConvergeConfig& config, uint32_t seed) {
  RenderSettings r;
  r.scene_file = s.scene;
  r.integrator = config.integrator;
  r.sampler = config.sampler;
  r.integrator_params = config.params;
  r.seed = seed;
  r.resolution = s.resolution;
  r.threads = s.threads;
  r.quiet = true;
  r.image_written = false;  // snapshots and results go to the study folder, checked in run_converge
  return r;
}

// The reference configuration when none is given: an unbiased integrator that is not among the
// configurations compared (a reference made by one of them shares its systematic errors), or, when
// both are compared, one half by each.
std::vector<std::string> default_reference_configs(const std::vector<ConvergeConfig>& configs) {
  auto compared = [&](const std::string& integrator) {
    return std::any_of(configs.begin(), configs.end(), [&](const ConvergeConfig& c) { return c.integrator == integrator; });
  };
  if (!compared("path")) return {"path:sobol", "path:sobol"};
  if (!compared("bdpt")) return {"bdpt:sobol", "bdpt:sobol"};
  return {"path:sobol", "bdpt:sobol"};
}

// Where references are kept between studies: $PENUMBRA_REFERENCE_CACHE, else
// $XDG_CACHE_HOME/penumbra/references, else ~/.cache/penumbra/references.
fs::path reference_cache_dir() {
  if (const char* d = std::getenv("PENUMBRA_REFERENCE_CACHE"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return fs::path(d) / "penumbra" / "references";
  if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".cache" / "penumbra" / "references";
  return fs::temp_directory_path() / "penumbra-references";
}

// Two independent half-length renders: their mean is the reference, and their difference estimates
// the reference's own variance, which is subtracted from every measured squared error. Cached by the
// scene's hash and the reference settings, so a rerun of a study does not remake it.
void make_reference(const ConvergeSettings& s, const std::vector<std::string>& halves_configs, ImageRgb* reference,
                    ImageRgb* variance, std::string* description) {
  std::string res = s.resolution ? fmt::format("{}x{}", s.resolution->first, s.resolution->second) : "scene";
  std::string amount = s.make_reference_spp > 0 ? fmt::format("{}spp", s.make_reference_spp)
                                                : fmt::format("{:g}s", s.make_reference);
  std::string key = fmt::format("{}-{}-{}-{}-{}", scene_hash(parse_scene_file(s.scene)), res, halves_configs[0],
                                halves_configs[1], amount);
  for (char& c : key)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.') c = '_';
  *description = halves_configs[0] == halves_configs[1] ? halves_configs[0] : halves_configs[0] + " + " + halves_configs[1];
  fs::path cache = reference_cache_dir() / key;
  ImageRgb halves[2];
  if (fs::exists(cache / "half-1.exr") && fs::exists(cache / "half-2.exr")) {
    std::fprintf(stderr, "converge: reference from the cache %s\n", cache.string().c_str());
    for (int h = 0; h < 2; ++h) halves[h] = read_image((cache / fmt::format("half-{}.exr", h + 1)).string());
  } else {
    for (int h = 0; h < 2; ++h) {
      ConvergeConfig config = parse_configs(halves_configs[h], "--reference-config").at(0);
      RenderSettings r = base_settings(s, config, 1000001u + h);
      std::string budget;
      if (s.make_reference_spp > 0) {
        r.spp = s.make_reference_spp;
        budget = fmt::format("{} spp", *r.spp);
      } else {
        r.time_budget = s.make_reference / 2.0;
        budget = fmt::format("{:.0f} s", r.time_budget);
      }
      std::fprintf(stderr, "converge: reference half %d (%s, %s)\n", h + 1, halves_configs[h].c_str(), budget.c_str());
      halves[h] = render(r).image;
    }
    std::error_code ec;
    fs::create_directories(cache, ec);
    if (!ec)
      for (int h = 0; h < 2; ++h) write_image((cache / fmt::format("half-{}.exr", h + 1)).string(), halves[h]);
  }
  *variance = half_reference_variance(halves[0], halves[1], reference);
  write_image((fs::path(s.out_dir) / "reference.exr").string(), *reference);
  write_image((fs::path(s.out_dir) / "reference-variance.exr").string(), *variance);
}

// Time at which a mean error curve first reaches `target`, interpolated in log-log; -1 if never.
double time_to_reach(const std::vector<std::pair<double, double>>& curve, double target) {
  for (size_t i = 0; i < curve.size(); ++i) {
    if (curve[i].second > target) continue;
    if (i == 0) return curve[0].first;
    auto [t0, e0] = curve[i - 1];
    auto [t1, e1] = curve[i];
    double f = (std::log(target) - std::log(e0)) / (std::log(e1) - std::log(e0));
    return std::exp(std::log(t0) + f * (std::log(t1) - std::log(t0)));
  }
  return -1.0;
}

// Quantile q of `v` (linear interpolation between order statistics); v is copied.
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  double x = q * static_cast<double>(v.size() - 1);
  size_t i = static_cast<size_t>(std::floor(x));
  size_t j = std::min(i + 1, v.size() - 1);
  return v[i] + (x - static_cast<double>(i)) * (v[j] - v[i]);
}

double median(const std::vector<double>& v) { return quantile(v, 0.5); }

// The metrics a study reports, by name, from one snapshot's errors.
const std::vector<std::pair<std::string, double ImageErrors::*>>& metrics() {
  static const std::vector<std::pair<std::string, double ImageErrors::*>> m = {
      {"relmse", &ImageErrors::rel_mse},
      {"rmse", &ImageErrors::rmse},
      {"mae", &ImageErrors::mae},
      {"relmse_clamped", &ImageErrors::rel_mse_clamped},
      {"relse_median", &ImageErrors::rel_se_median},
      {"worst_share", &ImageErrors::worst_share}};
  return m;
}

struct RatioInterval {
  double ratio = 0, low = 0, high = 0;
};

// Ratio of the medians of a and b with a percentile-bootstrap 95 % interval: runs are resampled with
// replacement within each configuration (2000 times, fixed seed, so a study's report is reproducible).
RatioInterval bootstrap_ratio(const std::vector<double>& a, const std::vector<double>& b, uint64_t seed) {
  RatioInterval r;
  double mb = median(b);
  r.ratio = mb != 0.0 ? median(a) / mb : 0.0;
  Pcg32 rng(seed, 0x626f6f74u /* "boot" */);
  std::vector<double> ratios, ra(a.size()), rb(b.size());
  const int resamples = 2000;
  for (int k = 0; k < resamples; ++k) {
    for (double& x : ra) x = a[std::min(a.size() - 1, static_cast<size_t>(rng.next_float() * a.size()))];
    for (double& x : rb) x = b[std::min(b.size() - 1, static_cast<size_t>(rng.next_float() * b.size()))];
    double d = median(rb);
    if (d != 0.0) ratios.push_back(median(ra) / d);
  }
  r.low = quantile(ratios, 0.025);
  r.high = quantile(ratios, 0.975);
  return r;
}

}  // namespace

std::vector<ConvergeConfig> parse_configs(const std::string& text, const std::string& option) {
  std::vector<ConvergeConfig> out;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string item = text.substr(start, end - start);
    if (!item.empty()) {
      ConvergeConfig c;
      c.name = item;
      // integrator[/NAME=VALUE...][:sampler]: the sampler follows the first ':'.
      size_t colon = item.find(':');
      std::string head = item.substr(0, colon);
      c.sampler = colon == std::string::npos ? "" : item.substr(colon + 1);
      size_t slash = head.find('/');
      c.integrator = head.substr(0, slash);
      if (c.integrator.empty()) throw Error(fmt::format("{}: '{}' names no integrator", option, item));
      std::string where = fmt::format("{} '{}'", option, item);
      while (slash != std::string::npos) {
        size_t next = head.find('/', slash + 1);
        std::string text = head.substr(slash + 1, next == std::string::npos ? std::string::npos : next - slash - 1);
        ParamOverride o = parse_param_override(text, where);
        o.origin = fmt::format("{}: {}", where, text);  // "--configs 'bdpt/maxdepth=x:sobol': maxdepth=x"
        c.params.push_back(std::move(o));
        slash = next;
      }
      for (const ConvergeConfig& other : out)
        if (other.name == c.name) throw Error(fmt::format("{}: '{}' is given twice", option, item));
      out.push_back(std::move(c));
    }
    start = end + 1;
  }
  if (out.empty()) throw Error(fmt::format("{}: give at least one integrator[/NAME=VALUE...][:sampler]", option));
  return out;
}

int run_converge(const ConvergeSettings& s) {
  if (s.configs.empty()) throw Error("--configs: give at least one integrator[/NAME=VALUE...][:sampler]");
  if (s.runs < 1) throw Error("--runs must be at least 1");
  if (s.snapshots < 2) throw Error("--snapshots must be at least 2");
  // Parameter overrides are checked against the integrators' tables before any long render.
  for (const ConvergeConfig& c : s.configs) check_param_overrides(c.integrator, c.params);
  std::vector<std::string> reference_configs =
      s.reference_config.empty() ? default_reference_configs(s.configs) : std::vector<std::string>{s.reference_config, s.reference_config};
  if (making_reference(s))
    for (const std::string& rc : reference_configs) {
      ConvergeConfig ref = parse_configs(rc, "--reference-config").at(0);
      check_param_overrides(ref.integrator, ref.params);
    }
  // The output folder is made and probed before any render, like every other output.
  std::error_code dir_error;
  fs::create_directories(s.out_dir, dir_error);
  if (dir_error) throw Error(fmt::format("-o: cannot create the folder '{}': {}", s.out_dir, dir_error.message()));
  if (std::string problem = output_path_problem((fs::path(s.out_dir) / "results.csv").string()); !problem.empty())
    throw Error(fmt::format("-o: {}", problem));

  ImageRgb reference, variance;
  bool have_variance = false;
  std::string reference_description = s.reference.empty() ? "" : s.reference;
  if (making_reference(s)) {
    make_reference(s, reference_configs, &reference, &variance, &reference_description);
    have_variance = true;
  } else if (!s.reference.empty()) {
    reference = read_image(s.reference);
    fs::path var_path = fs::path(s.reference).parent_path() / "reference-variance.exr";
    if (fs::exists(var_path)) {
      variance = read_image(var_path.string());
      have_variance = true;
    }
  } else {
    throw Error("give --reference REF.exr, --make-reference SECONDS or --make-reference-spp N");
  }

  std::vector<double> times;
  for (int k = 0; k < s.snapshots; ++k) times.push_back(s.time * std::pow(2.0, -(s.snapshots - 1 - k)));

  std::vector<Row> rows;
  ReportImages report_images;
  report_images.reference = reference;
  for (size_t ci = 0; ci < s.configs.size(); ++ci) {
    const ConvergeConfig& config = s.configs[ci];
    for (int run = 0; run < s.runs; ++run) {
      // Independent seeds for every run of every configuration: the intervals treat them as such.
      RenderSettings r = base_settings(s, config, static_cast<uint32_t>(1 + run + 1000 * ci));
      r.time_budget = s.time;
      r.snapshot_times = times;
      int snapshot = 0;
      if (run == 0) report_images.configs.emplace_back(config.name, ImageRgb{});
      r.on_snapshot = [&](double seconds, int spp, const ImageRgb& img) {
        ImageErrors e = image_errors(img, reference, have_variance ? &variance : nullptr);
        // The snapshot stands for the latest snapshot time it has passed, not for the next in
        // sequence: a run whose first pass outlasts the first snapshot times (a pilot, a long
        // iteration) skips those, and numbering its snapshots in order compared its 10-s image with
        // the others' 5-s images.
        int slot = snapshot;
        while (slot + 1 < static_cast<int>(times.size()) && times[slot + 1] <= seconds * (1.0 + 1e-9)) ++slot;
        rows.push_back(Row{config.name, run, slot, seconds, spp, e});
        snapshot = slot + 1;
        if (run == 0) report_images.configs.back().second = img;  // the first run's latest snapshot
      };
      std::fprintf(stderr, "converge: %s run %d/%d (%.0f s)\n", config.name.c_str(), run + 1, s.runs, s.time);
      render(r);
    }
  }

  // Raw rows.
  std::ostringstream csv;
  csv << "config,run,snapshot,seconds,spp,rmse,relmse,mae,relmse_clamped,relse_median,worst_share\n";
  for (const Row& row : rows)
    csv << fmt::format("{},{},{},{:.6g},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", row.config, row.run,
                       row.snapshot, row.seconds, row.spp, row.errors.rmse, row.errors.rel_mse, row.errors.mae,
                       row.errors.rel_mse_clamped, row.errors.rel_se_median, row.errors.worst_share);
  write_text_atomically((fs::path(s.out_dir) / "results.csv").string(), csv.str());

  // Per configuration and snapshot, over the runs: the median and interquartile range of every metric
  // (a heavy-tailed estimator's mean error is decided by its worst run); efficiency and the time to
  // reach a common relMSE from the median curves.
  nlohmann::json summary;
  summary["scene"] = s.scene;
  summary["relmse_epsilon"] = kRelMseEpsilon;
  summary["relmse_formula"] = "mean over pixels and channels of (I - R)^2 / (R^2 + eps), reference variance subtracted";
  summary["statistics"] = "median and interquartile range over runs; ratios: medians with a bootstrap 95 % interval";
  summary["reference_variance_subtracted"] = have_variance;
  summary["time_budget"] = s.time;
  summary["runs"] = s.runs;
  auto values = [&](const std::string& config, int snapshot, double ImageErrors::*field) {
    std::vector<double> v;
    for (const Row& row : rows)
      if (row.config == config && row.snapshot == snapshot) v.push_back(row.errors.*field);
    return v;
  };
  std::map<std::string, std::vector<std::pair<double, double>>> curves;
  std::map<std::string, int> last_snapshot;
  double common_target = 0.0;
  for (const auto& config : s.configs) {
    const std::string& name = config.name;
    nlohmann::json points = nlohmann::json::array();
    for (int k = 0; k < s.snapshots; ++k) {
      std::vector<double> t, spp;
      for (const Row& row : rows)
        if (row.config == name && row.snapshot == k) t.push_back(row.seconds), spp.push_back(row.spp);
      if (t.empty()) continue;
      nlohmann::json p = {{"seconds", median(t)}, {"spp", median(spp)}, {"runs", t.size()}};
      for (const auto& [metric, field] : metrics()) {
        std::vector<double> v = values(name, k, field);
        p[metric] = median(v);
        p[metric + "_q25"] = quantile(v, 0.25);
        p[metric + "_q75"] = quantile(v, 0.75);
        p[metric + "_min"] = quantile(v, 0.0);
        p[metric + "_max"] = quantile(v, 1.0);
      }
      points.push_back(p);
      curves[name].emplace_back(median(t), p["relmse"].get<double>());
      last_snapshot[name] = k;
    }
    summary["configs"][name]["points"] = points;
    if (!curves[name].empty()) {
      auto [t_final, rel_final] = curves[name].back();
      summary["configs"][name]["final_relmse"] = rel_final;
      summary["configs"][name]["efficiency"] = rel_final > 0 ? 1.0 / (rel_final * t_final) : 0.0;
      common_target = std::max(common_target, rel_final);
      const nlohmann::json& last = points.back();
      std::fprintf(stderr,
                   "converge: %-28s at %5.1f s: relMSE %.4g [%.4g, %.4g], RMSE %.4g [%.4g, %.4g], MAE %.4g, "
                   "clamped relMSE %.4g, worst 0.1 %% of pixels hold %.0f %% of the squared error\n",
                   name.c_str(), t_final, last["relmse"].get<double>(), last["relmse_q25"].get<double>(),
                   last["relmse_q75"].get<double>(), last["rmse"].get<double>(), last["rmse_q25"].get<double>(),
                   last["rmse_q75"].get<double>(), last["mae"].get<double>(), last["relmse_clamped"].get<double>(),
                   100.0 * last["worst_share"].get<double>());
    }
  }
  // The target every configuration reaches: the worst final median relMSE.
  summary["time_to_reach"]["relmse"] = common_target;
  for (const auto& [name, curve] : curves) summary["time_to_reach"]["seconds"][name] = time_to_reach(curve, common_target);

  // The reference's own error against the smallest error it is asked to rank: above 10 % of it, the
  // ranking may be the reference's, and the report says so loudly.
  summary["reference"]["made_by"] = reference_description;
  if (have_variance) {
    const ReferenceNoise noise = reference_noise(reference, variance);
    double ref_error = noise.error, smallest = 1e300;
    for (const auto& [name, curve] : curves)
      if (!curve.empty()) smallest = std::min(smallest, curve.back().second);
    bool trusted = smallest > 0.0 && ref_error <= 0.1 * smallest;
    summary["reference"]["relmse"] = ref_error;
    summary["reference"]["floor"] = noise.floor;
    summary["reference"]["smallest_compared_relmse"] = smallest;
    summary["reference"]["trusted"] = trusted;
    std::fprintf(stderr, "converge: reference (%s) own relMSE %.3g (over its neighbours' mean), %.0f %% of the "
                 "smallest error compared (%.3g)%s\n",
                 reference_description.c_str(), ref_error, smallest > 0 ? 100.0 * ref_error / smallest : 0.0, smallest,
                 trusted ? "" : ": WARNING: above 10 %, the reference's own noise may decide the ranking; make a longer reference");
  }

  // Every pairwise ratio at equal time (the last snapshot), with its interval; a conclusion only
  // where the interval excludes 1.
  nlohmann::json ratios = nlohmann::json::array();
  uint64_t boot_seed = 1;
  for (size_t i = 0; i < s.configs.size(); ++i)
    for (size_t j = i + 1; j < s.configs.size(); ++j) {
      const std::string &a = s.configs[i].name, &b = s.configs[j].name;
      if (!last_snapshot.count(a) || !last_snapshot.count(b)) continue;
      int k = std::min(last_snapshot[a], last_snapshot[b]);
      for (const auto& [metric, field] : metrics()) {
        if (metric == "worst_share") continue;
        RatioInterval r = bootstrap_ratio(values(a, k, field), values(b, k, field), boot_seed++);
        std::string conclusion = r.high < 1.0   ? a + " lower"
                                 : r.low > 1.0 ? b + " lower"
                                               : "no conclusion: the interval contains 1";
        ratios.push_back({{"a", a}, {"b", b}, {"metric", metric}, {"snapshot", k}, {"seconds", times[k]},
                          {"ratio", r.ratio}, {"low", r.low}, {"high", r.high}, {"conclusion", conclusion}});
        std::fprintf(stderr, "converge: %s / %s %s at %.3g s: %.3g [%.3g, %.3g]: %s\n", a.c_str(), b.c_str(),
                     metric.c_str(), times[k], r.ratio, r.low, r.high, conclusion.c_str());
      }
    }
  summary["ratios"] = ratios;
  write_text_atomically((fs::path(s.out_dir) / "summary.json").string(), summary.dump(2) + "\n");
  write_report((fs::path(s.out_dir) / "report.html").string(), summary, report_images);
  std::fprintf(stderr, "converge: wrote %s/results.csv, summary.json and report.html (%zu snapshots)\n", s.out_dir.c_str(), rows.size());
  return 0;
}

}  // namespace penumbra::cli
