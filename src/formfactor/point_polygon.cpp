#include "formfactor/point_polygon.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "formfactor/convex_clip.h"

namespace radiosa {

namespace {

constexpr int kMaxVerts = 20;  // inputs of up to 16 vertices, cut by one plane

Vec3 unit_or_zero(const Vec3& v) {
    const double l = glm::length(v);
    return l > 0.0 ? v / l : Vec3(0.0);
}

// The index after k in a cycle of n (no division: these loops are the innermost of every
// shadowed pair).
int next_in_cycle(int k, int n) { return k + 1 == n ? 0 : k + 1; }

// An arc of the spherical polygon's boundary: its angle gamma < pi, and sin(gamma) and
// cos(gamma) up to one positive factor (|a x b| and a . b, which the angle is the atan2 of).
struct ArcAngle {
    double gamma = 0.0, sin = 0.0, cos = 0.0;
};

// Length of the part of the great-circle arc a -> b (unit vectors) inside the cap
// {w : w . d >= cos_a} (cos_a > 0).
double arc_inside_cap(const Vec3& a, const Vec3& b, const ArcAngle& arc, const Vec3& d, double cos_a) {
    const double gamma = arc.gamma;
    if (gamma <= 0.0) return 0.0;
    const Vec3 w = unit_or_zero(b - glm::dot(b, a) * a);
    const double p = glm::dot(a, d), q = glm::dot(w, d);
    const double amp = std::sqrt(p * p + q * q);
    if (amp <= cos_a) return 0.0;
    // Both ends clearly inside the cap: so is the arc (the cap is convex on the sphere). Both
    // clearly outside, and the arc's point nearest d (angle atan2(q, p)) not between them: the
    // arc misses the cap. The margin is far above what rounding moves the angles below, so
    // either answer is the one they give.
    constexpr double kMargin = 1e-12;
    const double pb = glm::dot(b, d);
    if (p >= cos_a + kMargin && pb >= cos_a + kMargin) return gamma;
    if (p <= cos_a - kMargin && pb <= cos_a - kMargin && !(q > 0.0 && p * arc.sin - q * arc.cos > 0.0))
        return 0.0;
    const double phi0 = std::atan2(q, p), delta = std::acos(std::min(1.0, cos_a / amp));
    double len = 0.0;
    for (double shift : {-2 * kPi, 0.0, 2 * kPi}) {
        const double lo = std::max(0.0, phi0 - delta + shift), hi = std::min(gamma, phi0 + delta + shift);
        if (hi > lo) len += hi - lo;
    }
    return len;
}

// Cuts the polygon to x's front half-space n . (y - x) >= 0 (Sutherland-Hodgman), reversing the
// order so that, seen from outside the sphere of directions, the boundary runs counter-clockwise.
int clip_to_front(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                  std::array<Vec3, kMaxVerts>* clipped) {
    int nc = 0;
    for (int k = count - 1; k >= 0; --k) {
        const Vec3& a = v[k];
        const Vec3& b = v[k == 0 ? count - 1 : k - 1];
        const double da = glm::dot(n, a - x), db = glm::dot(n, b - x);
        if (da >= 0.0) (*clipped)[nc++] = a;
        if ((da >= 0.0) != (db >= 0.0) && nc < kMaxVerts) (*clipped)[nc++] = a + (b - a) * (da / (da - db));
    }
    return nc;
}

// A monotone stand-in for the angle t of the unit vector (c, s) in [0, 2 pi), free of
// trigonometry: 0 at t = 0, 2 at pi, 4 at 2 pi, and pi / 2 times it within 0.33 rad of t.
double pseudo_angle(double c, double s) { return s >= 0.0 ? 1.0 - c : 3.0 + c; }

// Adds to `blocked`, term by term, the Lambert integral along the arcs of the cap's boundary circle, w(t) =
// cos_a d + sin_a (cos t e1 + sin t e2), that lie inside the spherical polygon whose edges' great
// circles have the normals mk[0..nc) (w[k] x w[k + 1], pointing inside). The
// circle is cut where it crosses the polygon's edges' great circles; every cut is a unit vector
// (cos t, sin t) found by algebra, the pieces are ordered by pseudo_angle, and only a piece that
// is inside takes one atan2 (its angle): this is the innermost loop of every shadowed pair.
double add_cap_circle_inside(double blocked, const std::array<Vec3, kMaxVerts>& mk, int nc, const Vec3& n,
                             const Vec3& d, double sin_a, double cos_a) {
    const Vec3 e1 =
        unit_or_zero(std::abs(d.x) < 0.9 ? glm::cross(d, Vec3(1, 0, 0)) : glm::cross(d, Vec3(0, 1, 0)));
    const Vec3 e2 = glm::cross(d, e1);
    struct CutPoint {
        double key, c, s;
    };
    std::array<CutPoint, 2 * kMaxVerts> cuts;
    int ncuts = 0;
    for (int k = 0; k < nc; ++k) {
        const double a0 = glm::dot(d, mk[k]), b1 = glm::dot(e1, mk[k]), b2 = glm::dot(e2, mk[k]);
        const double amp = std::sqrt(b1 * b1 + b2 * b2);
        if (amp * sin_a <= std::abs(a0) * cos_a)
            continue;  // the circle does not cross this edge's great circle
        // w(t) . m_k = 0 at t = t_k -+ beta: cos(t_k) = b1 / amp, cos(beta) = -cos_a a0 / (sin_a amp).
        const double ck = b1 / amp, sk = b2 / amp;
        const double cb = std::clamp(-cos_a * a0 / (sin_a * amp), -1.0, 1.0), sb = std::sqrt(1.0 - cb * cb);
        for (const double sign : {1.0, -1.0}) {
            const double c = ck * cb + sign * sk * sb, s = sk * cb - sign * ck * sb;
            cuts[ncuts++] = {pseudo_angle(c, s), c, s};
        }
    }
    auto inside = [&](double c, double s) {
        const Vec3 wm = cos_a * d + sin_a * (c * e1 + s * e2);
        for (int k = 0; k < nc; ++k)
            if (glm::dot(wm, mk[k]) < 0.0) return false;
        return true;
    };
    if (ncuts == 0) return inside(1.0, 0.0) ? blocked + 2 * kPi * sin_a * sin_a * glm::dot(n, d) : blocked;
    std::sort(cuts.begin(), cuts.begin() + ncuts,
              [](const CutPoint& a, const CutPoint& b) { return a.key < b.key; });
    for (int c = 0; c < ncuts; ++c) {
        const CutPoint& p1 = cuts[c];
        const CutPoint& p2 = cuts[next_in_cycle(c, ncuts)];
        const double dkey = c + 1 < ncuts ? p2.key - p1.key : p2.key + 4.0 - p1.key;
        if (!(dkey > 0.0)) continue;
        const double sy = p1.c * p2.s - p1.s * p2.c, cy = p1.c * p2.c + p1.s * p2.s;
        // The piece's angle: atan2's branch nearest the pseudo-angles' rough measure of it.
        auto angle = [&] {
            const double raw = std::atan2(sy, cy);
            return raw + 2 * kPi * std::round((0.5 * kPi * dkey - raw) / (2 * kPi));
        };
        // Its middle: the bisector of its ends (their sum, or its opposite past a half turn),
        // by rotation where the two nearly cancel.
        double mc = p1.c + p2.c, ms = p1.s + p2.s;
        const double ml = std::sqrt(mc * mc + ms * ms);
        double delta = std::numeric_limits<double>::quiet_NaN();
        if (ml > 0.25 && std::abs(sy) > 1e-6) {
            // Clear of a half turn (the ends do not nearly cancel) and of a point or a whole
            // turn: the sign of its sine says on which side of a half turn the angle lies (the
            // pseudo-angles are within 0.66 rad of it), and the angle waits until the piece
            // is known to lie inside.
            const double f = (sy < 0.0 ? -1.0 : 1.0) / ml;
            mc *= f, ms *= f;
        } else {
            delta = angle();
            if (!(delta > 0.0)) continue;
            if (ml > 0.25) {
                const double f = (delta > kPi ? -1.0 : 1.0) / ml;
                mc *= f, ms *= f;
            } else {
                const double h = 0.5 * delta, ch = std::cos(h), sh = std::sin(h);
                mc = p1.c * ch - p1.s * sh, ms = p1.s * ch + p1.c * sh;
            }
        }
        if (!inside(mc, ms)) continue;
        if (std::isnan(delta)) delta = angle();
        const Vec3 integral =
            cos_a * sin_a * ((p2.c - p1.c) * e2 - (p2.s - p1.s) * e1) + sin_a * sin_a * delta * d;
        blocked += glm::dot(n, integral);
    }
    return blocked;
}

// The polygon as seen from x: its front part's vertex directions w, the normals m = w[k] x
// w[k + 1] of its edges' great circles and their unit vectors u (with |m|, the sine of each
// edge's angle), and (once measure() has run) the angles and Lambert's integral over it (2 pi
// times the unblocked form factor). Each cross product is taken once: measure() and the cap's
// circle reuse them.
struct SphericalPolygon {
    std::array<Vec3, kMaxVerts> w, u, m;
    std::array<ArcAngle, kMaxVerts> arc{};
    int nc = 0;
    double whole = 0.0;
    bool measured = false;
};

// The edges' angles and Lambert's integral: sum over edges of (arc angle) * n . (unit normal
// of the arc's great circle). Left until needed: a point the blocker misses needs neither.
void measure(const Vec3& n, SphericalPolygon* sp) {
    if (sp->measured) return;
    sp->measured = true;
    sp->whole = 0.0;
    for (int k = 0; k < sp->nc; ++k) {
        const Vec3& a = sp->w[k];
        const Vec3& b = sp->w[next_in_cycle(k, sp->nc)];
        ArcAngle& arc = sp->arc[k];  // arc.sin is |m[k]|, from project()
        arc.cos = glm::dot(a, b);
        arc.gamma = std::atan2(arc.sin, arc.cos);  // accurate for small and large angles
        sp->whole += arc.gamma * glm::dot(n, sp->u[k]);
    }
}

// False when x sees nothing of the polygon (behind it, or the polygon behind x).
bool project(const Vec3& x, const Vec3& n, const Vec3* v, int count, SphericalPolygon* sp) {
    // Front side of the polygon (Newell normal, robust for any planar polygon).
    Vec3 m(0.0);
    for (int k = 0; k < count; ++k) m += glm::cross(v[k], v[next_in_cycle(k, count)]);
    if (glm::dot(m, x - v[0]) <= 0.0) return false;

    std::array<Vec3, kMaxVerts> clipped;
    sp->nc = clip_to_front(x, n, v, count, &clipped);
    if (sp->nc < 3) return false;
    for (int k = 0; k < sp->nc; ++k) sp->w[k] = unit_or_zero(clipped[k] - x);

    for (int k = 0; k < sp->nc; ++k) {
        sp->m[k] = glm::cross(sp->w[k], sp->w[next_in_cycle(k, sp->nc)]);
        sp->arc[k].sin = glm::length(sp->m[k]);
        sp->u[k] = sp->arc[k].sin > 0.0 ? sp->m[k] / sp->arc[k].sin : Vec3(0.0);
    }
    sp->measured = false;
    return true;
}

// Lambert's integral over the part of the spherical polygon inside the blocker's cone (a cap
// around d with half-angle alpha): 2 pi times the form factor the blocker takes away.
double blocked_part(SphericalPolygon& sp, const Vec3& x, const Vec3& n, const BoundingSphere& blocker) {
    const Vec3 to_c = blocker.center - x;
    const double dist = glm::length(to_c);
    if (!(dist > blocker.radius)) return 0.0;
    const Vec3 d = to_c / dist;
    const double sin_a = blocker.radius / dist, cos_a = std::sqrt(std::max(0.0, 1.0 - sin_a * sin_a));
    // Quick answers: the cap wholly outside one edge's great circle (nothing blocked), or
    // wholly inside all of them (the whole cap, sin^2(alpha) n . d).
    bool inside_all = true;
    for (int k = 0; k < sp.nc; ++k) {
        const double side = glm::dot(d, sp.u[k]);
        if (side <= -sin_a) return 0.0;
        inside_all = inside_all && side >= sin_a;
    }
    if (inside_all) return 2.0 * kPi * sin_a * sin_a * glm::dot(n, d);
    measure(n, &sp);
    // The polygon wholly inside the cap (every vertex is: a cap narrower than a hemisphere is
    // convex on the sphere): all of it is blocked. The umbra of a ball larger than the polygon
    // it hides, the common case on a shadowed pair's patch.
    bool vertices_inside = true;
    for (int k = 0; k < sp.nc && vertices_inside; ++k) vertices_inside = glm::dot(sp.w[k], d) >= cos_a;
    if (vertices_inside) return sp.whole;
    double blocked = 0.0;
    // (1) polygon edges inside the cap.
    bool edge_inside = false;
    for (int k = 0; k < sp.nc; ++k) {
        const double len = arc_inside_cap(sp.w[k], sp.w[next_in_cycle(k, sp.nc)], sp.arc[k], d, cos_a);
        edge_inside = edge_inside || len > 0.0;
        blocked += len * glm::dot(n, sp.u[k]);
    }
    // No edge enters the cap and its centre lies outside an edge: the two are apart (seen past
    // a corner of the polygon, where no edge's great circle separates them).
    if (!edge_inside) {
        for (int k = 0; k < sp.nc; ++k)
            if (glm::dot(d, sp.u[k]) < 0.0) return 0.0;
    }
    // (2) arcs of the cap's circle inside the polygon.
    return add_cap_circle_inside(blocked, sp.m, sp.nc, n, d, sin_a, cos_a);
}

}  // namespace

double point_to_polygon(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                        const BoundingSphere* blocker) {
    if (count < 3 || count > 16) return 0.0;
    SphericalPolygon sp;
    if (!project(x, n, v, count, &sp)) return 0.0;
    measure(n, &sp);
    const double blocked = blocker ? blocked_part(sp, x, n, *blocker) : 0.0;
    return std::max(0.0, (sp.whole - blocked) / (2.0 * kPi));
}

namespace {
// The form factor the blocker takes away from the projected polygon sp, in [0, unblocked].
double blocked_factor(SphericalPolygon& sp, const Vec3& x, const Vec3& n, const BoundingSphere& blocker) {
    const double blocked = blocked_part(sp, x, n, blocker);
    if (blocked == 0.0) return 0.0;  // the blocker misses: the polygon's angles are not needed
    measure(n, &sp);
    return std::clamp(blocked / (2.0 * kPi), 0.0, std::max(0.0, sp.whole / (2.0 * kPi)));
}
}  // namespace

double point_to_polygon_blocked(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                const BoundingSphere& blocker) {
    SphericalPolygon sp;
    if (!project(x, n, v, count, &sp)) return 0.0;
    return blocked_factor(sp, x, n, blocker);
}

namespace {

// A cone of directions from x around the unit vector d, of half-angle alpha < pi / 2.
struct Cone {
    Vec3 d;
    double sin_a, cos_a;
    bool contains(const Vec3& w) const { return glm::dot(w, d) > cos_a; }
};

// The parts of edge k's arc (angles phi in [0, gamma) from w[k] toward w[k + 1]) inside some
// cone: their union's length.
double edge_inside_cones(const SphericalPolygon& sp, int k, const std::array<Cone, kMaxBallUnion>& cones,
                         int nk) {
    const double gamma = sp.arc[k].gamma;
    if (!(gamma > 0.0)) return 0.0;
    const Vec3& a = sp.w[k];
    const Vec3& b = sp.w[next_in_cycle(k, sp.nc)];
    const Vec3 wv = unit_or_zero(b - glm::dot(b, a) * a);
    std::array<std::pair<double, double>, 3 * kMaxBallUnion> spans;
    int ns = 0;
    for (int c = 0; c < nk; ++c) {
        const double p = glm::dot(a, cones[c].d), q = glm::dot(wv, cones[c].d);
        const double amp = std::sqrt(p * p + q * q);
        if (amp <= cones[c].cos_a) continue;
        const double phi0 = std::atan2(q, p), delta = std::acos(std::min(1.0, cones[c].cos_a / amp));
        for (double shift : {-2 * kPi, 0.0, 2 * kPi}) {
            const double lo = std::max(0.0, phi0 - delta + shift), hi = std::min(gamma, phi0 + delta + shift);
            if (hi > lo) spans[ns++] = {lo, hi};
        }
    }
    std::sort(spans.begin(), spans.begin() + ns);
    double len = 0.0, end = 0.0;
    for (int k2 = 0; k2 < ns; ++k2) {
        const double lo = std::max(spans[k2].first, end);
        if (spans[k2].second > lo) len += spans[k2].second - lo;
        end = std::max(end, spans[k2].second);
    }
    return len;
}

// Lambert's integral along the arcs of cone c's circle inside the polygon and outside every other
// cone: the circle w(t) = cos_a d + sin_a (cos t e1 + sin t e2) is cut where it crosses an edge's
// great circle or another cone's circle, and each piece is kept or not by its middle.
double circle_outside_others(const SphericalPolygon& sp, const Vec3& n,
                             const std::array<Cone, kMaxBallUnion>& cones, int nk, int c) {
    const Cone& o = cones[c];
    const Vec3 e1 =
        unit_or_zero(std::abs(o.d.x) < 0.9 ? glm::cross(o.d, Vec3(1, 0, 0)) : glm::cross(o.d, Vec3(0, 1, 0)));
    const Vec3 e2 = glm::cross(o.d, e1);
    std::array<double, 2 * (kMaxVerts + kMaxBallUnion)> cuts;
    int ncuts = 0;
    // w(t) . m = rhs for a unit m: sin_a (b1 cos t + b2 sin t) = rhs - cos_a (d . m).
    const auto cut_by = [&](const Vec3& m, double rhs) {
        const double a0 = glm::dot(o.d, m), b1 = glm::dot(e1, m), b2 = glm::dot(e2, m);
        const double amp = std::sqrt(b1 * b1 + b2 * b2) * o.sin_a;
        const double r = rhs - o.cos_a * a0;
        if (!(amp > std::abs(r))) return;
        const double tk = std::atan2(b2, b1), beta = std::acos(r / amp);
        cuts[ncuts++] = tk - beta;
        cuts[ncuts++] = tk + beta;
    };
    for (int k = 0; k < sp.nc; ++k) cut_by(sp.u[k], 0.0);
    for (int k = 0; k < nk; ++k)
        if (k != c) cut_by(cones[k].d, cones[k].cos_a);
    const auto kept = [&](double t) {
        const Vec3 w = o.cos_a * o.d + o.sin_a * (std::cos(t) * e1 + std::sin(t) * e2);
        for (int k = 0; k < sp.nc; ++k)
            if (glm::dot(w, sp.u[k]) < 0.0) return false;
        for (int k = 0; k < nk; ++k)
            if (k != c && cones[k].contains(w)) return false;
        return true;
    };
    // int n . (w x dw) over t in [t1, t2].
    const auto piece = [&](double t1, double t2) {
        const double c1 = std::cos(t1), s1 = std::sin(t1), c2 = std::cos(t2), s2 = std::sin(t2);
        const Vec3 integral =
            o.cos_a * o.sin_a * ((c2 - c1) * e2 - (s2 - s1) * e1) + o.sin_a * o.sin_a * (t2 - t1) * o.d;
        return glm::dot(n, integral);
    };
    if (ncuts == 0) return kept(0.0) ? 2 * kPi * o.sin_a * o.sin_a * glm::dot(n, o.d) : 0.0;
    for (int k = 0; k < ncuts; ++k) cuts[k] -= 2 * kPi * std::floor(cuts[k] / (2 * kPi));
    std::sort(cuts.begin(), cuts.begin() + ncuts);
    double sum = 0.0;
    for (int k = 0; k < ncuts; ++k) {
        const double t1 = cuts[k], t2 = k + 1 < ncuts ? cuts[k + 1] : cuts[0] + 2 * kPi;
        if (t2 > t1 && kept(0.5 * (t1 + t2))) sum += piece(t1, t2);
    }
    return sum;
}

}  // namespace

double point_to_polygon_blocked_by_balls(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                                         const BoundingSphere* balls, int ball_count) {
    if (ball_count < 1 || ball_count > static_cast<int>(kMaxBallUnion) || count < 3 || count > 16) return 0.0;
    SphericalPolygon sp;
    if (!project(x, n, v, count, &sp)) return 0.0;
    // The cones that reach into the polygon (a cone wholly outside one edge's great circle
    // cannot).
    std::array<Cone, kMaxBallUnion> cones;
    int nk = 0, last = -1;
    for (int b = 0; b < ball_count; ++b) {
        // The same ball twice (the two sides of a two-sided sphere) is one cone.
        bool again = false;
        for (int e = 0; e < b && !again; ++e)
            again = balls[e].center == balls[b].center && balls[e].radius == balls[b].radius;
        if (again) continue;
        const Vec3 to_c = balls[b].center - x;
        const double dist = glm::length(to_c);
        if (!(dist > balls[b].radius)) continue;
        const double sin_a = balls[b].radius / dist;
        const Cone cone{to_c / dist, sin_a, std::sqrt(std::max(0.0, 1.0 - sin_a * sin_a))};
        bool reaches = true;
        for (int k = 0; k < sp.nc && reaches; ++k) reaches = glm::dot(cone.d, sp.u[k]) > -sin_a;
        if (reaches) cones[nk++] = cone, last = b;
    }
    if (nk == 0) return 0.0;
    if (nk == 1) return blocked_factor(sp, x, n, balls[last]);  // point_to_polygon_blocked's value
    measure(n, &sp);
    double blocked = 0.0;
    for (int k = 0; k < sp.nc; ++k) blocked += edge_inside_cones(sp, k, cones, nk) * glm::dot(n, sp.u[k]);
    for (int c = 0; c < nk; ++c) blocked += circle_outside_others(sp, n, cones, nk, c);
    return std::clamp(blocked / (2.0 * kPi), 0.0, std::max(0.0, sp.whole / (2.0 * kPi)));
}

namespace {

// A convex polygon being cut, with room for the vertices cuts add.
using Poly = PolygonBuffer<16>;

Vec3 centroid(const Poly& p) {
    Vec3 c(0.0);
    for (int k = 0; k < p.n; ++k) c += p.v[k];
    return c / double(p.n);
}

// The convex polygon a cut by every edge of the convex polygon b, both on the plane with unit
// normal m: their intersection.
Poly intersect_in_plane(Poly a, const Poly& b, const Vec3& m) {
    const Vec3 cb = centroid(b);
    for (int k = 0; k < b.n && a.n >= 3; ++k) {
        const Vec3 e = b.v[(k + 1) % b.n] - b.v[k];
        Vec3 inward = glm::cross(m, e);
        if (glm::dot(inward, cb - b.v[k]) < 0.0) inward = -inward;
        a = clip_half_space(a, inward, b.v[k]);
    }
    return a;
}

}  // namespace

double point_to_polygon_hidden(const Vec3& x, const Vec3& n, const Vec3* v, int count,
                               const std::vector<std::array<Vec3, 4>>& occluders) {
    if (count < 3 || count > 8 || occluders.empty() || occluders.size() > kMaxFlatOccluders) return 0.0;
    Vec3 m(0.0);
    for (int k = 0; k < count; ++k) m += glm::cross(v[k], v[(k + 1) % count]);
    const double ml = glm::length(m);
    if (!(ml > 0.0)) return 0.0;
    m /= ml;
    const double hx = glm::dot(m, x - v[0]);
    if (!(hx > 0.0)) return 0.0;
    Poly target;
    for (int k = 0; k < count; ++k) target.v[target.n++] = v[k];
    const Vec3 cj = centroid(target);
    // Each occluder cut to the pyramid from x over the polygon and to the near side of its
    // plane (beyond it nothing blocks), then projected from x onto the plane: a convex polygon
    // inside the target.
    std::vector<Poly> shadows;
    for (const auto& occ : occluders) {
        Poly p;
        for (const Vec3& c : occ) p.v[p.n++] = c;
        for (int k = 0; k < count && p.n >= 3; ++k) {
            Vec3 side = glm::cross(v[k] - x, v[(k + 1) % count] - x);
            if (glm::dot(side, cj - x) < 0.0) side = -side;
            p = clip_half_space(p, side, x);
        }
        if (p.n >= 3) p = clip_half_space(p, m, v[0]);
        if (p.n < 3) continue;
        bool ok = true;
        for (int k = 0; k < p.n && ok; ++k) {
            const double depth = hx - glm::dot(m, p.v[k] - v[0]);
            ok = depth > 1e-12 * hx;
            if (ok) p.v[k] = x + (p.v[k] - x) * (hx / depth);
        }
        if (ok) shadows.push_back(p);
    }
    // The union of the shadows by inclusion and exclusion over their intersections.
    double hidden = 0.0;
    const int ns = static_cast<int>(shadows.size());
    for (int mask = 1; mask < (1 << ns); ++mask) {
        Poly inter;
        int bits = 0;
        for (int k = 0; k < ns; ++k) {
            if (!(mask & (1 << k))) continue;
            inter = bits++ == 0 ? shadows[k] : intersect_in_plane(inter, shadows[k], m);
            if (inter.n < 3) break;
        }
        if (inter.n < 3) continue;
        // Counter-clockwise about the target's front normal, as point_to_polygon expects.
        Vec3 pm(0.0);
        for (int k = 0; k < inter.n; ++k) pm += glm::cross(inter.v[k], inter.v[(k + 1) % inter.n]);
        if (glm::dot(pm, m) < 0.0) std::reverse(inter.v.begin(), inter.v.begin() + inter.n);
        const double f = point_to_polygon(x, n, inter.v.data(), inter.n, nullptr);
        hidden += (bits % 2 == 1 ? f : -f);
    }
    const double open = point_to_polygon(x, n, v, count, nullptr);
    return std::clamp(hidden, 0.0, open);
}

}  // namespace radiosa
