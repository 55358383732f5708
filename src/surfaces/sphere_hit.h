#pragma once
// A whole sphere's ray test, inline: SphereSurface (sphere.cpp) and the BVH's test of a
// candidate ball (geometry/ray_index.cpp) share it, so both give the same distance bit for bit.
// geometry/ball_hits_avx512.cpp repeats it in AVX-512 lanes, line by line: change both.
#include <cmath>
#include <limits>
#include <utility>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "util/math.h"

namespace radiosa {

// The roots of |o + t d - c|^2 = R^2 in increasing order, solved in the cancellation-free form;
// false when the line misses.
inline bool sphere_roots(const Ray& ray, const Vec3& center, double radius, double roots[2]) {
    const Vec3 oc = ray.origin - center;
    const double a = glm::dot(ray.dir, ray.dir);
    const double b = glm::dot(oc, ray.dir);
    // Discriminant via the perpendicular distance (Hearn & Baker / Ray Tracing Gems ch. 7),
    // first: most lines that reach a ball's bounding box still miss the ball.
    const Vec3 perp = oc - (b / a) * ray.dir;
    const double disc = a * (radius * radius - glm::dot(perp, perp));
    if (disc < 0.0) return false;
    // c = |oc|^2 - R^2 computed as (|oc| - R)(|oc| + R) keeps precision near the surface.
    const double loc = glm::length(oc);
    const double c = (loc - radius) * (loc + radius);
    const double q = -(b + std::copysign(std::sqrt(disc), b));
    roots[0] = c / q;
    roots[1] = q / a;
    if (q == 0.0) roots[0] = roots[1] = 0.0;
    if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
    return true;
}

// The first root in (t_min, t_max) where the ray arrives on the front side (orientation +1:
// the outside), or infinity.
inline double sphere_front_distance(const Ray& ray, const Vec3& center, double radius, double orientation,
                                    double t_min, double t_max) {
    double roots[2];
    if (sphere_roots(ray, center, radius, roots))
        for (double dist : roots)
            if (dist > t_min && dist < t_max && orientation * glm::dot(ray.at(dist) - center, ray.dir) < 0.0)
                return dist;
    return std::numeric_limits<double>::infinity();
}

#if defined(__x86_64__)
// sphere_front_distance(*rays[i], ..., 0, t_max[i]) for i < 4 in four AVX lanes: the same
// operations in the same order (no FMA: each product and sum rounds as in the scalar test), so
// the same bits. Call only where the processor has AVX.
__attribute__((target("avx"))) inline __m256d dot4(__m256d x0, __m256d y0, __m256d z0, __m256d x1, __m256d y1,
                                                   __m256d z1) {
    return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x0, x1), _mm256_mul_pd(y0, y1)), _mm256_mul_pd(z0, z1));
}
__attribute__((target("avx"))) inline __m256d blend4(__m256d mask, __m256d yes, __m256d no) {
    return _mm256_or_pd(_mm256_and_pd(mask, yes), _mm256_andnot_pd(mask, no));
}
__attribute__((target("avx"))) inline void sphere_front_distance4(const Ray* const rays[4],
                                                                  const Vec3& center, double radius,
                                                                  double orientation, const double t_max[4],
                                                                  double out[4]) {
    const __m256d dx = _mm256_set_pd(rays[3]->dir.x, rays[2]->dir.x, rays[1]->dir.x, rays[0]->dir.x);
    const __m256d dy = _mm256_set_pd(rays[3]->dir.y, rays[2]->dir.y, rays[1]->dir.y, rays[0]->dir.y);
    const __m256d dz = _mm256_set_pd(rays[3]->dir.z, rays[2]->dir.z, rays[1]->dir.z, rays[0]->dir.z);
    const __m256d ox =
        _mm256_set_pd(rays[3]->origin.x, rays[2]->origin.x, rays[1]->origin.x, rays[0]->origin.x);
    const __m256d oy =
        _mm256_set_pd(rays[3]->origin.y, rays[2]->origin.y, rays[1]->origin.y, rays[0]->origin.y);
    const __m256d oz =
        _mm256_set_pd(rays[3]->origin.z, rays[2]->origin.z, rays[1]->origin.z, rays[0]->origin.z);
    const __m256d cx = _mm256_set1_pd(center.x), cy = _mm256_set1_pd(center.y), cz = _mm256_set1_pd(center.z);
    const __m256d ocx = _mm256_sub_pd(ox, cx), ocy = _mm256_sub_pd(oy, cy), ocz = _mm256_sub_pd(oz, cz);
    const __m256d qa = dot4(dx, dy, dz, dx, dy, dz);
    const __m256d qb = dot4(ocx, ocy, ocz, dx, dy, dz);
    const __m256d k = _mm256_div_pd(qb, qa);
    const __m256d px = _mm256_sub_pd(ocx, _mm256_mul_pd(k, dx)),
                  py = _mm256_sub_pd(ocy, _mm256_mul_pd(k, dy)),
                  pz = _mm256_sub_pd(ocz, _mm256_mul_pd(k, dz));
    const __m256d R = _mm256_set1_pd(radius), zero = _mm256_setzero_pd();
    const __m256d disc = _mm256_mul_pd(qa, _mm256_sub_pd(_mm256_mul_pd(R, R), dot4(px, py, pz, px, py, pz)));
    const __m256d inf = _mm256_set1_pd(std::numeric_limits<double>::infinity());
    const __m256d miss = _mm256_cmp_pd(disc, zero, _CMP_LT_OQ);
    if (_mm256_movemask_pd(miss) == 15) {
        _mm256_storeu_pd(out, inf);
        return;
    }
    const __m256d loc = _mm256_sqrt_pd(dot4(ocx, ocy, ocz, ocx, ocy, ocz));
    const __m256d c = _mm256_mul_pd(_mm256_sub_pd(loc, R), _mm256_add_pd(loc, R));
    const __m256d sign = _mm256_set1_pd(-0.0);
    const __m256d root = _mm256_or_pd(_mm256_andnot_pd(sign, _mm256_sqrt_pd(disc)), _mm256_and_pd(sign, qb));
    const __m256d q = _mm256_xor_pd(sign, _mm256_add_pd(qb, root));
    const __m256d zero_q = _mm256_cmp_pd(q, zero, _CMP_EQ_OQ);
    const __m256d r0 = _mm256_andnot_pd(zero_q, _mm256_div_pd(c, q)),
                  r1 = _mm256_andnot_pd(zero_q, _mm256_div_pd(q, qa));
    const __m256d swap = _mm256_cmp_pd(r0, r1, _CMP_GT_OQ);
    const __m256d lo = blend4(swap, r1, r0), hi = blend4(swap, r0, r1);
    const __m256d tmax = _mm256_loadu_pd(t_max), O = _mm256_set1_pd(orientation);
    __m256d take[2];
    const __m256d t[2] = {lo, hi};
    for (int j = 0; j < 2; ++j) {
        const __m256d hx = _mm256_sub_pd(_mm256_add_pd(ox, _mm256_mul_pd(t[j], dx)), cx),
                      hy = _mm256_sub_pd(_mm256_add_pd(oy, _mm256_mul_pd(t[j], dy)), cy),
                      hz = _mm256_sub_pd(_mm256_add_pd(oz, _mm256_mul_pd(t[j], dz)), cz);
        const __m256d f = _mm256_cmp_pd(_mm256_mul_pd(O, dot4(hx, hy, hz, dx, dy, dz)), zero, _CMP_LT_OQ);
        const __m256d in =
            _mm256_and_pd(_mm256_cmp_pd(t[j], zero, _CMP_GT_OQ), _mm256_cmp_pd(t[j], tmax, _CMP_LT_OQ));
        take[j] = _mm256_andnot_pd(miss, _mm256_and_pd(f, in));
    }
    _mm256_storeu_pd(out, blend4(take[0], lo, blend4(take[1], hi, inf)));
}

#endif

}  // namespace radiosa
