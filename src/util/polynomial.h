#pragma once
// Real roots of a polynomial of low degree on an interval, by isolating them between the roots of
// its derivative (where it is monotone) and bisecting each sign change: robust where the closed
// forms for cubics and quartics lose digits, and exact in its bookkeeping (every simple root in the
// interval is found, in increasing order).
#include <vector>

namespace radiosa {

// coeffs[k] multiplies x^k (degree = coeffs.size() - 1, at most 8). Roots of even multiplicity
// (a tangent ray) are found only where rounding gives them a sign change.
std::vector<double> real_roots(const std::vector<double>& coeffs, double lo, double hi);

}  // namespace radiosa
