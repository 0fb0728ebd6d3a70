// One render from a scene file to images and a stats file: the entry point the command-line
// program, the tests and the benchmarks share.
#pragma once

#include "image/exr_layers.h"
#include "image/image_io.h"

#include <penumbra/params.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace penumbra {

class InterruptGuard;
class Registry;

/// One integrator parameter set on the command line (`--param NAME=VALUE`, or `/NAME=VALUE` in a
/// `penumbra converge` configuration). VALUE is text; its type comes from the integrator's
/// parameter table. `origin` prefixes every error about it, e.g. "--param maxdepth=abc".
struct ParamOverride {
  std::string name, value, origin;
};

/// Splits "NAME=VALUE" (VALUE may be empty for strings). `option` names where it came from
/// ("--param"); a missing '=' or an empty or malformed NAME is an Error that names it.
ParamOverride parse_param_override(const std::string& text, const std::string& option = "--param");

/// Turns overrides into typed parameters of integrator `integrator` (a name or alias) by its declared
/// table: an unknown name (with a did-you-mean), an "unsupported" parameter or a value that does not
/// parse as the declared type is an Error starting with the override's origin. Returns one Param
/// per override (a later override of the same name replaces an earlier one).
std::vector<Param> typed_param_overrides(const std::string& integrator, const std::vector<ParamOverride>& overrides,
                                         Registry& registry);
/// The same check without rendering, for validating before long work (`penumbra converge`).
void check_param_overrides(const std::string& integrator, const std::vector<ParamOverride>& overrides,
                           const std::vector<std::string>& plugin_dirs = {});

/// Command-line choices; each one, when set, overrides what the scene file says.
struct RenderSettings {
  std::string scene_file;
  std::string output;                    // image path; default: the Film's filename
  std::optional<int> spp;
  double time_budget = 0.0;              // seconds, 0 = none
  int threads = 0;                       // 0 = all cores
  std::optional<uint32_t> seed;
  bool spectral = false;                 // --spectral: the Film's "spectral" set to true
  std::string integrator;                // --integrator NAME
  std::string sampler;                   // --sampler NAME
  std::vector<ParamOverride> integrator_params;  // --param NAME=VALUE, applied after --integrator
  std::optional<std::pair<int, int>> resolution;  // --res WxH
  std::string stats_file;                // --stats FILE.json
  bool image_written = true;             // false: the caller keeps the image (converge); its path is not checked
  bool quiet = false;                    // no progress output
  bool strict = false;                   // --strict: scenes that render black (render/scene_warnings.h) are errors
  float firefly_threshold = 1000.f;      // samples brighter than this (max component) are counted
  std::vector<std::string> plugin_dirs;  // default: Registry::default_search_dirs()
  /// Snapshots for convergence studies: after the first complete pass at or past each of these
  /// render times (seconds, ascending), `on_snapshot` receives the current estimate. The time spent
  /// in the callback does not count as render time.
  std::vector<double> snapshot_times;
  std::function<void(double seconds, int spp, const ImageRgb& image)> on_snapshot;
  std::vector<std::string> aovs;         // --aov NAME[,NAME...], added to the Film's "aovs"
  /// Split renders (docs/farm.md): with --spp-total N this render takes sample indices
  /// [spp_offset, spp_offset + spp_count) of one N-sample render; the default count is the rest.
  std::optional<int> spp_total;
  int spp_offset = 0;
  std::optional<int> spp_count;
  /// Checkpoints (docs/robustness.md): written atomically after the first complete pass at least
  /// `checkpoint_every` seconds (0: never periodically) after the previous one, and when the render
  /// is interrupted (to `checkpoint_file`, default: the image's path + ".checkpoint").
  std::string checkpoint_file;           // --checkpoint FILE
  double checkpoint_every = 0.0;         // --checkpoint-every SECONDS
  std::string resume_file;               // --resume FILE: continue the render saved there
  /// SIGINT/SIGTERM end the render after the current pass, with its image and a checkpoint.
  bool handle_signals = false;
};

struct RenderStats {
  double seconds = 0.0;        // rendering only
  double load_seconds = 0.0;   // parsing, plugin loading, BVH build
  int spp = 0;
  // Pixel samples in the image over the pixel count: spp plus what a pass cut by the time budget
  // added (equal to spp where the integrator drops a cut pass, as sppm does its iteration).
  double samples_per_pixel = 0.0;
  uint64_t pixels = 0;
  uint64_t rays = 0;
  uint64_t nonfinite_samples = 0;
  uint64_t firefly_samples = 0;          // samples or splats above firefly_threshold (kept, not clamped)
  float firefly_threshold = 0.f;
  std::optional<std::pair<int, int>> first_nonfinite_pixel;
  uint64_t peak_memory_bytes = 0;
  std::vector<std::string> plugins_loaded;
  std::vector<std::string> structures_built;
  std::string integrator, sampler, scene_file, output;
  int threads = 0;
  uint32_t seed = 0;
  size_t triangles = 0;        // stored once (an instanced object's triangles count once)
  size_t instances = 0;        // ObjectInstance placements
  size_t instanced_triangles = 0;  // triangles as the instances place them
  std::string scene_hash;      // render_outputs.h
  int spp_total = 0;           // samples of the whole render this one is a part of (= spp unsplit)
  int first_sample = 0;        // index of this render's first sample
  std::string aovs;            // AOVs written, e.g. "albedo,samples"
  std::vector<std::pair<std::string, std::string>> integrator_params;  // overrides given, as text
  std::vector<std::pair<std::string, double>> integrator_stats;  // Object::statistics() of the integrator
  double mrays_per_second() const { return seconds > 0 ? rays / seconds * 1e-6 : 0.0; }
};

struct RenderResult {
  int interrupted_by = 0;        // the signal that ended the render early, or 0
  std::string checkpoint;        // the last checkpoint written, if any
  ImageRgb image;
  std::vector<ImageLayer> aovs;  // written with the beauty as EXR layers
  RenderStats stats;
  /// With settings.handle_signals: the SIGINT/SIGTERM handlers installed for the render. They stay
  /// installed while the result lives, so a second signal while the outputs are written still
  /// exits at once (with its message) instead of killing the process silently.
  std::shared_ptr<const InterruptGuard> signal_handlers;
};

/// Parses, builds and renders. Throws Error for anything the user can fix.
RenderResult render(const RenderSettings& settings);
/// Writes the image (and the stats when settings.stats_file is set).
void write_outputs(const RenderSettings& settings, const RenderResult& result);
std::string stats_json(const RenderStats& stats);

}  // namespace penumbra
