#pragma once
// Exact ray casting of the parametric surfaces: every pixel is the mean of samples x
// samples sub-pixel rays on a regular grid (deterministic, against silhouette aliasing).
#include <vector>

#include "geometry/scene_geometry.h"
#include "render/camera.h"
#include "render/shading.h"

namespace radiosa {

struct RenderOptions {
    int width = 512;
    int height = 512;
    int samples = 3;  // per axis: samples^2 rays per pixel
};

// Linear radiosity image, RGB float, row-major from the top-left pixel.
struct Image {
    int width = 0, height = 0;
    std::vector<float> rgb;
    Rgb pixel(int x, int y) const {
        const size_t i = 3 * (static_cast<size_t>(y) * width + x);
        return Rgb(rgb[i], rgb[i + 1], rgb[i + 2]);
    }
};

Image render_image(const SceneGeometry& geometry, const NodeRadiosity& nodes,
                   const PinholeCamera& camera, const RenderOptions& options);

// Pixel area covered by one surface (fraction of sub-pixel rays whose nearest front-facing
// hit is on it, summed over pixels): checks silhouettes against closed forms.
double surface_coverage(const SceneGeometry& geometry, int surface, const PinholeCamera& camera,
                        const RenderOptions& options);

}  // namespace radiosa
