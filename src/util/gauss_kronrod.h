#pragma once
// The Kronrod (7, 15) pair on [-1, 1] (Piessens et al., QUADPACK qk15) and a globally adaptive
// 1-D integrator built on it.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace radiosa {

// Abscissae of the 15-point rule from the outside in (odd positions are the 7-point Gauss
// nodes), its weights, and the Gauss weights of positions 1, 3, 5, 7.
inline constexpr std::array<double, 8> kKronrodX = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.0};
inline constexpr std::array<double, 8> kKronrodW = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
inline constexpr std::array<double, 4> kGauss7W = {
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

struct Integral1D {
    double value = 0.0;
    double error = 0.0;  // sum of |K15 - G7| over the final intervals, plus rounding
    int evaluations = 0;
};

// One interval of a globally adaptive 1-D rule: its ends, its value and its error estimate.
struct Piece1D {
    double a, b, value, error;
};

// Globally adaptive bisection: from rule(a, b) (a Piece1D), the piece with the largest error is
// halved while more(sum of the errors) holds and there are fewer than `max_pieces`. Returns the
// sums of the final pieces' values and errors (`evaluations` is left to the caller's rule).
template <class Rule, class More>
Integral1D bisect_largest_error(const Rule& rule, double a, double b, const More& more, int max_pieces) {
    auto lower = [](const Piece1D& x, const Piece1D& y) { return x.error < y.error; };
    std::vector<Piece1D> heap{rule(a, b)};
    double err = heap[0].error;
    while (more(err) && static_cast<int>(heap.size()) < max_pieces) {
        std::pop_heap(heap.begin(), heap.end(), lower);
        const Piece1D top = heap.back();
        heap.pop_back();
        err -= top.error;
        const double mid = 0.5 * (top.a + top.b);
        for (const Piece1D& half : {rule(top.a, mid), rule(mid, top.b)}) {
            heap.push_back(half);
            err += half.error;
            std::push_heap(heap.begin(), heap.end(), lower);
        }
    }
    Integral1D sum;
    for (const Piece1D& p : heap) {
        sum.value += p.value;
        sum.error += p.error;
    }
    return sum;
}

// The integral of f over [a, b]: the interval with the largest |K15 - G7| is bisected until
// the errors sum to at most `abs_tol` (or to the rounding level of the values summed), or
// `max_intervals` is reached (the returned error then shows it).
template <class F>
Integral1D adaptive_kronrod(const F& f, double a, double b, double abs_tol, int max_intervals = 200) {
    int evaluations = 0;
    double mag = 0.0;
    auto rule = [&](double lo, double hi) {
        const double c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
        const double fc = f(c);
        double k = kKronrodW[7] * fc, g = kGauss7W[3] * fc, m = kKronrodW[7] * std::abs(fc);
        for (int i = 0; i < 7; ++i) {
            const double f1 = f(c - h * kKronrodX[i]), f2 = f(c + h * kKronrodX[i]);
            k += kKronrodW[i] * (f1 + f2);
            m += kKronrodW[i] * (std::abs(f1) + std::abs(f2));
            if (i % 2 == 1) g += kGauss7W[i / 2] * (f1 + f2);
        }
        evaluations += 15;
        mag += std::abs(m * h);
        return Piece1D{lo, hi, k * h, std::abs((k - g) * h)};
    };
    constexpr double eps = std::numeric_limits<double>::epsilon();
    Integral1D out = bisect_largest_error(
        rule, a, b, [&](double err) { return err > std::max(abs_tol, 64 * eps * mag); }, max_intervals);
    out.error += 64 * eps * mag;
    out.evaluations = evaluations;
    return out;
}

}  // namespace radiosa
