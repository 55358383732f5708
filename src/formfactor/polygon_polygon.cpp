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

// The double integral of ln(r / rho) over two parallel edges, in closed form (the edges' lines
// at distance h; positions along them measured on a common axis: the first edge covers
// [0, len_a], the second [b0, b1]). With f(u) = ln sqrt(u^2 + h^2) - ln rho of the offset
// u = s - t, the integral is Phi(len_a - b0) - Phi(-b0) - Phi(len_a - b1) + Phi(-b1) for any
// Phi with Phi'' = f:
//   Phi(u) = u^2/4 (ln(u^2 + h^2) - 2 ln rho) - h^2/4 ln(1 + u^2/h^2) + h u atan(u / h) - 3 u^2 / 4,
// left without the term -h^2/4 ln(h^2 / rho^2), constant in u, which the four would cancel but
// whose rounding they would not (far apart, h^2 times the logarithm's last bit). Every term is
// then of order u^2. Touching and collinear edges (h = 0, u = 0) take the limits, 0 ln 0 = 0.
// The rounding estimate counts each Phi's terms and how far an error of one ulp of the inputs
// (u, h) moves it.
ParallelEdges parallel_edges_log_integral(double len_a, double b0, double b1, double h, double log_rho) {
    constexpr double eps = std::numeric_limits<double>::epsilon();
    ParallelEdges out;
    auto phi = [&](double u, double sign) {
        const double r2 = u * u + h * h;
        const double lg = r2 > 0.0 ? std::log(r2) - 2.0 * log_rho : 0.0;
        const double at = h > 0.0 ? std::atan(u / h) : 0.0;
        const double l1 = h > 0.0 ? std::log1p((u / h) * (u / h)) : 0.0;
        const double t1 = 0.25 * u * u * lg, t2 = -0.25 * h * h * l1, t3 = h * u * at, t4 = 0.75 * u * u;
        const double du = 0.5 * u * lg - u + h * at;  // Phi'(u)
        const double dh = u * at - 0.5 * h * l1;      // d Phi / dh
        out.value += sign * (t1 + t2 + t3 - t4);
        out.error += std::abs(t1) + std::abs(t2) + std::abs(t3) + t4 +
                     (std::abs(du) + std::abs(dh)) * (std::abs(u) + h);
    };
    phi(len_a - b0, 1.0);
    phi(-b0, -1.0);
    phi(len_a - b1, -1.0);
    phi(-b1, 1.0);
    out.error *= 16 * eps;
    return out;
}

namespace {

// Edges whose directions agree to this (the sine of the angle between them) are taken as
// parallel: the closed form above replaces the adaptive rule, and what the tilt can change is
// added to the estimate.
constexpr double kParallelSine = 1e-12;

// A_a F_ab's sum term for edges k and l when they are parallel: the closed form, with the
// bound on what a tilt of `sine` changes (the lines' distance then varies by at most
// sine x span along the edges; the integral of ln r moves by at most pi per unit of that
// distance per unit of length, the Poisson kernel's mass).
PolygonPair parallel_pair(const Vec3& ak, const Vec3& dk, double lk, const Vec3& bl, const Vec3& dl,
                          double ll, double sine, double log_rho) {
    const Vec3 w = bl - ak;
    const double along = glm::dot(w, dk);
    const double h = glm::length(w - along * dk);
    const double end = along + (glm::dot(dk, dl) > 0.0 ? ll : -ll);
    const ParallelEdges p =
        parallel_edges_log_integral(lk, std::min(along, end), std::max(along, end), h, log_rho);
    const double span = lk + ll + glm::length(w);
    return PolygonPair{p.value, p.error + kPi * sine * span * (lk + ll), 4};
}

// A bound on |integral over edges a0 -> a0 + da and b0 -> b0 + db of ln(r / rho)|, for edges
// whose weight d_k . d_l is rounding: with R the largest distance between their ends (distance
// is convex, so it peaks at ends) ln(r / rho) = ln(R / rho) - ln(R / r), and since r is at least
// the offset along the longer edge (of length L), the second part integrates over that edge
// to at most L (ln(2 R / L) + 1) (its worst case, the other end's foot at the middle), twice
// for edges that are only nearly perpendicular.
double log_integral_bound(const Vec3& a0, const Vec3& da, const Vec3& b0, const Vec3& db, double log_rho) {
    double r = 0.0;
    for (const Vec3& p : {a0, a0 + da})
        for (const Vec3& q : {b0, b0 + db}) r = std::max(r, glm::length(q - p));
    const double la = glm::length(da), lb = glm::length(db), l = std::max(la, lb);
    return la * lb * (std::abs(std::log(r) - log_rho) + 2.0 * (std::log(2.0 * r / l) + 1.0));
}

// Edge k's and edge l's term of the sum, times d_k . d_l, with its error (scaled units). With a
// tolerance (`pair_tol` > 0, this pair's share): edges perpendicular but for rounding (a turned
// room's) add nothing worth counting, and parallel edges (every pair of an axis-aligned room's
// rectangles) take the closed form, each where its bound is within the share. Else, and to
// round-off, the adaptive rule (the closed form's terms are of order the squared distances, and
// cancel more than the rule's between a tiny patch and a large one).
PolygonPair edge_pair_term(const Vec3& ak, const Vec3& dk, double lk, const Vec3& bl, const Vec3& dl,
                           double ll, double log_rho, double pair_tol) {
    const Vec3 uk = dk / lk, ul = dl / ll;
    const double c = glm::dot(uk, ul);
    if (c == 0.0) return PolygonPair{};
    auto weighted = [c](const PolygonPair& p) {
        return PolygonPair{c * p.value, std::abs(c) * p.error, p.evaluations};
    };
    if (pair_tol > 0.0) {
        if (std::abs(c) <= kParallelSine) {
            const double bound = std::abs(c) * log_integral_bound(ak, dk, bl, dl, log_rho);
            if (bound <= pair_tol) return PolygonPair{0.0, bound, 0};
        }
        const double sine = glm::length(glm::cross(uk, ul));
        if (sine <= kParallelSine) {
            const PolygonPair p = parallel_pair(ak, uk, lk, bl, ul, ll, sine, log_rho);
            if (p.error <= pair_tol) return weighted(p);
        }
    }
    return weighted(integrate_edge_pair(ak, uk, lk, Edge{bl, ul, ll}, log_rho, pair_tol));
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
            const PolygonPair p = edge_pair_term(ak, dk, lk, bl, dl, ll, log_rho, pair_tol);
            sum += p.value;
            err += p.error;
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
