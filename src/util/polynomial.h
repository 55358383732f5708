#pragma once
// Real roots of a polynomial of low degree on an interval, by isolating them between the roots of
// its derivative (where it is monotone) and bisecting each sign change: robust where the closed
// forms for cubics and quartics lose digits, and exact in its bookkeeping (every simple root in the
// interval is found, in increasing order).

namespace radiosa {

// coeffs[k] multiplies x^k, k < count (degree count - 1, at most kMaxPolynomialDegree: more
// coefficients find no roots). The roots go to roots[] (room for the degree's count; nothing is
// allocated) and their number is returned. Roots of even multiplicity (a tangent ray) are found
// only where rounding gives them a sign change.
inline constexpr int kMaxPolynomialDegree = 8;
int real_roots(const double* coeffs, int count, double lo, double hi, double* roots);

}  // namespace radiosa
