#pragma once
// atan2_acos (util/angles.h) in four lanes: call only where the processor has AVX2 and FMA.
// Its file is compiled with -mavx2 -mfma and holds nothing else, so that no AVX instruction
// reaches code that runs on other processors.
#include <cstddef>

namespace radiosa {

void atan2_acos_avx2(std::size_t n, const double* y, const double* x, const double* z, double* phi,
                     double* theta);

}  // namespace radiosa
