#include "util/polynomial.h"

#include <algorithm>
#include <cmath>

namespace radiosa {

namespace {

double eval(const std::vector<double>& c, double x) {
    double v = 0.0;
    for (size_t k = c.size(); k-- > 0;) v = v * x + c[k];
    return v;
}

// The root of c in [a, b], where c is monotone and c(a), c(b) differ in sign: Newton steps, with
// a bisection whenever a step would leave the bracket or shrink it too slowly; it stops at
// adjacent doubles or a step below 1e-15 of the bracket's scale.
double root_between(const std::vector<double>& c, double a, double b, double fa) {
    const double scale = std::max(std::abs(a), std::abs(b)) + (b - a);
    double x = 0.5 * (a + b), width = b - a;
    for (int i = 0; i < 200; ++i) {
        double f = 0.0, df = 0.0;
        for (size_t k = c.size(); k-- > 0;) {
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

std::vector<double> real_roots(const std::vector<double>& coeffs, double lo, double hi) {
    std::vector<double> c = coeffs;
    while (c.size() > 1 && c.back() == 0.0) c.pop_back();
    std::vector<double> roots;
    if (c.size() <= 1 || !(lo < hi)) return roots;
    if (c.size() == 2) {
        const double x = -c[0] / c[1];
        if (x >= lo && x <= hi) roots.push_back(x);
        return roots;
    }
    // The derivative's roots split [lo, hi] into pieces on which c is monotone.
    std::vector<double> d(c.size() - 1);
    for (size_t k = 1; k < c.size(); ++k) d[k - 1] = static_cast<double>(k) * c[k];
    std::vector<double> knots = {lo};
    for (double x : real_roots(d, lo, hi))
        if (x > knots.back()) knots.push_back(x);
    if (hi > knots.back()) knots.push_back(hi);
    for (size_t i = 0; i + 1 < knots.size(); ++i) {
        const double a = knots[i], b = knots[i + 1];
        const double fa = eval(c, a), fb = eval(c, b);
        double x;
        if (fa == 0.0)
            x = a;
        else if (fb == 0.0 || (fa < 0.0) == (fb < 0.0))
            continue;  // b's root (if any) is found on the next piece
        else
            x = root_between(c, a, b, fa);
        if (roots.empty() || x > roots.back()) roots.push_back(x);
    }
    if (eval(c, hi) == 0.0 && (roots.empty() || hi > roots.back())) roots.push_back(hi);
    return roots;
}

}  // namespace radiosa
