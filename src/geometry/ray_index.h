#pragma once
// A bounding-volume hierarchy over a scene's surfaces for the nearest front-facing hit of a ray:
// Embree 3's BVH (the field's standard; Debian libembree-dev) with each surface as one user
// primitive, boxed by its exact extent along x, y and z (Surface::linear_range) and intersected
// by the surface's own exact double-precision intersect(): nothing is tessellated. Embree
// traverses in float, so the boxes are padded and the ray is first clipped to the scene's
// bounding sphere and taken relative to its centre (a camera a million units away loses no
// precision); which surface is hit, and where, is decided in double exactly as a loop over
// every surface would decide it, ties going to the lower surface index.
//
// Embree stays behind this interface (its API changes in version 4).
#include <memory>
#include <optional>
#include <vector>

#include "surfaces/surface.h"
#include "util/math.h"

namespace radiosa {

class RayIndex {
public:
    // The surfaces must outlive the index.
    explicit RayIndex(const std::vector<const Surface*>& surfaces);
    ~RayIndex();
    RayIndex(const RayIndex&) = delete;
    RayIndex& operator=(const RayIndex&) = delete;

    struct Found {
        int surface = -1;
        SurfaceHit hit;
    };
    // The nearest front-side hit with dist in (0, inf), as
    //   for k: surface k .intersect(ray, 0, best, HitSide::FrontOnly)
    // would find it. Safe to call from many threads at once.
    std::optional<Found> nearest_front(const Ray& ray) const;
    // found[i] = nearest_front(rays[i]) for i < count, a miss as found[i].surface = -1 (its hit
    // then unset), traced in packets through Embree's packet traversal: faster for coherent
    // rays, such as an image's neighbours. `packet`: 16 rays (where the processor has AVX-512,
    // whose lanes then test a ball eight rays at a time), 8, or 0 for the widest it has.
    void nearest_front(const Ray* rays, std::size_t count, Found* found, int packet = 0) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m;
};

}  // namespace radiosa
