#include "util/angles_avx2.h"

#include <sleef.h>

namespace radiosa {

void atan2_acos_avx2(std::size_t n, const double* y, const double* x, const double* z, double* phi,
                     double* theta) {
    const __m256d lo = _mm256_set1_pd(-1.0), hi = _mm256_set1_pd(1.0);
    for (std::size_t i = 0; i < n; i += 4) {
        // The last values take lanes of their own, the others harmless ones (plain loops: no
        // library template is instantiated with AVX here).
        alignas(32) double ys[4] = {0.0, 0.0, 0.0, 0.0}, xs[4] = {1.0, 1.0, 1.0, 1.0},
                           zs[4] = {0.0, 0.0, 0.0, 0.0};
        alignas(32) double p[4], t[4];
        const std::size_t m = n - i < 4 ? n - i : 4;
        for (std::size_t k = 0; k < m; ++k) ys[k] = y[i + k], xs[k] = x[i + k], zs[k] = z[i + k];
        _mm256_store_pd(p, Sleef_atan2d4_u35avx2(_mm256_load_pd(ys), _mm256_load_pd(xs)));
        _mm256_store_pd(t, Sleef_acosd4_u35avx2(_mm256_min_pd(hi, _mm256_max_pd(lo, _mm256_load_pd(zs)))));
        for (std::size_t k = 0; k < m; ++k) phi[i + k] = p[k], theta[i + k] = t[k];
    }
}

}  // namespace radiosa
