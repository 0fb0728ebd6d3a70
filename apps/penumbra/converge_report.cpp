#include "converge_report.h"

#include "render/image_metrics.h"
#include "util/output_file.h"

#include <penumbra/error.h>

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <unistd.h>

namespace fs = std::filesystem;

namespace penumbra::cli {

namespace {

std::string base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = static_cast<uint8_t>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<uint8_t>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) v |= static_cast<uint8_t>(bytes[i + 2]);
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[v & 63] : '=';
  }
  return out;
}

// A PNG data URI of `img` through the sRGB display's Standard view (written to a temporary file by
// the one image writer, then embedded).
std::string png_data_uri(const ImageRgb& img) {
  fs::path tmp = fs::temp_directory_path() / fmt::format("penumbra-report-{}-{}.png", ::getpid(), std::rand());
  write_image(tmp.string(), img, {}, "Standard");
  std::ifstream in(tmp, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  fs::remove(tmp);
  return "data:image/png;base64," + base64(bytes);
}

float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

// False colour of the per-pixel relative squared error (I - R)^2 / (R^2 + eps), channels averaged,
// on a log scale from 1e-4 (dark blue) to 1 and above (yellow); stored so the Standard view shows
// the palette's sRGB values.
ImageRgb error_map(const ImageRgb& img, const ImageRgb& ref) {
  static const float palette[5][3] = {{0.05f, 0.03f, 0.35f}, {0.23f, 0.32f, 0.55f}, {0.13f, 0.57f, 0.55f},
                                      {0.37f, 0.79f, 0.38f}, {0.99f, 0.91f, 0.14f}};
  ImageRgb out{img.width, img.height, std::vector<float>(img.pixels.size())};
  for (size_t p = 0; p < img.pixels.size() / 3; ++p) {
    double e = 0.0;
    for (int c = 0; c < 3; ++c) {
      double r = ref.pixels[3 * p + c], d = img.pixels[3 * p + c] - r;
      e += d * d / (r * r + kRelMseEpsilon) / 3.0;
    }
    double x = std::clamp((std::log10(std::max(e, 1e-12)) + 4.0) / 4.0, 0.0, 1.0) * 4.0;
    int i = std::min(3, static_cast<int>(x));
    double f = x - i;
    for (int c = 0; c < 3; ++c)
      out.pixels[3 * p + c] = srgb_to_linear(static_cast<float>((1 - f) * palette[i][c] + f * palette[i + 1][c]));
  }
  return out;
}

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};

// A log-log plot of `metric`'s median against time per configuration, with its interquartile band.
std::string svg_plot(const nlohmann::json& summary, const std::string& metric, const std::string& label) {
  const double W = 560, H = 360, L = 70, R = 170, T = 20, B = 50;
  double t0 = 1e300, t1 = 0, e0 = 1e300, e1 = 0;
  for (const auto& [name, data] : summary["configs"].items())
    for (const auto& p : data["points"]) {
      double t = p["seconds"], lo = p[metric + "_q25"], hi = p[metric + "_q75"];
      if (t > 0) t0 = std::min(t0, t), t1 = std::max(t1, t);
      if (lo > 0) e0 = std::min(e0, lo);
      if (hi > 0) e1 = std::max(e1, hi);
    }
  if (!(t1 > 0) || !(e1 > 0)) return "<p>no data to plot</p>";
  if (t1 <= t0) t1 = t0 * 2;
  if (e1 <= e0) e1 = e0 * 2;
  double lt0 = std::floor(std::log10(t0)), lt1 = std::ceil(std::log10(t1));
  double le0 = std::floor(std::log10(e0)), le1 = std::ceil(std::log10(e1));
  auto X = [&](double t) { return L + (std::log10(t) - lt0) / (lt1 - lt0) * (W - L - R); };
  auto Y = [&](double e) { return H - B - (std::log10(std::max(e, 1e-300)) - le0) / (le1 - le0) * (H - T - B); };
  std::ostringstream o;
  o << fmt::format("<svg class=\"plot\" xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\">",
                   W, H, W, H);
  o << fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#888\"/>", L, T, W - L - R,
                   H - T - B);
  for (double k = lt0; k <= lt1; ++k)
    o << fmt::format("<text x=\"{:.1f}\" y=\"{}\" font-size=\"11\" text-anchor=\"middle\">1e{}</text>", X(std::pow(10, k)),
                     H - B + 16, static_cast<int>(k));
  for (double k = le0; k <= le1; ++k)
    o << fmt::format("<text x=\"{}\" y=\"{:.1f}\" font-size=\"11\" text-anchor=\"end\">1e{}</text>"
                     "<line x1=\"{}\" x2=\"{}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#eee\"/>",
                     L - 4, Y(std::pow(10, k)) + 4, static_cast<int>(k), L, W - R, Y(std::pow(10, k)), Y(std::pow(10, k)));
  o << fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"12\" text-anchor=\"middle\">render time [s]</text>",
                   (L + W - R) / 2, H - 12);
  o << fmt::format("<text x=\"14\" y=\"{}\" font-size=\"12\" transform=\"rotate(-90 14 {})\" text-anchor=\"middle\">{}</text>",
                   (T + H - B) / 2, (T + H - B) / 2, escape(label));
  int k = 0;
  for (const auto& [name, data] : summary["configs"].items()) {
    const char* colour = kColours[k % 8];
    std::string band, line;
    const auto& pts = data["points"];
    for (const auto& p : pts) band += fmt::format("{:.1f},{:.1f} ", X(p["seconds"]), Y(p[metric + "_q75"]));
    for (auto it = pts.rbegin(); it != pts.rend(); ++it)
      band += fmt::format("{:.1f},{:.1f} ", X((*it)["seconds"]), Y((*it)[metric + "_q25"]));
    for (const auto& p : pts) line += fmt::format("{:.1f},{:.1f} ", X(p["seconds"]), Y(p[metric]));
    o << fmt::format("<polygon points=\"{}\" fill=\"{}\" fill-opacity=\"0.15\" stroke=\"none\"/>", band, colour);
    o << fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>", line, colour);
    o << fmt::format("<rect x=\"{}\" y=\"{}\" width=\"12\" height=\"3\" fill=\"{}\"/><text x=\"{}\" y=\"{}\" font-size=\"11\">{}</text>",
                     W - R + 10, T + 10 + 16 * k, colour, W - R + 26, T + 14 + 16 * k, escape(name));
    ++k;
  }
  o << "</svg>";
  return o.str();
}

std::string number(const nlohmann::json& v) { return fmt::format("{:.4g}", v.get<double>()); }

}  // namespace

void write_report(const std::string& path, const nlohmann::json& summary, const ReportImages& images) {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>penumbra converge: "
    << escape(summary["scene"].get<std::string>()) << "</title>\n<style>\n"
       "body{font-family:sans-serif;margin:24px;color:#222;max-width:1400px}table{border-collapse:collapse;margin:8px 0}"
       "td,th{border:1px solid #ccc;padding:3px 8px;font-size:13px;text-align:right}th{background:#f3f3f3}"
       "td.l,th.l{text-align:left}.warn{background:#fdd;border:2px solid #c00;padding:8px;font-weight:bold}"
       ".ok{background:#efe;border:1px solid #8c8;padding:8px}.grid{display:flex;flex-wrap:wrap;gap:16px}"
       ".cell{font-size:12px}.cell img{image-rendering:pixelated;border:1px solid #ccc;display:block}"
       "#viewer{position:relative;display:inline-block;overflow:hidden;border:1px solid #888}"
       "#viewer img{image-rendering:pixelated;display:block}#rightimg{position:absolute;left:0;top:0}"
       "</style></head><body>\n";
  h << "<h1>Convergence study</h1>\n<p>Scene <code>" << escape(summary["scene"].get<std::string>()) << "</code>, "
    << summary["runs"].get<int>() << " runs per configuration, " << summary["time_budget"].get<double>()
    << " s each. " << escape(summary["statistics"].get<std::string>()) << ". relMSE: "
    << escape(summary["relmse_formula"].get<std::string>()) << ".</p>\n";
  if (summary.contains("reference") && summary["reference"].contains("trusted")) {
    const auto& r = summary["reference"];
    bool trusted = r["trusted"].get<bool>();
    h << "<p class=\"" << (trusted ? "ok" : "warn") << "\">Reference: " << escape(r["made_by"].get<std::string>())
      << "; its own relMSE " << number(r["relmse"]) << " is "
      << fmt::format("{:.0f}", 100.0 * r["relmse"].get<double>() / std::max(1e-300, r["smallest_compared_relmse"].get<double>()))
      << " % of the smallest error compared" << (trusted ? "." : ": above 10 %, the reference's noise may decide the ranking.")
      << "</p>\n";
  }
  h << "<h2>Error versus time</h2>\n<div class=\"grid\">" << svg_plot(summary, "relmse", "median relMSE (IQR band)")
    << svg_plot(summary, "rmse", "median RMSE (IQR band)") << "</div>\n";

  h << "<h2>At the last snapshot</h2>\n<table><tr><th class=\"l\">configuration</th><th>time [s]</th><th>spp</th>"
       "<th>relMSE median [IQR]</th><th>RMSE median [IQR]</th><th>MAE</th><th>relMSE clamped at p99.9</th>"
       "<th>median pixel error</th><th>share of worst 0.1 %</th><th>efficiency 1/(relMSE t)</th></tr>\n";
  for (const auto& [name, data] : summary["configs"].items()) {
    if (data["points"].empty()) continue;
    const auto& p = data["points"].back();
    h << "<tr><td class=\"l\">" << escape(name) << "</td><td>" << number(p["seconds"]) << "</td><td>" << number(p["spp"])
      << "</td><td>" << number(p["relmse"]) << " [" << number(p["relmse_q25"]) << ", " << number(p["relmse_q75"])
      << "]</td><td>" << number(p["rmse"]) << " [" << number(p["rmse_q25"]) << ", " << number(p["rmse_q75"])
      << "]</td><td>" << number(p["mae"]) << "</td><td>" << number(p["relmse_clamped"]) << "</td><td>"
      << number(p["relse_median"]) << "</td><td>" << fmt::format("{:.1f} %", 100.0 * p["worst_share"].get<double>())
      << "</td><td>" << number(data["efficiency"]) << "</td></tr>\n";
  }
  h << "</table>\n";

  h << "<h2>Ratios at equal time</h2>\n<p>Ratio of medians a / b with a bootstrap 95 % interval; a conclusion only "
       "where the interval excludes 1.</p>\n<table><tr><th class=\"l\">a</th><th class=\"l\">b</th><th class=\"l\">metric</th>"
       "<th>at [s]</th><th>ratio [95 %]</th><th class=\"l\">conclusion</th></tr>\n";
  for (const auto& r : summary["ratios"])
    h << "<tr><td class=\"l\">" << escape(r["a"].get<std::string>()) << "</td><td class=\"l\">"
      << escape(r["b"].get<std::string>()) << "</td><td class=\"l\">" << escape(r["metric"].get<std::string>())
      << "</td><td>" << number(r["seconds"]) << "</td><td>" << number(r["ratio"]) << " [" << number(r["low"]) << ", "
      << number(r["high"]) << "]</td><td class=\"l\">" << escape(r["conclusion"].get<std::string>()) << "</td></tr>\n";
  h << "</table>\n";

  // Images: each configuration at equal time, and its error map.
  std::vector<std::pair<std::string, std::string>> uris;  // name -> data URI, reference first
  uris.emplace_back("reference", png_data_uri(images.reference));
  for (const auto& [name, img] : images.configs) uris.emplace_back(name, png_data_uri(img));
  int w = images.reference.width, scale = w > 0 && w < 256 ? std::max(1, 256 / w) : 1;
  h << "<h2>Images at the last snapshot (first run) and their per-pixel error</h2>\n<p>Error maps: (I - R)^2 / (R^2 + "
       "0.01) on a log scale, dark blue 1e-4 to yellow 1 and above.</p>\n<div class=\"grid\">\n";
  h << "<div class=\"cell\"><img alt=\"reference\" width=\"" << w * scale << "\" src=\"" << uris[0].second
    << "\">reference</div>\n";
  for (size_t i = 0; i < images.configs.size(); ++i) {
    const auto& [name, img] = images.configs[i];
    h << "<div class=\"cell\"><img alt=\"" << escape(name) << "\" width=\"" << w * scale << "\" src=\"" << uris[i + 1].second
      << "\"><img alt=\"error of " << escape(name) << "\" width=\"" << w * scale << "\" src=\""
      << png_data_uri(error_map(img, images.reference)) << "\">" << escape(name) << "</div>\n";
  }
  h << "</div>\n";

  // The crop viewer: left and right images, a wipe slider and a zoom.
  h << "<h2>Compare</h2>\n<p><label>left <select id=\"left\"></select></label> <label>right <select id=\"right\">"
       "</select></label> <label>wipe <input id=\"wipe\" type=\"range\" min=\"0\" max=\"100\" value=\"50\"></label> "
       "<label>zoom <select id=\"zoom\"><option>1</option><option selected>2</option><option>4</option><option>8</option>"
       "</select></label></p>\n<div id=\"viewer\"><img id=\"leftimg\" alt=\"left\"><img id=\"rightimg\" alt=\"right\"></div>\n";
  h << "<script>\nconst images = {";
  for (size_t i = 0; i < uris.size(); ++i)
    h << (i ? "," : "") << "\n  " << nlohmann::json(uris[i].first).dump() << ": \"" << uris[i].second << "\"";
  h << "\n};\nconst width = " << w * scale << ";\n";
  h << R"(const left = document.getElementById('left'), right = document.getElementById('right');
const leftImg = document.getElementById('leftimg'), rightImg = document.getElementById('rightimg'), wipe = document.getElementById('wipe'), zoom = document.getElementById('zoom');
for (const name of Object.keys(images)) { left.add(new Option(name, name)); right.add(new Option(name, name)); }
left.value = 'reference';
right.selectedIndex = Math.min(1, right.options.length - 1);
function update() {
  const z = Number(zoom.value);
  leftImg.src = images[left.value];
  rightImg.src = images[right.value];
  for (const img of [leftImg, rightImg]) img.style.width = (width * z) + 'px';
  rightImg.style.clipPath = 'inset(0 0 0 ' + wipe.value + '%)';
}
for (const el of [left, right, wipe, zoom]) el.addEventListener('input', update);
update();
</script>
)";
  h << "</body></html>\n";
  write_text_atomically(path, h.str());
}

}  // namespace penumbra::cli
