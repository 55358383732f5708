#include "util/convex_distance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace radiosa {

namespace {

// The point of the affine hull of s[0..n) nearest the origin, as barycentric weights; false
// when the system is degenerate.
bool affine_nearest(const Vec3* s, int n, double* w) {
    if (n == 1) {
        w[0] = 1.0;
        return true;
    }
    // Minimise |s0 + sum_k x_k (s_k - s0)|^2: normal equations of size n - 1 <= 3.
    std::array<Vec3, 3> e;
    for (int k = 1; k < n; ++k) e[k - 1] = s[k] - s[0];
    const int m = n - 1;
    double A[3][4] = {};
    for (int r = 0; r < m; ++r) {
        for (int c = 0; c < m; ++c) A[r][c] = glm::dot(e[r], e[c]);
        A[r][m] = -glm::dot(e[r], s[0]);
    }
    // Gaussian elimination with partial pivoting.
    for (int c = 0; c < m; ++c) {
        int p = c;
        for (int r = c + 1; r < m; ++r)
            if (std::abs(A[r][c]) > std::abs(A[p][c])) p = r;
        if (!(std::abs(A[p][c]) > 1e-300)) return false;
        for (int k = 0; k <= m; ++k) std::swap(A[c][k], A[p][k]);
        for (int r = 0; r < m; ++r) {
            if (r == c) continue;
            const double f = A[r][c] / A[c][c];
            for (int k = c; k <= m; ++k) A[r][k] -= f * A[c][k];
        }
    }
    double sum = 0.0;
    for (int r = 0; r < m; ++r) {
        w[r + 1] = A[r][m] / A[r][r];
        sum += w[r + 1];
    }
    w[0] = 1.0 - sum;
    return std::all_of(w, w + n, [](double x) { return std::isfinite(x); });
}

// Replaces the simplex s[0..*n) by the smallest sub-simplex holding its point nearest the
// origin, and returns that point.
Vec3 reduce(std::array<Vec3, 4>* s, int* n) {
    Vec3 best(0.0);
    double best_d = std::numeric_limits<double>::infinity();
    std::array<Vec3, 4> best_s{};
    int best_n = 0;
    for (int mask = 1; mask < (1 << *n); ++mask) {
        std::array<Vec3, 4> sub;
        int m = 0;
        for (int k = 0; k < *n; ++k)
            if (mask & (1 << k)) sub[m++] = (*s)[k];
        double w[4];
        if (!affine_nearest(sub.data(), m, w)) continue;
        if (std::any_of(w, w + m, [](double x) { return x <= 0.0; }) && m > 1) continue;
        Vec3 p(0.0);
        for (int k = 0; k < m; ++k) p += w[k] * sub[k];
        const double d = glm::dot(p, p);
        if (d < best_d) {
            best_d = d;
            best = p;
            best_s = sub;
            best_n = m;
        }
    }
    *s = best_s;
    *n = best_n;
    return best;
}

}  // namespace

double convex_distance(std::span<const Vec3> a, std::span<const Vec3> b, double enough) {
    // Support point of the Minkowski difference a - b in direction d.
    auto support = [&](const Vec3& d) {
        Vec3 pa = a[0], pb = b[0];
        double ba = glm::dot(pa, d), bb = glm::dot(pb, d);
        for (const Vec3& p : a)
            if (glm::dot(p, d) > ba) ba = glm::dot(p, d), pa = p;
        for (const Vec3& p : b)
            if (glm::dot(p, d) < bb) bb = glm::dot(p, d), pb = p;
        return pa - pb;
    };
    double scale = 0.0;
    for (const Vec3& p : a) scale = std::max(scale, glm::length(p - a[0]));
    for (const Vec3& p : b) scale = std::max(scale, glm::length(p - a[0]));
    const double eps = 1e-12 * std::max(scale, 1e-300);
    std::array<Vec3, 4> s{a[0] - b[0]};
    int n = 1;
    Vec3 v = s[0];
    double lower = 0.0;
    for (int iter = 0; iter < 64; ++iter) {
        const double vv = glm::length(v);
        if (vv <= eps) return 0.0;
        const Vec3 w = support(-v);
        // Every point of the difference lies on the far side of the plane through w normal to
        // v: the distance is at least v . w / |v|.
        lower = std::max(lower, glm::dot(v, w) / vv);
        if (lower > enough || vv - lower <= 1e-12 * vv) return lower;
        if (n == 4) return lower;  // origin inside (degenerate progress): report the bound
        s[n++] = w;
        v = reduce(&s, &n);
    }
    return lower;
}

double distance_to_segment(const Vec3& x, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(x - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(x - (a + t * ab));
}

double distance_to_polygon(const Vec3& x, const std::array<Vec3, 4>& v) {
    Vec3 m(0.0);
    for (int k = 0; k < 4; ++k) m += glm::cross(v[k], v[(k + 1) % 4]);
    const double ml = glm::length(m);
    if (!(ml > 0.0)) return glm::length(x - v[0]);
    m /= ml;
    const double h = glm::dot(x - v[0], m);
    const Vec3 p = x - h * m;
    bool inside = true;
    for (int k = 0; k < 4 && inside; ++k)
        inside = glm::dot(glm::cross(v[(k + 1) % 4] - v[k], p - v[k]), m) >= 0.0;
    if (inside) return std::abs(h);
    double d = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 4; ++k) d = std::min(d, distance_to_segment(x, v[k], v[(k + 1) % 4]));
    return d;
}

}  // namespace radiosa
