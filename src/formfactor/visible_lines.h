#pragma once
// The numeric path's inner integral, F(dx -> patch j), where a surface without a closed-form
// shadow (a torus, a Bezier patch, the receiver itself) hides part of the receiver and the
// fixed tensor rules disagree: iterated 1-D integrals along the receiver's t lines. Along each
// line the visibility of evenly spaced samples is tested, every change between two neighbours
// is located by bisection, and the kernel is integrated over each visible stretch by adaptive
// Gauss-Kronrod with no further ray tests. Across the lines (in s) adaptive Gauss-Kronrod
// again. A shadow's edge inside a tensor rule makes it converge like its spacing; here it is a
// break of a 1-D integral, placed to the precision the tolerance needs, and what is left varies
// smoothly except where an edge runs along a line. As with the tensor rules, a visible or
// hidden stretch narrower than the samples' spacing on every line can be missed.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "formfactor/cubature.h"
#include "util/gauss_kronrod.h"

namespace radiosa {

struct LineIntegral {
    double value = 0.0;
    double error = 0.0;       // the 1-D rules' estimates and the breaks' uncertainty
    long long lines = 0;      // t lines sampled (integrated, or looked at for their shape)
    long long ray_tests = 0;  // calls of `blocked`
};

inline constexpr int kLineSamples = 16;  // intervals between a line's visibility samples

namespace visible_lines_detail {

// A line's visibility at kLineSamples + 1 evenly spaced t, ends included.
struct Samples {
    std::array<double, kLineSamples + 1> t{};
    std::array<bool, kLineSamples + 1> on{};
    double kmax = 0.0;  // the largest |kernel| among them
    // Twice the number of changes between neighbours, plus whether the first is visible: what a
    // line's visible stretches look like, up to where they start and end.
    int shape() const {
        int changes = 0;
        for (int q = 0; q < kLineSamples; ++q) changes += on[q] != on[q + 1];
        return 2 * changes + (on[0] ? 1 : 0);
    }
};

template <class Kernel, class Blocked>
class Lines {
public:
    Lines(const Rect& r, const Kernel& kernel, const Blocked& blocked, double abs_tol)
        : m_r(r),
          m_kernel(kernel),
          m_blocked(blocked),
          m_tol(abs_tol),
          m_line_tol(0.5 * abs_tol / (r.s1 - r.s0)) {}

    LineIntegral run(int max_panels) {
        std::array<double, kLineSamples + 2> breaks{};
        const int n_breaks = s_breaks(&breaks);
        const int panels = std::max(max_panels / (n_breaks - 1), 4);
        for (int b = 0; b + 1 < n_breaks; ++b) {
            const Integral1D across = adaptive_kronrod([this](double s) { return line(s); }, breaks[b],
                                                       breaks[b + 1], 0.5 * m_tol / (n_breaks - 1), panels);
            m_out.value += across.value;
            m_out.error += across.error;
        }
        m_out.error += m_line_err * (m_r.s1 - m_r.s0);
        return m_out;
    }

private:
    bool active(double s, double t, double* k) {
        if (!m_kernel(s, t, k)) return false;
        ++m_out.ray_tests;
        return !m_blocked();
    }

    Samples sample(double s) {
        ++m_out.lines;
        Samples a;
        const double dt = m_r.t1 - m_r.t0;
        for (int q = 0; q <= kLineSamples; ++q) {
            a.t[q] = q == kLineSamples ? m_r.t1 : m_r.t0 + dt * q / kLineSamples;
            double k = 0.0;
            a.on[q] = active(s, a.t[q], &k);
            a.kmax = std::max(a.kmax, std::abs(k));
        }
        return a;
    }

    // The integral along the line at s. Neighbours that disagree have a change between them:
    // bisection places it to within delta, where the kernel's largest sampled value times delta
    // is a small part of the line's share of the tolerance. Each visible stretch is then
    // integrated by adaptive Gauss-Kronrod, with no ray tests.
    double line(double s) {
        const Samples a = sample(s);
        const double dt = m_r.t1 - m_r.t0;
        const double delta = std::max(1e-13 * dt, 0.05 * m_line_tol / std::max(2.0 * a.kmax, 1e-300));
        double uncertain = 0.0, sum = 0.0, err = 0.0;
        std::array<double, 2 * (kLineSamples + 1)> ends{};
        int n_ends = 0;
        if (a.on[0]) ends[n_ends++] = m_r.t0;
        for (int q = 0; q < kLineSamples; ++q) {
            if (a.on[q] == a.on[q + 1]) continue;
            double lo = a.t[q], hi = a.t[q + 1], k = 0.0;
            while (hi - lo > delta) {
                const double mid = 0.5 * (lo + hi);
                (active(s, mid, &k) == a.on[q] ? lo : hi) = mid;
            }
            ends[n_ends++] = 0.5 * (lo + hi);
            m_kernel(s, 0.5 * (lo + hi), &k);
            uncertain += 0.5 * (hi - lo) * 2.0 * std::max(a.kmax, std::abs(k));
        }
        if (a.on[kLineSamples]) ends[n_ends++] = m_r.t1;
        const int pieces = n_ends / 2;
        auto along = [&](double t) {
            double k = 0.0;
            m_kernel(s, t, &k);
            return k;
        };
        for (int p = 0; p < pieces; ++p) {
            const Integral1D v =
                adaptive_kronrod(along, ends[2 * p], ends[2 * p + 1], 0.25 * m_line_tol / pieces, 64);
            sum += v.value;
            err += v.error;
        }
        m_line_err = std::max(m_line_err, err + uncertain);
        return sum;
    }

    // Across the lines the integral jumps or bends where a line's visible stretches change shape
    // (a shadow's edge along a line, a shadow's tip, a sliver at the receiver's edge that no
    // Kronrod node would see): lines evenly spaced in s, ends included, and a bisection between
    // neighbours of different shapes place those breaks. Returns their number, ends included.
    int s_breaks(std::array<double, kLineSamples + 2>* breaks) {
        const double ds = m_r.s1 - m_r.s0, dt = m_r.t1 - m_r.t0;
        std::array<int, kLineSamples + 1> shapes{};
        std::array<double, kLineSamples + 1> ss{};
        double kmax = 0.0;
        for (int q = 0; q <= kLineSamples; ++q) {
            ss[q] = q == kLineSamples ? m_r.s1 : m_r.s0 + ds * q / kLineSamples;
            const Samples a = sample(ss[q]);
            shapes[q] = a.shape();
            kmax = std::max(kmax, a.kmax);
        }
        // A break misplaced by delta costs at most the kernel's integral over a strip that wide.
        const double delta = std::max(1e-13 * ds, 0.05 * m_tol / std::max(2.0 * kmax * dt, 1e-300));
        int n = 0;
        (*breaks)[n++] = m_r.s0;
        for (int q = 0; q < kLineSamples; ++q) {
            if (shapes[q] == shapes[q + 1]) continue;
            double lo = ss[q], hi = ss[q + 1];
            while (hi - lo > delta) {
                const double mid = 0.5 * (lo + hi);
                (sample(mid).shape() == shapes[q] ? lo : hi) = mid;
            }
            (*breaks)[n++] = 0.5 * (lo + hi);
            m_out.error += 0.5 * (hi - lo) * 2.0 * kmax * dt;
        }
        (*breaks)[n++] = m_r.s1;
        return n;
    }

    const Rect m_r;
    const Kernel& m_kernel;
    const Blocked& m_blocked;
    const double m_tol, m_line_tol;  // the whole integral's; a line's, per unit of s
    double m_line_err = 0.0;         // the largest line's error, per unit of s
    LineIntegral m_out;
};

}  // namespace visible_lines_detail

// `kernel(s, t, &k)` sets k to the kernel at receiver parameters (s, t) (smooth: no clamping)
// and returns whether the pair faces there (both cosines positive, the points apart);
// `blocked()` tests the segment to the point of the kernel's last call. The integral of the
// kernel over the facing, unblocked part of r, to about `abs_tol`, with at most `max_panels`
// intervals in s.
template <class Kernel, class Blocked>
LineIntegral integrate_by_lines(const Rect& r, const Kernel& kernel, const Blocked& blocked, double abs_tol,
                                int max_panels = 32) {
    if (!(r.s1 > r.s0 && r.t1 > r.t0)) return {};
    return visible_lines_detail::Lines<Kernel, Blocked>(r, kernel, blocked, abs_tol).run(max_panels);
}

}  // namespace radiosa
