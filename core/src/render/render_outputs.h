// What a render writes besides the beauty: AOV layers, the header metadata that identifies it, and
// the sample range of a part of a split render (--spp-total/--spp-offset/--spp-count).
#pragma once

#include "image/exr_layers.h"
#include "parser/scene_description.h"
#include "render/render_session.h"

#include <string>
#include <utility>
#include <vector>

namespace penumbra {

/// The samples a render takes: indices [first, first + count) of a sequence of `total`.
struct SampleRange {
  int total = 0, first = 0, count = 0;
  bool split = false;  // --spp-total was given
};

/// The image written when neither -o nor the Film's "filename" names one.
inline constexpr const char* kDefaultOutput = "penumbra.exr";

/// Checks the files named on the command line (-o, --stats) before the scene is even read: the
/// folder exists and accepts new files, the image extension is known (and an 8-bit format has its
/// OpenColorIO config). Throws Error naming the option.
void check_command_line_outputs(const RenderSettings& settings);

/// Checks the split and AOV options against each other and the output image (the one of -o, the
/// Film's "filename" or the default: writable, known extension, EXR when it must hold AOV layers or
/// a split part; an error names -o or the scene's file:line:col), then writes them into the
/// description: pixelsamples becomes the total (so samplers that depend on it agree between
/// parts) and the Film's "aovs" gains --aov and, for a part, "samples" (which `penumbra merge`
/// needs). Throws Error before anything is built or rendered.
SampleRange apply_output_settings(const RenderSettings& settings, SceneDescription& desc);

/// Half-open index ranges as "0-16,32-48"; parse_ranges() throws Error for malformed text.
std::string format_ranges(const std::vector<std::pair<int, int>>& ranges);
std::vector<std::pair<int, int>> parse_ranges(const std::string& text);

/// Header entries of a render's image (penumbra:version, scene_hash, integrator, sampler, spp,
/// spp_total, seed, sample_range, scene, aovs).
std::vector<std::pair<std::string, std::string>> render_metadata(const RenderStats& stats);

/// Writes the beauty with write_image(), or, when there are AOV layers, one multilayer EXR.
void write_render_image(const RenderResult& result);

}  // namespace penumbra
