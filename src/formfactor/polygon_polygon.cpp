#include "formfactor/polygon_polygon.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "formfactor/convex_clip.h"
#include "util/gauss_kronrod.h"

namespace radiosa {

namespace {

constexpr int kMaxVerts = 9;  // a convex 8-gon cut by one plane

using Poly = PolygonBuffer<kMaxVerts>;

Vec3 newell(const Vec3* v, int n) {
    Vec3 m(0.0);
    for (int k = 0; k < n; ++k) m += glm::cross(v[k], v[(k + 1) % n]);
    return m;
}

// One edge of the second polygon: start, unit direction, length.
struct Edge {
    Vec3 q;
    Vec3 d;
    double len;
};

// The integral over the edge of ln(r / rho), r the distance to p, in closed form: with u the
// position of p's foot along the edge and h its distance from the edge's line,
//   int ln sqrt(tau^2 + h^2) dtau = tau/2 ln(tau^2 + h^2) - tau + h atan(tau / h).
// `mag` receives the size of the terms that cancel, for the rounding estimate.
double inner(const Vec3& p, const Edge& e, double log_rho, double* mag) {
    const Vec3 w = p - e.q;
    const double u = glm::dot(w, e.d);
    const double h = glm::length(glm::cross(w, e.d));
    auto prim = [&](double tau) {
        const double r2 = tau * tau + h * h;
        const double lg = r2 > 0.0 ? 0.5 * tau * (std::log(r2) - 2.0 * log_rho) : 0.0;
        return lg - tau + (h > 0.0 ? h * std::atan(tau / h) : 0.0);
    };
    const double hi = prim(e.len - u), lo = prim(-u);
    *mag += std::abs(hi) + std::abs(lo);
    return hi - lo;
}

// The integral over edge a0 -> a0 + len * d of inner(., e) by adaptive Gauss-Kronrod, bisecting
// the interval with the largest |K15 - G7| until the sum is below `tol` or the rounding level of
// the terms (or a cap of intervals is hit, which the returned error then shows).
PolygonPair integrate_edge_pair(const Vec3& a0, const Vec3& d, double len, const Edge& e, double log_rho,
                                double tol) {
    PolygonPair out;
    double mag = 0.0;
    auto rule = [&](double a, double b) {
        const double c = 0.5 * (a + b), h = 0.5 * (b - a);
        const double fc = inner(a0 + c * d, e, log_rho, &mag);
        double k = kKronrodW[7] * fc, g = kGauss7W[3] * fc;
        for (int i = 0; i < 7; ++i) {
            const double f = inner(a0 + (c - h * kKronrodX[i]) * d, e, log_rho, &mag) +
                             inner(a0 + (c + h * kKronrodX[i]) * d, e, log_rho, &mag);
            k += kKronrodW[i] * f;
            if (i % 2 == 1) g += kGauss7W[i / 2] * f;
        }
        out.evaluations += 15;
        return Piece1D{a, b, k * h, std::abs((k - g) * h)};
    };
    constexpr int kMaxIntervals = 400;
    constexpr double eps = std::numeric_limits<double>::epsilon();
    // Rounding: every evaluation's cancelling terms, scaled to the interval it came from.
    auto rounding = [&] { return 16 * eps * mag * len / std::max(1, out.evaluations); };
    const Integral1D sum = bisect_largest_error(
        rule, 0.0, len, [&](double err) { return err > std::max(tol, rounding()); }, kMaxIntervals);
    out.value = sum.value;
    out.error = sum.error + rounding();
    return out;
}

}  // namespace

PolygonPair polygon_to_polygon(const Vec3* a, int na, const Vec3* b, int nb, double abs_tol) {
    PolygonPair out;
    // Work in coordinates centred on a's first vertex and scaled to the larger polygon's size,
    // so that the logarithms are of order one at every scale.
    const Vec3 origin = a[0];
    double size = 0.0;
    for (int k = 0; k < na; ++k) size = std::max(size, glm::length(a[k] - origin));
    Vec3 cb(0.0);
    for (int k = 0; k < nb; ++k) cb += b[k];
    cb /= nb;
    for (int k = 0; k < nb; ++k) size = std::max(size, glm::length(b[k] - cb));
    if (!(size > 0.0)) return out;
    Poly pa, pb;
    for (int k = 0; k < na; ++k) pa.v[pa.n++] = (a[k] - origin) / size;
    for (int k = 0; k < nb; ++k) pb.v[pb.n++] = (b[k] - origin) / size;
    const Vec3 ma = newell(pa.v.data(), pa.n), mb = newell(pb.v.data(), pb.n);
    // Each polygon cut to the other's front side: there both cosines are positive.
    const Poly ca = clip_half_space(pa, mb, pb.v[0]), cbp = clip_half_space(pb, ma, pa.v[0]);
    if (ca.n < 3 || cbp.n < 3) return out;
    // Coplanar (or an edge-on sliver): nothing is exchanged.
    double ha = 0.0, hb = 0.0;
    for (int k = 0; k < ca.n; ++k) ha = std::max(ha, glm::dot(glm::normalize(mb), ca.v[k] - pb.v[0]));
    for (int k = 0; k < cbp.n; ++k) hb = std::max(hb, glm::dot(glm::normalize(ma), cbp.v[k] - pa.v[0]));
    if (!(ha > 1e-14) || !(hb > 1e-14)) return out;
    // ln r is taken relative to the polygons' distance, which the closed contours cancel
    // exactly, so that far-apart pairs keep their digits.
    Vec3 c1(0.0), c2(0.0);
    for (int k = 0; k < ca.n; ++k) c1 += ca.v[k];
    for (int k = 0; k < cbp.n; ++k) c2 += cbp.v[k];
    const double log_rho = std::log(std::max(1.0, glm::length(c1 / double(ca.n) - c2 / double(cbp.n))));
    // The tolerance in the scaled units, shared equally among the edge pairs (each weighted by
    // |d_k . d_l| <= 1 in the sum).
    const double scale2 = size * size / (2.0 * kPi);
    const double pair_tol = abs_tol / (scale2 * ca.n * cbp.n);
    double sum = 0.0, err = 0.0;
    for (int k = 0; k < ca.n; ++k) {
        const Vec3 ak = ca.v[k], dk = ca.v[(k + 1) % ca.n] - ak;
        const double lk = glm::length(dk);
        if (!(lk > 0.0)) continue;
        for (int l = 0; l < cbp.n; ++l) {
            const Vec3 bl = cbp.v[l], dl = cbp.v[(l + 1) % cbp.n] - bl;
            const double ll = glm::length(dl);
            if (!(ll > 0.0)) continue;
            const double c = glm::dot(dk / lk, dl / ll);
            if (c == 0.0) continue;
            const PolygonPair p =
                integrate_edge_pair(ak, dk / lk, lk, Edge{bl, dl / ll, ll}, log_rho, pair_tol);
            sum += c * p.value;
            err += std::abs(c) * p.error;
            out.evaluations += p.evaluations;
        }
    }
    // Both contours run counter-clockwise about normals that face each other, so the
    // textbook's sign (same sense about one common normal) flips.
    out.value = std::max(0.0, sum * scale2);
    out.error = (err + 64 * std::numeric_limits<double>::epsilon() * std::abs(sum)) * scale2;
    return out;
}

}  // namespace radiosa
