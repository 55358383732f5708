#pragma once
// The rendered picture, where the renderer meets the encoders: linear radiosity, unclamped.
#include <cstddef>
#include <vector>

#include "util/math.h"

namespace radiosa {

// Linear radiosity image, RGB float, row-major from the top-left pixel.
struct Image {
    int width = 0, height = 0;
    std::vector<float> rgb;
    Rgb pixel(int x, int y) const {
        const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
        return Rgb(rgb[i], rgb[i + 1], rgb[i + 2]);
    }
};

}  // namespace radiosa
