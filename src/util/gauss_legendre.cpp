#include "util/gauss_legendre.h"

#include <cmath>
#include <stdexcept>

#include "util/math.h"

namespace radiosa {

namespace {
// P_n(x) and its derivative, by the recurrence k P_k = (2k-1) x P_{k-1} - (k-1) P_{k-2}.
void legendre(int n, double x, double* p, double* dp) {
    double p0 = 1.0, p1 = x;
    for (int k = 2; k <= n; ++k) {
        const double pk = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = pk;
    }
    *p = p1;
    *dp = n * (x * p1 - p0) / (x * x - 1.0);
}
}  // namespace

GaussRule gauss_legendre(int n) {
    if (n < 1) throw std::invalid_argument("gauss_legendre: n must be >= 1");
    GaussRule rule;
    rule.x.resize(n);
    rule.w.resize(n);
    for (int i = 0; i < (n + 1) / 2; ++i) {
        // Tricomi's initial guess for the i-th largest root.
        double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
        double p = 0.0, dp = 1.0;
        for (int iter = 0; iter < 100; ++iter) {
            legendre(n, x, &p, &dp);
            const double dx = p / dp;
            x -= dx;
            if (std::abs(dx) < 1e-16) break;
        }
        legendre(n, x, &p, &dp);
        const double w = 2.0 / ((1.0 - x * x) * dp * dp);
        rule.x[i] = -x;
        rule.x[n - 1 - i] = x;
        rule.w[i] = w;
        rule.w[n - 1 - i] = w;
    }
    return rule;
}

}  // namespace radiosa
