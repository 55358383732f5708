#include "render/raycast.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>

namespace radiosa {

namespace {
// Sub-pixel ray (sx, sy) of pixel (x, y): the centres of an n x n grid of cells.
Ray sample_ray(const PinholeCamera& cam, int x, int y, int sx, int sy, int n) {
    return cam.ray(x + (sx + 0.5) / n, y + (sy + 0.5) / n);
}
// Calls f(hit or nullptr) for every sub-pixel ray of pixel (x, y).
template <class F>
void for_each_sample(const SceneGeometry& geo, const PinholeCamera& cam, int samples, int x, int y, F&& f) {
    for (int sy = 0; sy < samples; ++sy)
        for (int sx = 0; sx < samples; ++sx) {
            const auto hit = geo.intersect_front(sample_ray(cam, x, y, sx, sy, samples));
            f(hit ? &*hit : nullptr);
        }
}
}  // namespace

Image render_image(const SceneGeometry& geo, const NodeRadiosity& nodes, const PinholeCamera& cam,
                   const RenderOptions& opt) {
    Image img;
    img.width = opt.width;
    img.height = opt.height;
    img.rgb.assign(static_cast<size_t>(opt.width) * opt.height * 3, 0.0f);
    const int n = opt.samples;
    const double inv = 1.0 / (n * n);
    // A row's rays are traced together, a few pixels at a time (in packets through the BVH:
    // neighbours share its nodes; a few, so that rays and hits stay in the first-level cache),
    // a pixel's n x n samples in order. Rows are independent and each pixel's samples are
    // summed in a fixed order, so the image is the same whatever the number of threads.
    const int per_chunk = std::max(1, PinholeCamera::kRowRays / (n * n));  // pixels traced together
    tbb::parallel_for(tbb::blocked_range<int>(0, opt.height), [&](const tbb::blocked_range<int>& rows) {
        std::vector<Ray> rays(static_cast<std::size_t>(per_chunk) * n * n);
        std::vector<std::optional<Hit>> hits(rays.size());
        for (int y = rows.begin(); y != rows.end(); ++y)
            for (int x0 = 0; x0 < opt.width; x0 += per_chunk) {
                const int x1 = std::min(opt.width, x0 + per_chunk);
                if (n * n <= PinholeCamera::kRowRays) {
                    cam.row_rays(y, x0, x1, n, rays.data());
                } else {
                    std::size_t r = 0;
                    for (int sy = 0; sy < n; ++sy)
                        for (int sx = 0; sx < n; ++sx) rays[r++] = sample_ray(cam, x0, y, sx, sy, n);
                }
                geo.intersect_front(rays.data(), static_cast<std::size_t>(x1 - x0) * n * n, hits.data());
                std::size_t r = 0;
                for (int x = x0; x < x1; ++x) {
                    Rgb sum(0.0);
                    for (int k = 0; k < n * n; ++k, ++r)
                        if (hits[r]) sum += nodes.shade(*hits[r]);  // background (no hit) is black
                    const size_t i = 3 * (static_cast<size_t>(y) * opt.width + x);
                    for (int c = 0; c < 3; ++c) img.rgb[i + c] = static_cast<float>(sum[c] * inv);
                }
            }
    });
    return img;
}

double surface_coverage(const SceneGeometry& geo, int surface, const PinholeCamera& cam,
                        const RenderOptions& opt) {
    const double inv = 1.0 / (opt.samples * opt.samples);
    return tbb::parallel_reduce(
        tbb::blocked_range<int>(0, opt.height), 0.0,
        [&](const tbb::blocked_range<int>& rows, double acc) {
            for (int y = rows.begin(); y != rows.end(); ++y)
                for (int x = 0; x < opt.width; ++x)
                    for_each_sample(geo, cam, opt.samples, x, y, [&](const Hit* h) {
                        if (h && h->surface == surface) acc += inv;
                    });
            return acc;
        },
        [](double a, double b) { return a + b; });
}

}  // namespace radiosa
