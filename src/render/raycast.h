#pragma once
// Exact ray casting of the parametric surfaces: every pixel is the mean of samples x
// samples sub-pixel rays on a regular grid (deterministic, against silhouette aliasing).
#include <vector>

#include "geometry/scene_geometry.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/shading.h"

namespace radiosa {

struct RenderOptions {
    int width = 512;
    int height = 512;
    int samples = 3;  // per axis: samples^2 rays per pixel
};

Image render_image(const SceneGeometry& geometry, const NodeRadiosity& nodes, const PinholeCamera& camera,
                   const RenderOptions& options);

// Pixel area covered by one surface (fraction of sub-pixel rays whose nearest front-facing
// hit is on it, summed over pixels): checks silhouettes against closed forms.
double surface_coverage(const SceneGeometry& geometry, int surface, const PinholeCamera& camera,
                        const RenderOptions& options);

}  // namespace radiosa
