#pragma once
// Part of the encode plugin: palette outputs through libav.
#include <memory>

#include "encode/palette.h"

namespace radiosa::media {

// Indexed PNG (one frame) and GIF (all frames) through libav's png and gif encoders
// (palette_av.cpp); a build with -DRADIOSA_VIDEO=OFF has none and these throw Error.
void write_indexed_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& index,
                       const std::vector<Colour8>& palette);
class GifWriter {
public:
    GifWriter(const std::string& path, int width, int height, double fps,
              const std::vector<Colour8>& palette);
    ~GifWriter();
    void add_frame(const std::vector<std::uint8_t>& index);
    void finish();

private:
    struct Impl;
    std::unique_ptr<Impl> m;
};

}  // namespace radiosa::media
