#include "util/angles.h"

#include <sleef.h>

#include <algorithm>

#include "util/angles_avx2.h"

namespace radiosa {

void atan2_acos(std::size_t n, const double* y, const double* x, const double* z, double* phi,
                double* theta) {
    static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    if (avx2)
        atan2_acos_avx2(n, y, x, z, phi, theta);
    else
        atan2_acos_sse2(n, y, x, z, phi, theta);
}

void atan2_acos_sse2(std::size_t n, const double* y, const double* x, const double* z, double* phi,
                     double* theta) {
    const __m128d lo = _mm_set1_pd(-1.0), hi = _mm_set1_pd(1.0);
    for (std::size_t i = 0; i < n; i += 2) {
        // A last odd value takes a lane of its own, the other lane a harmless 0.
        alignas(16) double ys[2] = {y[i], 0.0}, xs[2] = {x[i], 1.0}, zs[2] = {z[i], 0.0}, p[2], t[2];
        if (i + 1 < n) ys[1] = y[i + 1], xs[1] = x[i + 1], zs[1] = z[i + 1];
        _mm_store_pd(p, Sleef_atan2d2_u35sse2(_mm_load_pd(ys), _mm_load_pd(xs)));
        _mm_store_pd(t, Sleef_acosd2_u35sse2(_mm_min_pd(hi, _mm_max_pd(lo, _mm_load_pd(zs)))));
        for (std::size_t k = 0; k < std::min<std::size_t>(2, n - i); ++k) {
            phi[i + k] = p[k];
            theta[i + k] = t[k];
        }
    }
}

}  // namespace radiosa
