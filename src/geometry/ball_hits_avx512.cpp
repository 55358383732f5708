#include "geometry/ball_hits_avx512.h"

#include <immintrin.h>

namespace radiosa {

namespace {
__m512d dot8(__m512d x0, __m512d y0, __m512d z0, __m512d x1, __m512d y1, __m512d z1) {
    return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(x0, x1), _mm512_mul_pd(y0, y1)), _mm512_mul_pd(z0, z1));
}
}  // namespace

// sphere_hit.h's sphere_roots and sphere_front_distance, line by line.
void sphere_front_distance8(const double* const ray[6], const double center[3], double radius,
                            double orientation, const double t_max[8], double out[8]) {
    const __m512d dx = _mm512_loadu_pd(ray[0]), dy = _mm512_loadu_pd(ray[1]), dz = _mm512_loadu_pd(ray[2]);
    const __m512d ox = _mm512_loadu_pd(ray[3]), oy = _mm512_loadu_pd(ray[4]), oz = _mm512_loadu_pd(ray[5]);
    const __m512d cx = _mm512_set1_pd(center[0]), cy = _mm512_set1_pd(center[1]),
                  cz = _mm512_set1_pd(center[2]);
    const __m512d ocx = _mm512_sub_pd(ox, cx), ocy = _mm512_sub_pd(oy, cy), ocz = _mm512_sub_pd(oz, cz);
    const __m512d qa = dot8(dx, dy, dz, dx, dy, dz);
    const __m512d qb = dot8(ocx, ocy, ocz, dx, dy, dz);
    const __m512d k = _mm512_div_pd(qb, qa);
    const __m512d px = _mm512_sub_pd(ocx, _mm512_mul_pd(k, dx)),
                  py = _mm512_sub_pd(ocy, _mm512_mul_pd(k, dy)),
                  pz = _mm512_sub_pd(ocz, _mm512_mul_pd(k, dz));
    const __m512d R = _mm512_set1_pd(radius), zero = _mm512_setzero_pd();
    const __m512d disc = _mm512_mul_pd(qa, _mm512_sub_pd(_mm512_mul_pd(R, R), dot8(px, py, pz, px, py, pz)));
    const __m512d inf = _mm512_set1_pd(__builtin_inf());
    const __mmask8 hit = static_cast<__mmask8>(~_mm512_cmp_pd_mask(disc, zero, _CMP_LT_OQ));
    if (hit == 0) {
        _mm512_storeu_pd(out, inf);
        return;
    }
    const __m512d loc = _mm512_sqrt_pd(dot8(ocx, ocy, ocz, ocx, ocy, ocz));
    const __m512d c = _mm512_mul_pd(_mm512_sub_pd(loc, R), _mm512_add_pd(loc, R));
    // -(b + copysign(sqrt(disc), b)) by the sign bit, as the scalar test computes it.
    const __m512i sign = _mm512_set1_epi64(static_cast<long long>(0x8000000000000000ULL));
    const __m512d root = _mm512_castsi512_pd(
        _mm512_or_si512(_mm512_andnot_si512(sign, _mm512_castpd_si512(_mm512_sqrt_pd(disc))),
                        _mm512_and_si512(sign, _mm512_castpd_si512(qb))));
    const __m512d q =
        _mm512_castsi512_pd(_mm512_xor_si512(sign, _mm512_castpd_si512(_mm512_add_pd(qb, root))));
    const __mmask8 nonzero_q = static_cast<__mmask8>(~_mm512_cmp_pd_mask(q, zero, _CMP_EQ_OQ));
    const __m512d r0 = _mm512_maskz_mov_pd(nonzero_q, _mm512_div_pd(c, q)),
                  r1 = _mm512_maskz_mov_pd(nonzero_q, _mm512_div_pd(q, qa));
    const __mmask8 swap = _mm512_cmp_pd_mask(r0, r1, _CMP_GT_OQ);
    const __m512d lo = _mm512_mask_blend_pd(swap, r0, r1), hi = _mm512_mask_blend_pd(swap, r1, r0);
    const __m512d tmax = _mm512_loadu_pd(t_max), O = _mm512_set1_pd(orientation);
    __mmask8 take[2];
    const __m512d t[2] = {lo, hi};
    for (int j = 0; j < 2; ++j) {
        const __m512d hx = _mm512_sub_pd(_mm512_add_pd(ox, _mm512_mul_pd(t[j], dx)), cx),
                      hy = _mm512_sub_pd(_mm512_add_pd(oy, _mm512_mul_pd(t[j], dy)), cy),
                      hz = _mm512_sub_pd(_mm512_add_pd(oz, _mm512_mul_pd(t[j], dz)), cz);
        const __mmask8 front =
            _mm512_cmp_pd_mask(_mm512_mul_pd(O, dot8(hx, hy, hz, dx, dy, dz)), zero, _CMP_LT_OQ);
        const __mmask8 in = static_cast<__mmask8>(_mm512_cmp_pd_mask(t[j], zero, _CMP_GT_OQ) &
                                                  _mm512_cmp_pd_mask(t[j], tmax, _CMP_LT_OQ));
        take[j] = static_cast<__mmask8>(hit & front & in);
    }
    _mm512_storeu_pd(out, _mm512_mask_blend_pd(take[0], _mm512_mask_blend_pd(take[1], inf, hi), lo));
}

}  // namespace radiosa
