#include "util/polynomial.h"

#include <algorithm>
#include <cmath>

namespace radiosa {

namespace {

double eval(const double* c, int n, double x) {
    double v = 0.0;
    for (int k = n; k-- > 0;) v = v * x + c[k];
    return v;
}

// The root of c in [a, b], where c is monotone and c(a), c(b) differ in sign: Newton steps, with
// a bisection whenever a step would leave the bracket or shrink it too slowly; it stops at
// adjacent doubles or a step below 1e-15 of the bracket's scale.
double root_between(const double* c, int n, double a, double b, double fa) {
    const double scale = std::max(std::abs(a), std::abs(b)) + (b - a);
    double x = 0.5 * (a + b), width = b - a;
    for (int i = 0; i < 200; ++i) {
        double f = 0.0, df = 0.0;
        for (int k = n; k-- > 0;) {
            df = df * x + f;
            f = f * x + c[k];
        }
        if (f == 0.0) return x;
        if ((f < 0.0) == (fa < 0.0))
            a = x;
        else
            b = x;
        double next = df != 0.0 ? x - f / df : a - 1.0;
        if (!(next > a && next < b) || std::abs(next - x) > 0.5 * width) next = 0.5 * (a + b);
        width = std::abs(next - x);
        if (width <= 1e-15 * scale || next <= a || next >= b) return next;
        x = next;
    }
    return x;
}

}  // namespace

int real_roots(const double* c, int count, double lo, double hi, double* roots) {
    if (count > kMaxPolynomialDegree + 1) return 0;
    int n = count;  // leading zeros left out
    while (n > 1 && c[n - 1] == 0.0) --n;
    int found = 0;
    if (n <= 1 || !(lo < hi)) return found;
    if (n == 2) {
        const double x = -c[0] / c[1];
        if (x >= lo && x <= hi) roots[found++] = x;
        return found;
    }
    // The derivative's roots split [lo, hi] into pieces on which c is monotone.
    double d[kMaxPolynomialDegree], inner[kMaxPolynomialDegree], knots[kMaxPolynomialDegree + 2];
    for (int k = 1; k < n; ++k) d[k - 1] = static_cast<double>(k) * c[k];
    int nk = 0;
    knots[nk++] = lo;
    const int ni = real_roots(d, n - 1, lo, hi, inner);
    for (int q = 0; q < ni; ++q)
        if (inner[q] > knots[nk - 1]) knots[nk++] = inner[q];
    if (hi > knots[nk - 1]) knots[nk++] = hi;
    for (int i = 0; i + 1 < nk; ++i) {
        const double a = knots[i], b = knots[i + 1];
        const double fa = eval(c, n, a), fb = eval(c, n, b);
        double x;
        if (fa == 0.0)
            x = a;
        else if (fb == 0.0 || (fa < 0.0) == (fb < 0.0))
            continue;  // b's root (if any) is found on the next piece
        else
            x = root_between(c, n, a, b, fa);
        if (found == 0 || x > roots[found - 1]) roots[found++] = x;
    }
    if (eval(c, n, hi) == 0.0 && (found == 0 || hi > roots[found - 1])) roots[found++] = hi;
    return found;
}

}  // namespace radiosa
