// The sense checks every loaded matrix passes (docs/cache.md, "Checks on every load"). A file
// whose checksum is right can still hold a matrix that is not this scene's: scaled, transposed,
// emptied, computed by another method, or with estimates that are not numbers. These checks
// are cheap next to a render (O(N^2), one pass) and catch all of those that change closure,
// reciprocity or the estimates; docs/cache.md says what they cannot catch.
#include <cmath>
#include <string>

#include "cache/cache_file.h"
#include "cache/cache_format.h"

namespace radiosa {

namespace {

std::string entry(std::size_t k, std::size_t n) {
    return "(" + std::to_string(k / n) + "," + std::to_string(k % n) + ")";
}

// Every value a number in range: F_ij in [0, 1] (up to its estimate), estimates finite and
// >= 0. (Estimates have no upper bound: a conservative one may exceed 1.)
void check_values(const FormFactors& ff) {
    const std::size_t n = static_cast<std::size_t>(ff.F.n);
    const bool estimates = !ff.error.empty();
    for (std::size_t k = 0; k < n * n; ++k) {
        const double f = ff.F.data[k], e = estimates ? ff.error[k] : 0.0;
        if (!(e >= 0.0 && std::isfinite(e)))
            throw CacheFileError("error estimate " + entry(k, n) + " is " + std::to_string(e) +
                                 ", not a finite number >= 0");
        if (!(f >= 0.0 && f <= 1.0 + e + 1e-12))
            throw CacheFileError("entry " + entry(k, n) + " is " + std::to_string(f) +
                                 ", not a number in [0, 1]");
    }
}

// A_i F_ij = A_j F_ji: exactly (to rounding) for the fixed rule, which sets both from one
// integral; for the error-controlled method within a multiple of the estimates or 1e-7 on the
// smaller patch's scale, whichever is larger: at tolerances below about 1e-9 the estimates
// understate (docs/accuracy.md), and an entry changed by less than 1e-7 is not worth a rebuild.
void check_reciprocity(const FormFactors& ff) {
    const std::size_t n = static_cast<std::size_t>(ff.F.n);
    const bool estimates = !ff.error.empty();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j) {
            const double a = ff.area[i] * ff.F.data[i * n + j], b = ff.area[j] * ff.F.data[j * n + i];
            double allowed = 1e-9 * std::max(a, b);
            if (estimates)
                allowed +=
                    std::max(16.0 * (ff.area[i] * ff.error[i * n + j] + ff.area[j] * ff.error[j * n + i]),
                             1e-7 * std::min(ff.area[i], ff.area[j]));
            if (std::abs(a - b) > allowed)
                throw CacheFileError("entries (" + std::to_string(i) + "," + std::to_string(j) + ") and (" +
                                     std::to_string(j) + "," + std::to_string(i) +
                                     ") break reciprocity A_i F_ij = A_j F_ji beyond their error estimates");
        }
}

}  // namespace

void check_cache_matrix(const FormFactors& ff, const FormFactorOptions& options, bool closed) {
    const std::size_t n = static_cast<std::size_t>(ff.F.n);
    const bool adaptive = options.method == FormFactorMethod::Adaptive;
    if (ff.area.size() != n || ff.error.size() != (adaptive ? n * n : 0))
        throw CacheFileError("matrix, areas and error estimates disagree in size");
    check_values(ff);
    std::vector<double> row_sum(n, 0.0), row_error(n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) {
            row_sum[i] += ff.F.data[i * n + j];
            if (adaptive) row_error[i] += ff.error[i * n + j];
        }
    CacheFileInfo info;
    info.options = options;
    info.closed = closed;
    cache_format::check_rows(row_sum, row_error, info);
    check_reciprocity(ff);
}

}  // namespace radiosa
