// Closure, reciprocity and the estimates' figures of a computed matrix (check_form_factors).
#include <algorithm>
#include <cmath>

#include "formfactor/form_factor.h"

namespace radiosa {

FormFactorChecks check_form_factors(const FormFactors& ff) {
    FormFactorChecks c;
    const int n = ff.F.n;
    for (int i = 0; i < n; ++i) {
        double row = 0.0;
        for (int j = 0; j < n; ++j) {
            row += ff.F(i, j);
            c.min_entry = std::min(c.min_entry, ff.F(i, j));
            if (j > i) {
                const double a = ff.area[i] * ff.F(i, j), b = ff.area[j] * ff.F(j, i);
                const double m = std::max(std::abs(a), std::abs(b));
                if (m > 0.0) c.reciprocity_max_error = std::max(c.reciprocity_max_error, std::abs(a - b) / m);
                c.reciprocity_abs_error =
                    std::max(c.reciprocity_abs_error, std::abs(a - b) / std::min(ff.area[i], ff.area[j]));
            }
        }
        if (!ff.error.empty()) {
            double row_est = 0.0;
            for (int j = 0; j < n; ++j) {
                const double e = ff.error[static_cast<std::size_t>(i) * n + j];
                row_est += e;
                c.max_error_estimate = std::max(c.max_error_estimate, e);
                if (ff.options.method == FormFactorMethod::Adaptive) {
                    const double target =
                        ff.options.tolerance * std::min(ff.area[i], ff.area[j]) / ff.area[i];
                    const double ratio = e / target;
                    if (ratio > 1.0 + 1e-9) {
                        ++c.entries_over_tolerance;
                        if (ratio > c.worst_miss_ratio) {
                            c.worst_miss_ratio = ratio;
                            c.worst_miss_estimate = e;
                            c.worst_miss_i = i;
                            c.worst_miss_j = j;
                        }
                    }
                }
                if (j > i) {
                    const double est =
                        ff.area[i] * e + ff.area[j] * ff.error[static_cast<std::size_t>(j) * n + i];
                    const double diff = std::abs(ff.area[i] * ff.F(i, j) - ff.area[j] * ff.F(j, i));
                    if (diff > 0.0)
                        c.reciprocity_vs_estimate =
                            std::max(c.reciprocity_vs_estimate, est > 0.0 ? diff / est : 1e300);
                }
            }
            c.max_row_error_estimate = std::max(c.max_row_error_estimate, row_est);
        }
        const double err = std::abs(row - 1.0);
        if (c.closure_worst_patch < 0 || err > c.closure_max_error) {
            c.closure_max_error = err;
            c.closure_worst_patch = i;
        }
    }
    return c;
}

}  // namespace radiosa
