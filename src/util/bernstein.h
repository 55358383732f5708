#pragma once
// Tensor-product Bernstein polynomials on [0,1]^2 and their products. A polynomial in this form
// lies within the range of its coefficients (the convex hull property), so a sign is proven
// over the whole square when every coefficient has it (surfaces/bezier.cpp proves with them that
// a patch is seen once from a polygon).
#include <cstddef>
#include <vector>

namespace radiosa {

template <class T>
struct Bernstein2 {
    int m = 0, n = 0;  // degrees in s and in t
    std::vector<T> c;  // c[i (n + 1) + j]: the coefficient of B_i^m(s) B_j^n(t)
    Bernstein2(int ms, int nt, const T& zero)
        : m(ms), n(nt), c(static_cast<std::size_t>((ms + 1) * (nt + 1)), zero) {}
    T& at(int i, int j) { return c[static_cast<std::size_t>(i * (n + 1) + j)]; }
    const T& at(int i, int j) const { return c[static_cast<std::size_t>(i * (n + 1) + j)]; }
};

// n choose k, exact for the small degrees used here.
inline double binomial(int n, int k) {
    double b = 1.0;
    for (int i = 1; i <= k; ++i) b = b * (n - k + i) / i;
    return b;
}

// The product f g, with each pair of coefficients combined by op(f_ij, g_kl) (a product that is
// linear in each argument: a dot or cross product, or a term affine in a parameter):
// (f g)_pq = sum over i + k = p, j + l = q of C(m1,i) C(m2,k) / C(m1+m2,p) x C(n1,j) C(n2,l) /
// C(n1+n2,q) x op(f_ij, g_kl).
template <class A, class B, class Op>
auto bernstein_product(const Bernstein2<A>& f, const Bernstein2<B>& g, const Op& op) {
    using T = decltype(op(f.c[0], g.c[0]));
    Bernstein2<T> h(f.m + g.m, f.n + g.n, 0.0 * op(f.c[0], g.c[0]));
    // The weights along t, one per (j, l), are the same for every (i, k).
    std::vector<double> wt(static_cast<std::size_t>((f.n + 1) * (g.n + 1)));
    for (int j = 0; j <= f.n; ++j)
        for (int l = 0; l <= g.n; ++l)
            wt[static_cast<std::size_t>(j * (g.n + 1) + l)] =
                binomial(f.n, j) * binomial(g.n, l) / binomial(f.n + g.n, j + l);
    for (int i = 0; i <= f.m; ++i)
        for (int k = 0; k <= g.m; ++k) {
            const double ws = binomial(f.m, i) * binomial(g.m, k) / binomial(f.m + g.m, i + k);
            for (int j = 0; j <= f.n; ++j)
                for (int l = 0; l <= g.n; ++l)
                    h.at(i + k, j + l) +=
                        ws * wt[static_cast<std::size_t>(j * (g.n + 1) + l)] * op(f.at(i, j), g.at(k, l));
        }
    return h;
}

// The derivative in s (a polynomial of degree m - 1 in s) or in t.
template <class T>
Bernstein2<T> bernstein_ds(const Bernstein2<T>& f) {
    Bernstein2<T> d(f.m - 1, f.n, 0.0 * f.c[0]);
    for (int i = 0; i < f.m; ++i)
        for (int j = 0; j <= f.n; ++j) d.at(i, j) = static_cast<double>(f.m) * (f.at(i + 1, j) - f.at(i, j));
    return d;
}
template <class T>
Bernstein2<T> bernstein_dt(const Bernstein2<T>& f) {
    Bernstein2<T> d(f.m, f.n - 1, 0.0 * f.c[0]);
    for (int i = 0; i <= f.m; ++i)
        for (int j = 0; j < f.n; ++j) d.at(i, j) = static_cast<double>(f.n) * (f.at(i, j + 1) - f.at(i, j));
    return d;
}

}  // namespace radiosa
