#include "render/render_session.h"

#include "parser/scene_description.h"
#include "registry/registry.h"
#include "render/checkpoint.h"
#include "render/interrupt.h"
#include "render/progress.h"
#include "render/ray_counter.h"
#include "render/render_outputs.h"
#include "render/scene_hash.h"
#include "render/scene_warnings.h"
#include "scene/scene_builder.h"
#include "util/output_file.h"


#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <mutex>

namespace penumbra {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

uint64_t peak_memory_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<uint64_t>(usage.ru_maxrss) * 1024u;
}

class Session final : public RenderContext, public CheckpointHost {
 public:
  Session(BuiltScene& built, RenderOptions options, const RenderSettings& settings)
      : built_(built), options_(options), settings_(settings), progress_("samples", settings.quiet) {}

  /// Continues from a checkpoint: the film's sums now, the integrator's state in resume().
  void restore(CheckpointData data) {
    ByteReader film(data.film, fmt::format("--resume {}: film state", settings_.resume_file));
    built_.film->load(film);
    resumed_ = std::move(data);
    resumed_seconds_ = resumed_->seconds;
    nonfinite_.store(resumed_->nonfinite);
    if (resumed_->first_nonfinite[0] >= 0) first_nonfinite_ = {resumed_->first_nonfinite[0], resumed_->first_nonfinite[1]};
  }
  void set_checkpoint(std::string path, CheckpointKey key) {
    checkpoint_path_ = std::move(path);
    key_ = std::move(key);
  }

  std::optional<ResumePoint> resume(SampleIntegrator& integrator) override {
    if (!resumed_) return std::nullopt;
    ByteReader in(resumed_->integrator, fmt::format("--resume {}: integrator state", settings_.resume_file));
    integrator.load_state(in);
    if (!in.at_end()) throw Error(fmt::format("--resume {}: the integrator's state has unexpected contents", settings_.resume_file));
    return resumed_->point;
  }
  void pass_complete(const ResumePoint& next, const SampleIntegrator& integrator) override {
    bool periodic = settings_.checkpoint_every > 0.0 && elapsed() - last_checkpoint_ >= settings_.checkpoint_every;
    if (checkpoint_path_.empty() || !(periodic || stop_requested())) return;
    auto t0 = Clock::now();
    CheckpointData d;
    d.key = key_;
    d.point = next;
    d.seconds = elapsed();
    d.nonfinite = nonfinite_.load();
    if (first_nonfinite_) d.first_nonfinite[0] = first_nonfinite_->first, d.first_nonfinite[1] = first_nonfinite_->second;
    ByteWriter film, state;
    built_.film->save(film);
    integrator.save_state(state);
    d.film = std::move(film.bytes());
    d.integrator = std::move(state.bytes());
    write_checkpoint(checkpoint_path_, d);
    written_ = checkpoint_path_;
    // Writing is not render time: a time budget is not eaten by checkpoints.
    snapshot_seconds_ += seconds_since(t0);
    last_checkpoint_ = elapsed();
  }
  bool stop_requested() const override { return settings_.handle_signals && InterruptGuard::signal_received() != 0; }
  const std::string& checkpoint_written() const { return written_; }

  const Scene& scene() const override { return *built_.scene; }
  Film& film() override { return *built_.film; }
  const Sampler& sampler() const override { return *built_.sampler; }
  const RenderOptions& options() const override { return options_; }
  double elapsed() const override { return resumed_seconds_ + seconds_since(start_) - snapshot_seconds_; }
  bool should_stop() const override {
    return options_.time_budget > 0.0 && elapsed() >= options_.time_budget;
  }
  void progress(uint64_t done, uint64_t total) override {
    progress_.update(done, total, elapsed(), options_.time_budget);
  }
  void report_nonfinite(Point2i pixel) override {
    built_.film->add_nonfinite(pixel);
    if (nonfinite_.fetch_add(1) == 0) {
      std::lock_guard<std::mutex> lock(mutex_);
      first_nonfinite_ = {pixel.x, pixel.y};
    }
  }
  void set_completed_spp(int spp, const std::function<ImageRgb()>& estimate, double splat_spp) override {
    completed_spp_ = spp;
    splat_spp_ = splat_spp > 0.0 ? splat_spp : spp;
    if (!settings_.on_snapshot || next_snapshot_ >= settings_.snapshot_times.size()) return;
    double t = elapsed();
    if (t < settings_.snapshot_times[next_snapshot_]) return;
    while (next_snapshot_ < settings_.snapshot_times.size() && settings_.snapshot_times[next_snapshot_] <= t)
      ++next_snapshot_;
    auto t0 = Clock::now();
    settings_.on_snapshot(t, spp, estimate ? estimate() : built_.film->image(splat_spp_));
    snapshot_seconds_ += seconds_since(t0);
  }

  void start() { start_ = Clock::now(); }
  void finish() { progress_.finish(elapsed()); }
  int completed_spp() const { return completed_spp_; }
  double splat_spp() const { return splat_spp_; }
  uint64_t nonfinite() const { return nonfinite_.load(); }
  std::optional<std::pair<int, int>> first_nonfinite() const { return first_nonfinite_; }

 private:
  BuiltScene& built_;
  RenderOptions options_;
  const RenderSettings& settings_;
  size_t next_snapshot_ = 0;
  double snapshot_seconds_ = 0.0;
  ProgressReporter progress_;
  Clock::time_point start_ = Clock::now();
  std::atomic<uint64_t> nonfinite_{0};
  std::optional<std::pair<int, int>> first_nonfinite_;
  std::mutex mutex_;
  int completed_spp_ = 0;
  double splat_spp_ = 0.0;
  std::optional<CheckpointData> resumed_;
  double resumed_seconds_ = 0.0;
  std::string checkpoint_path_, written_;
  CheckpointKey key_;
  double last_checkpoint_ = 0.0;
};

// What a checkpoint must agree on with the render that resumes it, besides the scene's fingerprint.
CheckpointKey checkpoint_key(const std::string& hash, const BuiltScene& built, const RenderOptions& options,
                             const SceneDescription& desc) {
  CheckpointKey key;
  key.scene_hash = hash;
  Point2i res = built.film->resolution();
  key.fields = {{"integrator", built.integrator_name},
                {"sampler", built.sampler_name},
                {"resolution", fmt::format("{}x{}", res.x, res.y)},
                {"seed", std::to_string(desc.sampler.params.get_int("seed", 0))},
                {"samples per pixel", options.spp == INT_MAX ? "until the time budget" : std::to_string(options.spp)},
                {"first sample", std::to_string(options.first_sample)}};
  return key;
}

// Replaces a plugin chosen by the scene with one named on the command line. Parameters the new
// plugin also declares (maxdepth, pixelsamples, seed) carry over; the others are dropped, with a note.
void override_plugin(SceneEntity& entity, PluginKind kind, const std::string& name, Registry& registry) {
  const PluginInfo& info = *registry.load(kind, name).info;
  ParamSet kept;
  for (const Param& p : entity.params.params()) {
    bool known = false;
    for (size_t i = 0; i < info.param_count; ++i)
      known = known || (p.name == info.params[i].name && std::string(info.params[i].type) != "unsupported");
    if (known)
      kept.add(p);
    else if (entity.type != name)
      warning(p.loc, fmt::format("parameter '{}' dropped: {} '{}' does not take it", p.name,
                                 plugin_kind_name(kind), name));
  }
  entity.type = name;
  entity.params = std::move(kept);
}

std::string trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

// Whole-text integer and float parsing (no trailing characters, finite).
bool parse_integer(const std::string& text, double* out) {
  long long v = 0;
  const char* first = text.data() + (!text.empty() && text[0] == '+' ? 1 : 0);
  const char* last = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(first, last, v);
  if (ec != std::errc() || ptr != last || first == last || v < INT_MIN || v > INT_MAX) return false;
  *out = static_cast<double>(v);
  return true;
}

bool parse_float(const std::string& text, double* out) {
  if (text.empty()) return false;
  char* end = nullptr;
  double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

// Numbers of a multi-component value: "0.5 0.5 0.5" or "0.5,0.5,0.5".
std::vector<std::string> split_numbers(const std::string& text) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : text) {
    if (c == ',' || std::isspace(static_cast<unsigned char>(c))) {
      if (!cur.empty()) out.push_back(cur), cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

int type_components(const std::string& base) {
  if (base == "rgb" || base == "point3" || base == "vector3" || base == "normal") return 3;
  if (base == "point2" || base == "vector2") return 2;
  return 1;
}

// The Param an override sets, typed by the plugin's declaration `spec`. Errors start with the origin.
Param typed_param(const ParamSpec& spec, const ParamOverride& o, const std::string& what) {
  auto fail = [&](const std::string& msg) { return Error(fmt::format("{}: {}", o.origin, msg)); };
  std::string type = spec.type;
  bool array = type.size() > 2 && type.compare(type.size() - 2, 2, "[]") == 0;
  std::string base = array ? type.substr(0, type.size() - 2) : type;
  Param p{base, o.name, {}, {}, {}, {}};
  // Plugins locate their own value errors ("maxdepth must be >= 0") with loc_of(name); this
  // location lets render() recognise those and name the override instead of a file.
  p.loc.filename = std::make_shared<const std::string>(o.origin);
  std::string value = base == "string" ? o.value : trim(o.value);
  if (base == "string") {
    p.strings.push_back(value);
  } else if (base == "bool") {
    std::string v = value;
    std::transform(v.begin(), v.end(), v.begin(), [](unsigned char c) { return std::tolower(c); });
    if (v != "true" && v != "false") throw fail(fmt::format("'{}' is not a bool (true or false)", o.value));
    p.bools.push_back(v == "true");
  } else if (base == "integer" || base == "float" || type_components(base) > 1) {
    std::vector<std::string> words = split_numbers(value);
    size_t k = static_cast<size_t>(type_components(base));
    if (!array && k == 1 && words.size() != 1) {
      throw fail(fmt::format("'{}' is not {}", o.value, base == "integer" ? "an integer" : "a float"));
    }
    if (!array && words.size() != k)
      throw fail(fmt::format("parameter '{}' of {} is of type {} and takes {} numbers (e.g. {}=0.5,0.5,0.5), got {}",
                             o.name, what, base, k, o.name, words.size()));
    if (array && (words.empty() || words.size() % k != 0))
      throw fail(fmt::format("parameter '{}' of {} is of type {} and takes a multiple of {} numbers, got {}",
                             o.name, what, type, k, words.size()));
    for (const std::string& w : words) {
      double v = 0;
      bool ok = base == "integer" ? parse_integer(w, &v) : parse_float(w, &v);
      if (!ok) throw fail(fmt::format("'{}' is not {}", w, base == "integer" ? "an integer" : "a float"));
      p.numbers.push_back(v);
    }
  } else {
    throw fail(fmt::format("parameter '{}' of {} has type '{}', which cannot be set on the command line",
                           o.name, what, type));
  }
  return p;
}

}  // namespace

ParamOverride parse_param_override(const std::string& text, const std::string& option) {
  ParamOverride o;
  o.origin = fmt::format("{} {}", option, text);
  size_t eq = text.find('=');
  if (eq == std::string::npos)
    throw Error(fmt::format("{}: expected NAME=VALUE (e.g. maxdepth=8), got '{}'", option, text));
  o.name = trim(text.substr(0, eq));
  o.value = text.substr(eq + 1);
  bool name_ok = !o.name.empty();
  for (char c : o.name) name_ok = name_ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
  if (!name_ok)
    throw Error(fmt::format("{}: expected NAME=VALUE with a parameter name before '=' (e.g. maxdepth=8), got '{}'",
                            option, text));
  return o;
}

std::vector<Param> typed_param_overrides(const std::string& integrator, const std::vector<ParamOverride>& overrides,
                                         Registry& registry) {
  std::vector<Param> out;
  if (overrides.empty()) return out;
  const PluginInfo& info = *registry.load(PluginKind::Integrator, integrator).info;
  std::string what = fmt::format("integrator '{}'", info.name);
  for (const ParamOverride& o : overrides) {
    const ParamSpec* match = nullptr;
    for (size_t i = 0; i < info.param_count; ++i)
      if (o.name == info.params[i].name) match = &info.params[i];
    if (!match) {
      std::string best, names;
      size_t best_d = SIZE_MAX;
      for (size_t i = 0; i < info.param_count; ++i) {
        if (std::string(info.params[i].type) == "unsupported") continue;
        size_t d = edit_distance(o.name, info.params[i].name);
        if (d < best_d) best_d = d, best = info.params[i].name;
        names += fmt::format("{}{}", names.empty() ? "" : ", ", info.params[i].name);
      }
      std::string hint = !best.empty() && best_d <= std::max<size_t>(2, o.name.size() / 3)
                             ? fmt::format("; did you mean '{}'?", best)
                             : fmt::format("; it takes: {}", names.empty() ? "no parameters" : names);
      throw Error(fmt::format("{}: unknown parameter '{}' for {}{}", o.origin, o.name, what, hint));
    }
    if (std::string(match->type) == "unsupported")
      throw Error(fmt::format("{}: parameter '{}' of {} is not supported by Penumbra{}{}", o.origin, o.name, what,
                              match->doc && *match->doc ? ": " : "", match->doc ? match->doc : ""));
    Param p = typed_param(*match, o, what);
    auto same = std::find_if(out.begin(), out.end(), [&](const Param& q) { return q.name == p.name; });
    if (same != out.end())
      *same = std::move(p);
    else
      out.push_back(std::move(p));
  }
  return out;
}

void check_param_overrides(const std::string& integrator, const std::vector<ParamOverride>& overrides,
                           const std::vector<std::string>& plugin_dirs) {
  Registry registry(plugin_dirs.empty() ? Registry::default_search_dirs() : plugin_dirs);
  typed_param_overrides(integrator, overrides, registry);
}

RenderResult render(const RenderSettings& settings) {
  auto t0 = Clock::now();
  size_t rays_before = total_rays();
  check_command_line_outputs(settings);
  SceneDescription desc = parse_scene_file(settings.scene_file);
  Registry registry(settings.plugin_dirs.empty() ? Registry::default_search_dirs() : settings.plugin_dirs);

  // Command-line overrides act on the description, before the scene's own choices are looked up.
  if (!settings.integrator.empty())
    override_plugin(desc.integrator, PluginKind::Integrator, settings.integrator, registry);
  if (!settings.sampler.empty())
    override_plugin(desc.sampler, PluginKind::Sampler, settings.sampler, registry);
  // --param NAME=VALUE, after --integrator: typed by the integrator's table, replacing the file's value.
  std::vector<Param> overrides = typed_param_overrides(
      desc.integrator.type.empty() ? kDefaultIntegrator : desc.integrator.type, settings.integrator_params, registry);
  if (!overrides.empty()) {
    ParamSet params;
    for (const Param& p : desc.integrator.params.params())
      if (std::none_of(overrides.begin(), overrides.end(), [&](const Param& o) { return o.name == p.name; }))
        params.add(p);
    for (const Param& p : overrides) params.add(p);
    desc.integrator.params = std::move(params);
  }
  if (settings.spp) {
    if (*settings.spp <= 0) throw Error("--spp must be positive");
    desc.sampler.params.set_int("pixelsamples", *settings.spp);
  }
  if (settings.seed) desc.sampler.params.set_int("seed", static_cast<int>(*settings.seed));
  if (settings.spectral) desc.film.params.set_bool("spectral", true);
  if (settings.resolution) {
    desc.film.params.set_int("xresolution", settings.resolution->first);
    desc.film.params.set_int("yresolution", settings.resolution->second);
  }

  SampleRange range = apply_output_settings(settings, desc);
  std::string hash = scene_hash(desc);

  int threads = settings.threads > 0 ? settings.threads : tbb::info::default_concurrency();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);

  BuiltScene built;
  try {
    built = build_scene(desc, registry);
  } catch (const Error& e) {
    // An integrator's complaint about an overridden value names the option, not a file position.
    for (const Param& p : overrides)
      if (e.loc().filename && e.loc().filename == p.loc.filename)
        throw Error(fmt::format("{}: {}", *p.loc.filename, e.what()));
    throw;
  }
  report_silent_results(silent_result_warnings(desc, built), settings.strict);
  built.film->set_firefly_threshold(settings.firefly_threshold);
  RenderOptions options;
  options.time_budget = settings.time_budget;
  options.threads = threads;
  options.spp = built.sampler->samples_per_pixel();
  options.spectral = built.spectral;
  if (built.spectral) {
    // Asked for on the command line, the complaint names the option; from the scene, its line.
    auto refuse = [&](const std::string& why) {
      if (settings.spectral) return Error("--spectral: " + why);
      return Error(desc.film.params.loc_of("spectral"), why);
    };
    auto* si = dynamic_cast<const SampleIntegrator*>(built.integrator.get());
    if (!si || !si->supports_spectral())
      throw refuse(fmt::format("integrator '{}' does not support spectral transport yet (available: path, bdpt, lighttracing, sppm)",
                               built.integrator_name));
  }
  if (settings.time_budget > 0.0 && !settings.spp) options.spp = INT_MAX;
  if (options.spp <= 0) throw Error(desc.sampler.params.loc_of("pixelsamples"), "pixelsamples must be positive");
  // Texture filter footprint as pbrt-v4 scales it, from the whole render's samples per pixel (the
  // parts of a split render filter alike).
  built.scene->set_texture_footprint_scale(std::max(0.125f, 1.f / std::sqrt(static_cast<float>(options.spp))));
  if (range.split) {
    options.spp = range.count;
    options.first_sample = range.first;
  }
  double load_seconds = seconds_since(t0);

  Session session(built, options, settings);
  CheckpointKey key = checkpoint_key(hash, built, options, desc);
  std::string checkpoint_path = settings.checkpoint_file;
  if (checkpoint_path.empty() && settings.handle_signals)
    checkpoint_path = (settings.output.empty() ? built.output_filename : settings.output) + ".checkpoint";
  if (!checkpoint_path.empty())
    check_checkpoint_path(checkpoint_path, settings.checkpoint_file.empty() ? "checkpoint of -o" : "--checkpoint");
  session.set_checkpoint(checkpoint_path, key);
  if (!settings.resume_file.empty()) {
    if (!dynamic_cast<SampleIntegrator*>(built.integrator.get()))
      throw Error(fmt::format("--resume: integrator '{}' does not run on the core's render loop and cannot resume",
                              built.integrator_name));
    session.restore(read_checkpoint(settings.resume_file, key));
  }
  std::shared_ptr<const InterruptGuard> interrupts;
  if (settings.handle_signals) interrupts = std::make_shared<const InterruptGuard>();
  session.start();
  built.integrator->render(session);
  double seconds = session.elapsed();
  session.finish();

  RenderResult result;
  result.interrupted_by = session.stop_requested() ? InterruptGuard::signal_received() : 0;
  result.checkpoint = session.checkpoint_written();
  result.signal_handlers = interrupts;
  result.image = built.film->image(session.splat_spp());
  result.aovs = built.film->aov_layers();
  if (built.film->has_splats()) built.structures_built.push_back("film_splat_buffer");
  for (const Object* o : {static_cast<const Object*>(built.integrator.get()), static_cast<const Object*>(built.sampler.get())})
    for (auto& name : o->structures_built())
      if (std::find(built.structures_built.begin(), built.structures_built.end(), name) == built.structures_built.end())
        built.structures_built.push_back(name);
  RenderStats& s = result.stats;
  s.seconds = seconds;
  s.load_seconds = load_seconds;
  s.spp = session.completed_spp();
  const auto* sample_integrator = dynamic_cast<const SampleIntegrator*>(built.integrator.get());
  s.samples_per_pixel = sample_integrator && sample_integrator->film_holds_estimate()
                            ? std::max(session.splat_spp(), static_cast<double>(s.spp))
                            : s.spp;
  s.pixels = static_cast<uint64_t>(result.image.width) * result.image.height;
  s.rays = total_rays() - rays_before;
  s.nonfinite_samples = session.nonfinite();
  s.firefly_samples = built.film->firefly_count();
  s.firefly_threshold = settings.firefly_threshold;
  s.first_nonfinite_pixel = session.first_nonfinite();
  s.peak_memory_bytes = peak_memory_bytes();
  s.plugins_loaded = registry.loaded();
  s.structures_built = built.structures_built;
  s.integrator = built.integrator_name;
  s.sampler = built.sampler_name;
  s.scene_file = settings.scene_file;
  s.output = settings.output.empty() ? built.output_filename : settings.output;
  s.threads = threads;
  s.seed = static_cast<uint32_t>(desc.sampler.params.get_int("seed", 0));
  s.triangles = built.scene->triangle_count();
  s.instances = built.scene->instance_count();
  s.instanced_triangles = built.scene->instanced_triangle_count();
  s.scene_hash = hash;
  s.first_sample = options.first_sample;
  s.spp_total = range.split ? range.total : s.spp;
  s.aovs = built.film->aovs().names();
  s.integrator_stats = built.integrator->statistics();
  for (const ParamOverride& o : settings.integrator_params) s.integrator_params.emplace_back(o.name, o.value);
  if (s.spp == 0 && session.splat_spp() == 0.0 && !result.interrupted_by)
    warning({}, fmt::format("no pass was completed{}: the image is black",
                            settings.time_budget > 0.0
                                ? fmt::format(" within the time budget of {:g} s (the integrator's preparation, e.g. a "
                                              "pilot, took it all)",
                                              settings.time_budget)
                                : ""));
  if (s.nonfinite_samples > 0)
    warning({}, fmt::format("{} non-finite samples were discarded (first at pixel {}, {})",
                            s.nonfinite_samples, s.first_nonfinite_pixel->first,
                            s.first_nonfinite_pixel->second));
  return result;
}

std::string stats_json(const RenderStats& s) {
  nlohmann::json j;
  j["seconds"] = s.seconds;
  j["load_seconds"] = s.load_seconds;
  j["spp"] = s.spp;
  j["pixels"] = s.pixels;
  j["rays"] = s.rays;
  j["mrays_per_second"] = s.mrays_per_second();
  j["samples_per_pixel"] = s.samples_per_pixel;
  j["samples_per_second"] = s.seconds > 0 ? s.pixels * s.samples_per_pixel / s.seconds : 0.0;
  j["plugins_loaded"] = s.plugins_loaded;
  j["structures_built"] = s.structures_built;
  j["nonfinite_samples"] = s.nonfinite_samples;
  j["firefly_samples"] = s.firefly_samples;
  j["firefly_threshold"] = s.firefly_threshold;
  j["first_nonfinite_pixel"] = s.first_nonfinite_pixel
                                   ? nlohmann::json::array({s.first_nonfinite_pixel->first,
                                                            s.first_nonfinite_pixel->second})
                                   : nlohmann::json(nullptr);
  j["peak_memory_bytes"] = s.peak_memory_bytes;
  j["integrator"] = s.integrator;
  j["sampler"] = s.sampler;
  j["scene"] = s.scene_file;
  j["output"] = s.output;
  j["threads"] = s.threads;
  j["seed"] = s.seed;
  j["triangles"] = s.triangles;
  j["instances"] = s.instances;
  j["instanced_triangles"] = s.instanced_triangles;
  j["scene_hash"] = s.scene_hash;
  j["spp_total"] = s.spp_total;
  j["first_sample"] = s.first_sample;
  nlohmann::json integrator_stats = nlohmann::json::object();
  for (const auto& [name, value] : s.integrator_stats) integrator_stats[name] = value;
  j["integrator_stats"] = integrator_stats;
  j["integrator_params"] = nlohmann::json::object();
  for (const auto& [name, value] : s.integrator_params) j["integrator_params"][name] = value;
  return j.dump(2) + "\n";
}

void write_outputs(const RenderSettings& settings, const RenderResult& result) {
  const RenderStats& s = result.stats;
  write_render_image(result);
  if (!settings.stats_file.empty()) write_text_atomically(settings.stats_file, stats_json(s));
}

}  // namespace penumbra
