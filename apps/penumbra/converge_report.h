// The HTML report of `penumbra converge`: one self-contained file (images embedded as PNG data
// URIs, plots as inline SVG, no external script or style) with the error-versus-time plots and their
// interquartile bands, the table of final errors and efficiencies, every pairwise ratio with its
// interval, and for each configuration its image at equal time, a false-colour map of its per-pixel
// error and a viewer that wipes between any two of them and the reference at a chosen zoom.
#pragma once

#include <penumbra/image.h>

#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace penumbra::cli {

struct ReportImages {
  ImageRgb reference;
  std::vector<std::pair<std::string, ImageRgb>> configs;  // each configuration's first run at its last snapshot
};

/// Writes `path` from the study's summary (summary.json's content) and images.
void write_report(const std::string& path, const nlohmann::json& summary, const ReportImages& images);

}  // namespace penumbra::cli
