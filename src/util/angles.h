#pragma once
// Many angles at once: phi[i] = atan2(y[i], x[i]) and theta[i] = acos(z[i]) (z clamped to
// [-1, 1]) for i < n, in SIMD lanes by SLEEF (Debian libsleef-dev), each within 3.5 ulp of the
// exact value (its "u35" functions: 1.5e-15 radians at most, a millionth of a pixel of any
// image). Four lanes (AVX2 with FMA) where the processor has them, else two (SSE2); a value
// does not depend on its lane or on n, so on one machine the same input always gives the same
// bits. glibc's atan2 and acos, one value at a time, take about ten times as long.
#include <cstddef>

namespace radiosa {

void atan2_acos(std::size_t n, const double* y, const double* x, const double* z, double* phi, double* theta);
// The same in two lanes (SSE2, every x86-64 processor): what atan2_acos does without AVX2.
void atan2_acos_sse2(std::size_t n, const double* y, const double* x, const double* z, double* phi,
                     double* theta);

}  // namespace radiosa
