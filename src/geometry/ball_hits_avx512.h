#pragma once
// A whole sphere's ray test (surfaces/sphere_hit.h) for eight rays in AVX-512 lanes, built in a
// file of its own for AVX-512F without FMA contraction (CMakeLists.txt): the same operations in
// the same order as sphere_front_distance, each rounded on its own, so the same bits. Call only
// where the processor has AVX-512F. Plain doubles only, so that no inline template is built for
// AVX-512 and picked by the linker for code that runs on other processors.

namespace radiosa {

// out[i] = sphere_front_distance(ray i, center, radius, orientation, 0, t_max[i]) for i < 8,
// ray i's direction (ray[0][i], ray[1][i], ray[2][i]) and origin (ray[3][i], ray[4][i], ray[5][i]).
void sphere_front_distance8(const double* const ray[6], const double center[3], double radius,
                            double orientation, const double t_max[8], double out[8]);

}  // namespace radiosa
