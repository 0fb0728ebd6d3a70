// The one way Penumbra opens an image file for reading, shared by every reader (environment maps,
// textures, normal maps, checkpoints and split-render parts): the file must be a regular file, its
// header must describe a size Penumbra is willing to hold, and OpenEXR files are parsed by
// OpenEXR's core library, which checks every size it reads from the header against the file.
#pragma once

#include <OpenImageIO/imageio.h>

#include <memory>
#include <string>
#include <vector>

namespace penumbra {

/// Opens `path` for reading. Throws Error naming the file when it is not a regular file, when
/// OpenImageIO cannot read its header, or when the header claims more than 2^28 pixels, more than
/// 64 channels or a volume (depth > 1) (a damaged or hostile header must not make the caller allocate).
std::unique_ptr<OIIO::ImageInput> open_image_input(const std::string& path);

/// Reads channels [0, channels) of the first subimage as floats, row after row (pixel-interleaved,
/// top row first). The result grows with the rows actually decoded, in bands of at least 64 rows
/// (whole tile rows for a tiled file), so a header that claims a huge image in a small or damaged
/// file fails at its first bad band instead of making the caller allocate the claimed size first.
/// Throws Error naming `path` with OpenImageIO's complaint.
std::vector<float> read_image_channels(OIIO::ImageInput& in, const std::string& path, int channels);

}  // namespace penumbra
