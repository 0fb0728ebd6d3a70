// Images in and out, for plugins that read textures or environment maps and for the runtime's
// output. Reading and writing go through OpenImageIO; 8-bit output through an OpenColorIO view.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace penumbra {

struct ImageRgb {
  int width = 0, height = 0;
  std::vector<float> pixels;  // RGB interleaved, linear Rec.709, row 0 = top
};

/// Writes by extension: .exr (32-bit float, zip), .hdr (RGBE), .tif/.tiff (32-bit float), .pfm
/// (float; written by Penumbra, since OpenImageIO 2.4 only reads it), .png/.jpg/.jpeg (8-bit through
/// the OCIO display `view`; empty means the config's default view, "Standard" in the shipped
/// config). `metadata` becomes string attributes where the format has room for them (EXR header,
/// PNG text chunks; PFM and HDR drop them).
/// Throws Error naming the file for an unknown extension, a malformed image or a failed write.
void write_image(const std::string& path, const ImageRgb& img,
                 const std::vector<std::pair<std::string, std::string>>& metadata = {},
                 const std::string& view = "");

/// How a file stores its pixels, for readers that decode them (a colour encoding such as sRGB
/// applies to integer formats only).
struct ImageFileInfo {
  bool integer = false;  // 8- or 16-bit integers (PNG, JPEG, 8-bit TIFF ...), read as value / max
  int channels = 0;
};

/// Reads any format OpenImageIO knows as float RGB (grey images are replicated, extra channels
/// dropped). Values are returned as stored: 8-bit files are not linearised. `info`, if given,
/// receives how the file stores them.
ImageRgb read_image(const std::string& path, ImageFileInfo* info = nullptr);

}  // namespace penumbra
