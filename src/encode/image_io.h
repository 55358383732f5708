#pragma once
// Part of the encode plugin (libradiosa_encode.so): stills through OpenImageIO. The rest of
// radiosa calls them through encode/encode.h. The format follows the file extension:
//   .exr        linear radiosity, 32-bit float, unscaled by exposure
//   .png/.jpg/.tif/...  8-bit sRGB: value = radiosity * 2^exposure, clamped to [0, 1],
//               then the sRGB transfer curve. Radiosity 1.0 is display white at exposure 0.
#include <string>

#include "render/image.h"

namespace radiosa::media {

void write_image(const Image& image, const std::string& path, double exposure_stops);

// Throws Error, before any work is done, when `path` cannot be written: its directory is
// missing or read-only, or no image writer handles its extension.
void check_image_output(const std::string& path);

// Reads an image back as linear-ish float RGB exactly as stored (for tests and checks).
Image read_image(const std::string& path);

}  // namespace radiosa::media
