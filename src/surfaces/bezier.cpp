#include "surfaces/bezier.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>

#include "surfaces/registry.h"
#include "util/bernstein.h"
#include "util/gauss_legendre.h"

namespace radiosa {

namespace {

void bernstein(double u, double b[4], double db[4]) {
    const double v = 1.0 - u;
    b[0] = v * v * v;
    b[1] = 3.0 * u * v * v;
    b[2] = 3.0 * u * u * v;
    b[3] = u * u * u;
    db[0] = -3.0 * v * v;
    db[1] = 3.0 * v * v - 6.0 * u * v;
    db[2] = 6.0 * u * v - 3.0 * u * u;
    db[3] = 3.0 * u * u;
}

// The blossom of the cubic p at (u1, u2, u3): de Casteljau's steps with one parameter each.
Vec3 blossom(const Vec3 p[4], double u1, double u2, double u3) {
    Vec3 q[3];
    for (int i = 0; i < 3; ++i) q[i] = (1.0 - u1) * p[i] + u1 * p[i + 1];
    for (int i = 0; i < 2; ++i) q[i] = (1.0 - u2) * q[i] + u2 * q[i + 1];
    return (1.0 - u3) * q[0] + u3 * q[1];
}

// The control points of the cubic p restricted to [a, b].
void restrict_cubic(const Vec3 p[4], double a, double b, Vec3 out[4]) {
    out[0] = blossom(p, a, a, a);
    out[1] = blossom(p, a, a, b);
    out[2] = blossom(p, a, b, b);
    out[3] = blossom(p, b, b, b);
}

// de Casteljau's halving of the cubic p at 1/2.
void halve(const Vec3 p[4], Vec3 left[4], Vec3 right[4]) {
    const Vec3 a = 0.5 * (p[0] + p[1]), b = 0.5 * (p[1] + p[2]), c = 0.5 * (p[2] + p[3]);
    const Vec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), m = 0.5 * (ab + bc);
    left[0] = p[0], left[1] = a, left[2] = ab, left[3] = m;
    right[0] = m, right[1] = bc, right[2] = c, right[3] = p[3];
}

// Whether the ray meets the box within (t_min, t_max); *entry is where it enters.
bool ray_box(const Ray& ray, const Vec3& lo, const Vec3& hi, double t_min, double t_max, double* entry) {
    double a = t_min, b = t_max;
    for (int k = 0; k < 3; ++k) {
        const double inv = 1.0 / ray.dir[k];
        double n = (lo[k] - ray.origin[k]) * inv, f = (hi[k] - ray.origin[k]) * inv;
        if (std::isnan(n) || std::isnan(f)) {  // parallel and on the slab's boundary
            if (ray.origin[k] < lo[k] || ray.origin[k] > hi[k]) return false;
            continue;
        }
        if (n > f) std::swap(n, f);
        a = std::max(a, n);
        b = std::min(b, f);
        if (a > b) return false;
    }
    *entry = a;
    return true;
}

constexpr int kStaticLevels = 5;  // halvings made once, with the patch: 32 x 32 leaves
constexpr int kMaxDepth = 10;     // halvings below a leaf whose Newton search fails
constexpr int kBeforeDepth = 3;   // halvings of a cell the segment leaves or reaches the surface in
constexpr double kSlack = 1e-9;   // a converged (s, t) may lie this far outside its cell

}  // namespace

BezierSurface::BezierSurface(const std::array<Vec3, 16>& cp) : m_cp(cp) {
    m_pole_t0 = cp[0] == cp[1] && cp[1] == cp[2] && cp[2] == cp[3];
    m_pole_t1 = cp[12] == cp[13] && cp[13] == cp[14] && cp[14] == cp[15];
    Vec3 lo = cp[0], hi = cp[0];
    for (const Vec3& p : cp) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    m_size = glm::length(hi - lo);
    m_tree.push_back(make_cell(0.0, 1.0, 0.0, 1.0));
    split(0, kStaticLevels);
}

Vec3 BezierSurface::point(double s, double t) const {
    double bs[4], ds[4], bt[4], dt[4];
    bernstein(s, bs, ds);
    bernstein(t, bt, dt);
    Vec3 p(0.0);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) p += (bt[i] * bs[j]) * m_cp[4 * i + j];
    return p;
}

void BezierSurface::partials(double s, double t, Vec3* dPds, Vec3* dPdt) const {
    double bs[4], ds[4], bt[4], dt[4];
    bernstein(s, bs, ds);
    bernstein(t, bt, dt);
    Vec3 a(0.0), b(0.0);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            a += (bt[i] * ds[j]) * m_cp[4 * i + j];
            b += (dt[i] * bs[j]) * m_cp[4 * i + j];
        }
    *dPds = a;
    *dPdt = b;
}

void BezierSurface::point_and_partials(double s, double t, Vec3* p, Vec3* dPds, Vec3* dPdt) const {
    // point() and partials() from one evaluation of the basis, each sum in their order.
    double bs[4], ds[4], bt[4], dt[4];
    bernstein(s, bs, ds);
    bernstein(t, bt, dt);
    Vec3 q(0.0), a(0.0), b(0.0);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            const Vec3& c = m_cp[4 * i + j];
            q += (bt[i] * bs[j]) * c;
            a += (bt[i] * ds[j]) * c;
            b += (dt[i] * bs[j]) * c;
        }
    *p = q;
    *dPds = a;
    *dPdt = b;
}

Vec3 BezierSurface::unit_normal(double s, double t) const {
    // At a collapsed edge the cross product vanishes; its direction has a limit from inside,
    // taken a little way into the patch, as far as the cross product needs to have digits.
    for (double step : {0.0, 1e-7, 1e-5, 1e-3}) {
        const double u = std::clamp(s, step, 1.0 - step), v = std::clamp(t, step, 1.0 - step);
        const Vec3 n = normal(u, v);
        const double len = glm::length(n);
        if (len > 1e-12 * m_size * m_size) return n / len;
    }
    return Vec3(0.0, 0.0, 1.0);  // a patch collapsed to a curve or a point: no area, no side
}

std::array<Vec3, 16> BezierSurface::sub_patch(double s0, double s1, double t0, double t1) const {
    if (s0 == 0.0 && s1 == 1.0 && t0 == 0.0 && t1 == 1.0) return m_cp;  // culling asks for the whole patch
    std::array<Vec3, 16> rows, out;
    for (int i = 0; i < 4; ++i) restrict_cubic(&m_cp[4 * i], s0, s1, &rows[4 * i]);
    for (int j = 0; j < 4; ++j) {
        const Vec3 col[4] = {rows[j], rows[4 + j], rows[8 + j], rows[12 + j]};
        Vec3 r[4];
        restrict_cubic(col, t0, t1, r);
        for (int i = 0; i < 4; ++i) out[4 * i + j] = r[i];
    }
    return out;
}

void BezierSurface::quarter(const std::array<Vec3, 16>& cp, std::array<std::array<Vec3, 16>, 4>* out) {
    // Each row halved in s, then each column of both halves in t: kids in the order
    // (s low, t low), (s high, t low), (s low, t high), (s high, t high).
    std::array<Vec3, 16> half[2];
    for (int i = 0; i < 4; ++i) halve(&cp[4 * i], &half[0][4 * i], &half[1][4 * i]);
    for (int side = 0; side < 2; ++side)
        for (int j = 0; j < 4; ++j) {
            const Vec3 col[4] = {half[side][j], half[side][4 + j], half[side][8 + j], half[side][12 + j]};
            Vec3 lo[4], hi[4];
            halve(col, lo, hi);
            for (int i = 0; i < 4; ++i) {
                (*out)[side][4 * i + j] = lo[i];
                (*out)[2 + side][4 * i + j] = hi[i];
            }
        }
}

void BezierSurface::split(int cell, int levels) {
    if (levels == 0) return;
    const Cell c = m_tree[cell];
    const double sm = 0.5 * (c.s0 + c.s1), tm = 0.5 * (c.t0 + c.t1);
    const int first = static_cast<int>(m_tree.size());
    m_tree[cell].first_child = first;
    m_tree.push_back(make_cell(c.s0, sm, c.t0, tm));
    m_tree.push_back(make_cell(sm, c.s1, c.t0, tm));
    m_tree.push_back(make_cell(c.s0, sm, tm, c.t1));
    m_tree.push_back(make_cell(sm, c.s1, tm, c.t1));
    for (int k = 0; k < 4; ++k) split(first + k, levels - 1);
}

BezierSurface::Cell BezierSurface::make_cell(double s0, double s1, double t0, double t1) const {
    return box_of(s0, s1, t0, t1, sub_patch(s0, s1, t0, t1));
}

BezierSurface::Cell BezierSurface::box_of(double s0, double s1, double t0, double t1,
                                          const std::array<Vec3, 16>& cp) const {
    Cell c{s0, s1, t0, t1, cp[0], cp[0]};
    for (const Vec3& p : cp) {
        c.lo = glm::min(c.lo, p);
        c.hi = glm::max(c.hi, p);
    }
    const Vec3 pad(1e-12 * m_size);
    c.lo -= pad;
    c.hi += pad;
    return c;
}

BezierSurface::Newton BezierSurface::newton(const Cell& c, const Ray& ray, double t_min, double t_max,
                                            SurfaceHit* hit) const {
    double s = 0.5 * (c.s0 + c.s1), t = 0.5 * (c.t0 + c.t1);
    const double dd = glm::dot(ray.dir, ray.dir);
    double lambda = glm::dot(point(s, t) - ray.origin, ray.dir) / dd;
    const double tol = 1e-13 * m_size;
    const double ws = c.s1 - c.s0, wt = c.t1 - c.t0;
    for (int it = 0; it < 16; ++it) {
        Vec3 p, ps, pt;
        point_and_partials(s, t, &p, &ps, &pt);
        const Vec3 f = p - ray.at(lambda);
        if (glm::length(f) <= tol && it > 0) break;
        const Mat3 J(ps, pt, -ray.dir);
        if (!(std::abs(glm::determinant(J)) > 0.0)) return Newton::None;
        const Vec3 step = glm::inverse(J) * f;
        s -= step.x;
        t -= step.y;
        lambda -= step.z;
        if (s < c.s0 - ws || s > c.s1 + ws || t < c.t0 - wt || t > c.t1 + wt)
            return Newton::None;  // diverging
    }
    if (glm::length(point(s, t) - ray.at(lambda)) > 1e3 * tol) return Newton::None;
    const bool inside = !(s < c.s0 - kSlack || s > c.s1 + kSlack || t < c.t0 - kSlack || t > c.t1 + kSlack);
    if (!inside && (s < -kSlack || s > 1.0 + kSlack || t < -kSlack || t > 1.0 + kSlack)) return Newton::None;
    if (!(lambda > t_min)) return inside ? Newton::Before : Newton::None;
    if (!(lambda < t_max)) return inside ? Newton::Beyond : Newton::None;
    const double sc = std::clamp(s, 0.0, 1.0), tc = std::clamp(t, 0.0, 1.0);
    const Vec3 n = unit_normal(sc, tc);
    const double margin = end_margin(ray, n, m_size);
    if (!(lambda > t_min + margin)) return inside ? Newton::Before : Newton::None;
    if (!(lambda < t_max - margin)) return inside ? Newton::Beyond : Newton::None;
    hit->dist = lambda;
    hit->s = sc;
    hit->t = tc;
    hit->front = glm::dot(n, ray.dir) < 0.0;
    return inside ? Newton::Hit : Newton::Elsewhere;
}

void BezierSurface::search(const Cell& c, const Ray& ray, double t_min, double* best, SurfaceHit* hit,
                           HitSide side, bool* found) const {
    if (c.first_child < 0) {
        refine(c, sub_patch(c.s0, c.s1, c.t0, c.t1), ray, t_min, best, hit, side, 0, kMaxDepth, found);
        return;
    }
    // The halves the ray enters, nearest first: a hit there prunes the others.
    std::array<std::pair<double, int>, 4> order;
    int n = 0;
    for (int k = 0; k < 4; ++k) {
        const Cell& kid = m_tree[c.first_child + k];
        double entry = 0.0;
        if (ray_box(ray, kid.lo, kid.hi, t_min, *best, &entry)) order[n++] = {entry, c.first_child + k};
    }
    std::sort(order.begin(), order.begin() + n);
    for (int i = 0; i < n && !(found && *found); ++i)
        if (order[i].first < *best) search(m_tree[order[i].second], ray, t_min, best, hit, side, found);
}

void BezierSurface::refine(const Cell& c, const std::array<Vec3, 16>& cp, const Ray& ray, double t_min,
                           double* best, SurfaceHit* hit, HitSide side, int depth, int max_depth,
                           bool* found) const {
    SurfaceHit h;
    const Newton n = newton(c, ray, t_min, *best, &h);
    const bool wanted = side == HitSide::Any || h.front;
    if ((n == Newton::Hit || n == Newton::Elsewhere) && wanted) {
        *best = h.dist;
        *hit = h;
        if (found) {
            *found = true;
            return;
        }
        // In this cell: a nearer crossing inside it would need the ray to fold back within it.
        if (n == Newton::Hit) return;
    }
    // A crossing at or before t_min, or at or beyond t_max (a segment leaving or reaching the
    // surface here): a second one in the same cell needs the surface to bend back within it, so
    // a few more halvings settle it.
    if (n == Newton::Before || n == Newton::Beyond) max_depth = std::min(max_depth, depth + kBeforeDepth);
    if (depth >= max_depth) return;
    const double sm = 0.5 * (c.s0 + c.s1), tm = 0.5 * (c.t0 + c.t1);
    std::array<std::array<Vec3, 16>, 4> kids;
    quarter(cp, &kids);
    const double rect[4][4] = {
        {c.s0, sm, c.t0, tm}, {sm, c.s1, c.t0, tm}, {c.s0, sm, tm, c.t1}, {sm, c.s1, tm, c.t1}};
    for (int k = 0; k < 4 && !(found && *found); ++k) {
        const Cell kc = box_of(rect[k][0], rect[k][1], rect[k][2], rect[k][3], kids[k]);
        double entry = 0.0;
        if (ray_box(ray, kc.lo, kc.hi, t_min, *best, &entry))
            refine(kc, kids[k], ray, t_min, best, hit, side, depth + 1, max_depth, found);
    }
}

std::optional<SurfaceHit> BezierSurface::crossing(const Ray& ray, double t_min, double t_max, HitSide side,
                                                  bool first) const {
    double entry = 0.0, best = t_max;
    if (!ray_box(ray, m_tree[0].lo, m_tree[0].hi, t_min, t_max, &entry)) return std::nullopt;
    SurfaceHit hit;
    bool found = false;
    search(m_tree[0], ray, t_min, &best, &hit, side, first ? &found : nullptr);
    if (!(best < t_max)) return std::nullopt;
    return hit;
}

std::optional<SurfaceHit> BezierSurface::intersect(const Ray& ray, double t_min, double t_max,
                                                   HitSide side) const {
    return crossing(ray, t_min, t_max, side, false);
}

bool BezierSurface::blocks(const Ray& ray, double t_min, double t_max) const {
    return crossing(ray, t_min, t_max, HitSide::Any, true).has_value();
}

double BezierSurface::area(double s0, double s1, double t0, double t1) const {
    const GaussRule& r = gauss_legendre(12);
    auto rule = [&](double a0, double a1, double b0, double b1) {
        double sum = 0.0;
        for (std::size_t i = 0; i < r.x.size(); ++i)
            for (std::size_t j = 0; j < r.x.size(); ++j)
                sum += r.w[i] * r.w[j] *
                       glm::length(
                           normal(a0 + 0.5 * (a1 - a0) * (r.x[i] + 1), b0 + 0.5 * (b1 - b0) * (r.x[j] + 1)));
        return sum * 0.25 * (a1 - a0) * (b1 - b0);
    };
    // Each rectangle against its four quarters, halving where they disagree.
    struct Rect {
        double a0, a1, b0, b1, value;
        int depth;
    };
    std::vector<Rect> todo = {{s0, s1, t0, t1, rule(s0, s1, t0, t1), 0}};
    double total = 0.0;
    int splits = 0;
    const double tol = 1e-15 * m_size * m_size;
    while (!todo.empty()) {
        const Rect q = todo.back();
        todo.pop_back();
        const double am = 0.5 * (q.a0 + q.a1), bm = 0.5 * (q.b0 + q.b1);
        const Rect kids[4] = {{q.a0, am, q.b0, bm, rule(q.a0, am, q.b0, bm), q.depth + 1},
                              {am, q.a1, q.b0, bm, rule(am, q.a1, q.b0, bm), q.depth + 1},
                              {q.a0, am, bm, q.b1, rule(q.a0, am, bm, q.b1), q.depth + 1},
                              {am, q.a1, bm, q.b1, rule(am, q.a1, bm, q.b1), q.depth + 1}};
        const double sum = kids[0].value + kids[1].value + kids[2].value + kids[3].value;
        // Rounding can keep a rectangle from meeting tol: a depth and a total cap end it.
        if (std::abs(sum - q.value) <= tol || q.depth >= 10 || ++splits > 2000) {
            total += sum;
            continue;
        }
        for (const Rect& k : kids) todo.push_back(k);
    }
    return total;
}

BoundingSphere BezierSurface::bound(double s0, double s1, double t0, double t1) const {
    const std::array<Vec3, 16> cp = sub_patch(s0, s1, t0, t1);
    Vec3 lo = cp[0], hi = cp[0];
    for (const Vec3& p : cp) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const Vec3 mid = 0.5 * (lo + hi);
    double r = 0.0;
    for (const Vec3& p : cp) r = std::max(r, glm::length(p - mid));
    return {mid, r * (1.0 + 1e-14) + 1e-15 * m_size};
}

std::pair<double, double> BezierSurface::linear_range(const Vec3& a, double s0, double s1, double t0,
                                                      double t1) const {
    const std::array<Vec3, 16> cp = sub_patch(s0, s1, t0, t1);
    double lo = glm::dot(a, cp[0]), hi = lo;
    for (const Vec3& p : cp) {
        lo = std::min(lo, glm::dot(a, p));
        hi = std::max(hi, glm::dot(a, p));
    }
    const double pad = 1e-14 * glm::length(a) * m_size;
    return {lo - pad, hi + pad};
}

bool BezierSurface::patch_contour(double s0, double s1, double t0, double t1,
                                  std::vector<ContourPiece>* out) const {
    // Row by row: point (i, j) of the sub-patch is cp[4 j + i], i along s. Counter-clockwise in
    // (s, t) is counter-clockwise about dP/ds x dP/dt, the front normal.
    const std::array<Vec3, 16> cp = sub_patch(s0, s1, t0, t1);
    auto at = [&](int i, int j) { return cp[static_cast<std::size_t>(4 * j + i)]; };
    out->clear();
    auto curve = [&](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
        ContourPiece p;
        p.cubic = true;
        p.q = {a, b, c, d};
        p.a = a;
        p.b = d;
        out->push_back(p);
    };
    curve(at(0, 0), at(1, 0), at(2, 0), at(3, 0));
    curve(at(3, 0), at(3, 1), at(3, 2), at(3, 3));
    curve(at(3, 3), at(2, 3), at(1, 3), at(0, 3));
    curve(at(0, 3), at(0, 2), at(0, 1), at(0, 0));
    return true;
}

namespace {

// a + b . x: a Bernstein coefficient of a polynomial in (s, t) that also depends on a point x.
struct AffineInX {
    double a = 0.0;
    Vec3 b{0.0};
    AffineInX& operator+=(const AffineInX& o) {
        a += o.a;
        b += o.b;
        return *this;
    }
};
AffineInX operator*(double w, const AffineInX& v) { return {w * v.a, w * v.b}; }

// +1 when every coefficient is above `slack` at every point x, -1 when every one is below
// -slack, else 0. Affine in x, a coefficient is then so over the points' convex hull.
int sign_everywhere(const Bernstein2<AffineInX>& f, std::span<const Vec3> from, double slack) {
    int sign = 0;
    for (const AffineInX& c : f.c)
        for (const Vec3& x : from) {
            const double v = c.a + glm::dot(c.b, x);
            const int s = v > slack ? 1 : v < -slack ? -1 : 0;
            if (s == 0 || (sign != 0 && s != sign)) return 0;
            sign = s;
        }
    return sign;
}

}  // namespace

int BezierSurface::seen_once_from(std::span<const Vec3> from, double s0, double s1, double t0,
                                  double t1) const {
    if (from.empty()) return 0;
    const std::array<Vec3, 16> cp = sub_patch(s0, s1, t0, t1);
    Bernstein2<Vec3> p(3, 3, Vec3(0.0));
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) p.at(i, j) = cp[static_cast<std::size_t>(4 * j + i)];
    const Bernstein2<Vec3> ps = bernstein_ds(p), pt = bernstein_dt(p);
    // The projection's frame: w from the points' mean toward the part's middle, e1 along dP/ds
    // there. Its Jacobian there is then triangular, so the signs below are consistent with one
    // orientation of the plane.
    Vec3 mean(0.0);
    double reach = m_size;
    for (const Vec3& x : from) {
        mean += x / static_cast<double>(from.size());
        reach = std::max(reach, glm::length(x - m_cp[0]) + m_size);
    }
    Vec3 dps, dpt;
    partials(0.5 * (s0 + s1), 0.5 * (t0 + t1), &dps, &dpt);
    const Vec3 to = point(0.5 * (s0 + s1), 0.5 * (t0 + t1)) - mean;
    if (!(glm::length(to) > 1e-9 * reach)) return 0;
    const Vec3 w = glm::normalize(to);
    const Vec3 along = dps - glm::dot(dps, w) * w;
    if (!(glm::length(along) > 1e-6 * glm::length(dps))) return 0;
    const Vec3 e1 = glm::normalize(along), e2 = glm::cross(w, e1);
    // Coefficients are rounded by a few ulps of terms up to reach^k.
    auto slack = [&](int k) { return 1e-10 * std::pow(reach, k); };
    // d = (P - x) . w > 0: the projection onto the plane normal to w is defined.
    Bernstein2<AffineInX> d(3, 3, AffineInX{});
    for (std::size_t k = 0; k < d.c.size(); ++k) d.c[k] = AffineInX{glm::dot(p.c[k], w), -w};
    if (sign_everywhere(d, from, slack(1)) != 1) return 0;
    // d^2 du/ds = ((P - x) x dP/ds) . e2 and -d^2 dv/dt = ((P - x) x dP/dt) . e1.
    auto crossed_with = [](const Vec3& e) {
        return [e](const Vec3& q, const Vec3& dq) {
            return AffineInX{glm::dot(glm::cross(q, dq), e), -glm::cross(dq, e)};
        };
    };
    const int du = sign_everywhere(bernstein_product(p, ps, crossed_with(e2)), from, slack(2));
    const int dv = sign_everywhere(bernstein_product(p, pt, crossed_with(e1)), from, slack(2));
    // d^3 det J = (P - x) . (dP/ds x dP/dt).
    const Bernstein2<Vec3> n =
        bernstein_product(ps, pt, [](const Vec3& a, const Vec3& b) { return glm::cross(a, b); });
    const int side = sign_everywhere(bernstein_product(n, p,
                                                       [](const Vec3& nn, const Vec3& q) {
                                                           return AffineInX{glm::dot(nn, q), -nn};
                                                       }),
                                     from, slack(3));
    // diag(du, -dv) J has a positive diagonal; its determinant, -du dv det J, must be positive too.
    if (du == 0 || dv == 0 || side == 0 || du * dv * side != -1) return 0;
    return side < 0 ? 1 : -1;  // n . (x - P) > 0: the points see the front
}

void BezierSurface::write_key(ByteWriter& w) const {
    for (const Vec3& p : m_cp)
        for (int k = 0; k < 3; ++k) w.f64(p[k]);
}

namespace {

// The numbers of one line, separated by commas and/or blanks.
std::vector<double> numbers_of(const std::string& line, const std::string& path, int line_no) {
    std::vector<double> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ',' || std::isspace(static_cast<unsigned char>(line[i])))) ++i;
        if (i >= line.size()) break;
        std::size_t j = i;
        while (j < line.size() && line[j] != ',' && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
        double v = 0.0;
        const auto [end, ec] = std::from_chars(line.data() + i, line.data() + j, v);
        if (ec != std::errc() || end != line.data() + j || !std::isfinite(v))
            throw Error(FileLoc{path, line_no, static_cast<int>(i) + 1},
                        "expected a finite number, got '" + line.substr(i, j - i) + "'");
        out.push_back(v);
        i = j;
    }
    return out;
}

}  // namespace

std::vector<std::array<Vec3, 16>> read_bezier_file(const std::string& path) {
    const std::string text = read_input_file(path);
    std::vector<std::pair<int, std::string>> lines;  // non-blank lines with their numbers
    std::size_t at = 0;
    for (int no = 1; at <= text.size(); ++no) {
        std::size_t end = text.find('\n', at);
        if (end == std::string::npos) end = text.size();
        const std::string line = text.substr(at, end - at);
        if (line.find_first_not_of(" \t\r,") != std::string::npos) lines.emplace_back(no, line);
        at = end + 1;
    }
    std::size_t next = 0;
    auto take = [&](std::size_t count, const char* what) {
        if (next >= lines.size())
            throw Error(FileLoc{path, lines.empty() ? 1 : lines.back().first, 1},
                        std::string("the file ends where ") + what + " should follow");
        const auto& [no, line] = lines[next++];
        const std::vector<double> v = numbers_of(line, path, no);
        if (v.size() != count)
            throw Error(FileLoc{path, no, 1}, std::string("expected ") + what + " (" + std::to_string(count) +
                                                  " numbers), got " + std::to_string(v.size()));
        return std::make_pair(no, v);
    };
    auto count_of = [&](const char* what, long max) {
        const auto [no, v] = take(1, what);
        if (v[0] != std::floor(v[0]) || v[0] < 1 || v[0] > max)
            throw Error(FileLoc{path, no, 1},
                        std::string(what) + " must be an integer from 1 to " + std::to_string(max));
        return static_cast<int>(v[0]);
    };
    const int patches = count_of("the number of patches", 20000);  // Bézier patches in one file
    std::vector<std::pair<int, std::vector<double>>> index_lines;
    for (int p = 0; p < patches; ++p) index_lines.push_back(take(16, "a patch's 16 point indices"));
    const int points = count_of("the number of points", 1600000);
    std::vector<Vec3> pts;
    for (int k = 0; k < points; ++k) {
        const auto [no, v] = take(3, "a point x, y, z");
        pts.emplace_back(v[0], v[1], v[2]);
    }
    if (next < lines.size())
        throw Error(FileLoc{path, lines[next].first, 1},
                    "unexpected data after the " + std::to_string(points) + " points the file announced");
    std::vector<std::array<Vec3, 16>> out;
    for (const auto& [no, idx] : index_lines) {
        std::array<Vec3, 16> cp;
        for (int k = 0; k < 16; ++k) {
            if (idx[k] != std::floor(idx[k]) || idx[k] < 1 || idx[k] > points)
                throw Error(FileLoc{path, no, 1}, "point index " + std::to_string(k + 1) +
                                                      " must be an integer from 1 to " +
                                                      std::to_string(points) + " (indices are 1-based)");
            cp[k] = pts[static_cast<std::size_t>(idx[k]) - 1];
        }
        out.push_back(cp);
    }
    return out;
}

namespace {

// control_points: 16 points, row by row; or file: a patch file (read_bezier_file), relative to
// the scene file. A patch without area (all its points on a curve) is refused.
std::vector<SurfacePart> read_bezier(YamlMap& m, const std::string& name) {
    std::vector<std::array<Vec3, 16>> patches;
    FileLoc where = m.loc();
    if (m.has("control_points") == m.has("file"))
        throw Error(m.loc(), "bezier '" + name +
                                 "' needs control_points (16 points) or file (a patch file), not both");
    if (m.has("control_points")) {
        const YAML::Node list = m.required("control_points");
        where = loc_of(list, m.file());
        if (!list.IsSequence() || list.size() != 16)
            throw Error(where, "control_points must be a list of 16 points [[x, y, z], ...], row by row");
        std::array<Vec3, 16> cp;
        for (int k = 0; k < 16; ++k)
            cp[k] = yaml_vec3(list[k], m.file(), "control_points[" + std::to_string(k) + "]");
        patches.push_back(cp);
    } else {
        const YAML::Node f = m.required("file");
        where = loc_of(f, m.file());
        const std::string rel = yaml_string(f, m.file(), "file");
        const std::string path = (std::filesystem::path(m.file()).parent_path() / rel).string();
        try {
            patches = read_bezier_file(path);
        } catch (const Error& e) {
            if (e.loc()) throw;
            throw Error(where, e.message() + " (file is relative to the scene file's folder)");
        }
    }
    std::vector<SurfacePart> parts;
    for (std::size_t k = 0; k < patches.size(); ++k) {
        auto surface = std::make_shared<BezierSurface>(patches[k]);
        const BoundingSphere b = surface->bound(0, 1, 0, 1);
        if (!(surface->area(0, 1, 0, 1) > 1e-12 * b.radius * b.radius))
            throw Error(where, "bezier '" + name + "': patch " + std::to_string(k) +
                                   " has no area (its control points lie on a curve)");
        parts.push_back(
            SurfacePart{patches.size() > 1 ? std::to_string(k) : "", surface, std::nullopt, std::nullopt});
    }
    return parts;
}

}  // namespace

extern const SurfaceType kBezierType;
const SurfaceType kBezierType = {
    .name = "bezier",
    .key_id = 6,
    .keys = "control_points | file",
    .read = nullptr,
    .example = {{"control_points",
                 "[[0,0,0],[1,0,0],[2,0,0],[3,0,0],[0,1,0],[1,1,1],[2,1,1],[3,1,0],"
                 "[0,2,0],[1,2,1],[2,2,1],[3,2,0],[0,3,0],[1,3,0],[2,3,0],[3,3,0]]"}},
    .variants = {{"control_points",
                  "[[0,0,0],[1,0,0],[2,0,0],[3,0,0],[0,1,0],[1,1,2],[2,1,1],[3,1,0],"
                  "[0,2,0],[1,2,1],[2,2,1],[3,2,0],[0,3,0],[1,3,0],[2,3,0],[3,3,0]]"},
                 {"control_points",
                  "[[0,0,0],[1,0,0],[2,0,0],[3,0,0],[0,1,0],[1,1,1],[2,1,1],[3,1,0],"
                  "[0,2,0],[1,2,1],[2,2,1],[3,2,0],[0,3,0],[1,3,0],[2,3,0],[3,3,0.5]]"}},
    .read_parts = read_bezier,
};

}  // namespace radiosa
