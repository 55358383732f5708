#pragma once
// Gauss-Legendre quadrature rules on [-1, 1].
#include <vector>

namespace radiosa {

struct GaussRule {
    std::vector<double> x;  // nodes, ascending
    std::vector<double> w;  // weights, summing to 2
};

// The n-point rule (exact for polynomials of degree 2n - 1). Nodes come from Newton's
// iteration on the three-term Legendre recurrence, accurate to ~1 ulp for n up to a few
// hundred; radiosa uses n <= 64.
GaussRule gauss_legendre(int n);

}  // namespace radiosa
