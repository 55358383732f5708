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

// The integral of f over [a, b]: the interval with the largest |K15 - G7| is bisected until
// the errors sum to at most `abs_tol` (or to the rounding level of the values summed), or
// `max_intervals` is reached (the returned error then shows it).
template <class F>
Integral1D adaptive_kronrod(const F& f, double a, double b, double abs_tol, int max_intervals = 200) {
    struct Piece {
        double a, b, value, error;
    };
    Integral1D out;
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
        out.evaluations += 15;
        mag += std::abs(m * h);
        return Piece{lo, hi, k * h, std::abs((k - g) * h)};
    };
    constexpr double eps = std::numeric_limits<double>::epsilon();
    auto lower = [](const Piece& x, const Piece& y) { return x.error < y.error; };
    std::vector<Piece> heap{rule(a, b)};
    double err = heap[0].error;
    while (err > std::max(abs_tol, 64 * eps * mag) && static_cast<int>(heap.size()) < max_intervals) {
        std::pop_heap(heap.begin(), heap.end(), lower);
        const Piece top = heap.back();
        heap.pop_back();
        err -= top.error;
        const double mid = 0.5 * (top.a + top.b);
        for (const Piece& half : {rule(top.a, mid), rule(mid, top.b)}) {
            heap.push_back(half);
            err += half.error;
            std::push_heap(heap.begin(), heap.end(), lower);
        }
    }
    err = 0.0;
    for (const Piece& p : heap) {
        out.value += p.value;
        err += p.error;
    }
    out.error = err + 64 * eps * mag;
    return out;
}

}  // namespace radiosa
