#pragma once
// A convex polygon in a fixed-size buffer, and its cut by a half-space (Sutherland-Hodgman):
// the closed forms clip patches, shadows and cones with it.
#include <array>
#include <cstddef>

#include "util/math.h"

namespace radiosa {

template <std::size_t N>
struct PolygonBuffer {
    std::array<Vec3, N> v{};
    int n = 0;
};

// The part of p where nrm . (y - o) >= 0, in the same order (vertices beyond N are dropped).
template <std::size_t N>
PolygonBuffer<N> clip_half_space(const PolygonBuffer<N>& p, const Vec3& nrm, const Vec3& o) {
    PolygonBuffer<N> out;
    for (int k = 0; k < p.n; ++k) {
        const Vec3& a = p.v[k];
        const Vec3& b = p.v[(k + 1) % p.n];
        const double da = glm::dot(nrm, a - o), db = glm::dot(nrm, b - o);
        if (da >= 0.0 && out.n < static_cast<int>(N)) out.v[out.n++] = a;
        if ((da >= 0.0) != (db >= 0.0) && out.n < static_cast<int>(N))
            out.v[out.n++] = a + (b - a) * (da / (da - db));
    }
    return out;
}

}  // namespace radiosa
