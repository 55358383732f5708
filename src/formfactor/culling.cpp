#include "formfactor/culling.h"

#include <algorithm>
#include <array>

#include "util/convex_distance.h"

namespace radiosa {

namespace {

// Signed distance range of a patch from a plane: from its corners for a polygon, exact from
// Surface::linear_range otherwise.
std::pair<double, double> extent(const SceneGeometry& g, const Patch& p, const Plane& plane) {
    if (p.polygon) {
        double lo = plane.signed_distance(p.corners[0]), hi = lo;
        for (int k = 1; k < 4; ++k) {
            const double d = plane.signed_distance(p.corners[k]);
            lo = std::min(lo, d);
            hi = std::max(hi, d);
        }
        return {lo, hi};
    }
    const auto [lo, hi] = g.surface(p.surface).linear_range(plane.normal, p.s0, p.s1, p.t0, p.t1);
    return {lo - plane.offset, hi - plane.offset};
}

}  // namespace

bool segments_through_ball(std::span<const Vec3> a, std::span<const Vec3> b, const BoundingSphere& ball,
                           double eps) {
    constexpr std::size_t kMaxCorners = 8;
    if (a.empty() || b.empty() || a.size() > kMaxCorners || b.size() > kMaxCorners) return false;
    const double r = ball.radius - eps;
    if (!(r > 0.0)) return false;
    std::array<Vec3, kMaxCorners> da, db;  // the corners from the centre
    for (std::size_t i = 0; i < a.size(); ++i) da[i] = a[i] - ball.center;
    for (std::size_t j = 0; j < b.size(); ++j) db[j] = b[j] - ball.center;
    const auto farthest = [&](double t) {  // squared
        double m = 0.0;
        for (std::size_t i = 0; i < a.size(); ++i)
            for (std::size_t j = 0; j < b.size(); ++j) {
                const Vec3 p = (1.0 - t) * da[i] + t * db[j];
                m = std::max(m, glm::dot(p, p));
            }
        return m;
    };
    // The search stops once the bracket is 1e-4 wide: near its minimum the distance moves
    // by less than that fraction of the corners' spread.
    double lo = 0.0, hi = 1.0;
    while (hi - lo > 1e-4) {
        const double t1 = lo + (hi - lo) / 3.0, t2 = hi - (hi - lo) / 3.0;
        const double f1 = farthest(t1), f2 = farthest(t2);
        if (std::min(f1, f2) < r * r) return true;
        if (f1 < f2)
            hi = t2;
        else
            lo = t1;
    }
    return false;
}

Culling::Culling(const SceneGeometry& g) : m_geo(g), m_eps(1e-12 * g.scale()) {
    const Vec3 axes[3] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
    m_surface_axes.resize(static_cast<std::size_t>(g.surface_count()));
    for (int k = 0; k < g.surface_count(); ++k)
        for (int a = 0; a < 3; ++a)
            m_surface_axes[static_cast<std::size_t>(k)][a] =
                g.surface(k).linear_range(axes[a], 0.0, 1.0, 0.0, 1.0);
    m_patch_axes.resize(static_cast<std::size_t>(g.patch_count()));
    for (int i = 0; i < g.patch_count(); ++i) {
        const Patch& p = g.patch(i);
        for (int a = 0; a < 3; ++a)
            m_patch_axes[static_cast<std::size_t>(i)][a] =
                g.surface(p.surface).linear_range(axes[a], p.s0, p.s1, p.t0, p.t1);
    }
}

// True when no energy can pass between the two patches: either one lies entirely
// behind or in the plane of the other (this covers patches of one planar surface), or
// both are patches of one surface that cannot see itself, or of the two sides of a surface.
bool Culling::culled(int i, int j) const {
    const Patch& pi = m_geo.patch(i);
    const Patch& pj = m_geo.patch(j);
    if (pi.surface == pj.surface && !m_geo.surface(pi.surface).sees_itself()) return true;
    // The two sides of a surface whose chords stay off it (a plane, a ball's or a cylinder's
    // boundary) face away from each other.
    if (m_geo.twin(pi.surface) == pj.surface && m_geo.surface(pi.surface).chords_never_cross()) return true;
    if (auto pl = m_geo.surface(pi.surface).plane(); pl && extent(m_geo, pj, *pl).second <= m_eps)
        return true;
    // A polygon that sees only the back of a curved patch (Surface::seen_once_from): every
    // point of each lies behind the other's tangent planes.
    if (sees_only_back(pi, pj) || sees_only_back(pj, pi)) return true;
    if (auto pl = m_geo.surface(pj.surface).plane(); pl && extent(m_geo, pi, *pl).second <= m_eps)
        return true;
    return false;
}

bool Culling::sees_only_back(const Patch& a, const Patch& b) const {
    const Surface& sb = m_geo.surface(b.surface);
    return a.polygon && !sb.plane() && !sb.sphere() &&
           sb.seen_once_from(a.corners, b.s0, b.s1, b.t0, b.t1) == -1;
}

// True when surface s provably keeps clear of every segment between the two polygon
// patches: those segments fill the convex hull of their 8 corners, and a sphere farther
// from it than its radius, or a planar convex polygon at a positive distance, meets none.
bool Culling::hull_misses(const Patch& pi, const Patch& pj, const Surface& s) const {
    const std::array<Vec3, 8> hull = {pi.corners[0], pi.corners[1], pi.corners[2], pi.corners[3],
                                      pj.corners[0], pj.corners[1], pj.corners[2], pj.corners[3]};
    if (const auto sph = s.sphere()) {
        const std::array<Vec3, 1> c = {sph->center};
        const double margin = sph->radius + m_eps;
        return convex_distance(hull, c, margin) > margin;
    }
    if (s.plane() && s.patches_are_polygons()) {
        const std::array<Vec3, 4> q = {s.point(0, 0), s.point(1, 0), s.point(1, 1), s.point(0, 1)};
        return convex_distance(hull, q, m_eps) > m_eps;
    }
    return false;
}

bool Culling::can_block_any(int i, int b, int k) const {
    const Patch& pi = m_geo.patch(i);
    const Surface& sb = m_geo.surface(b);
    const Surface& sk = m_geo.surface(k);
    if (!pi.polygon || !sb.patches_are_polygons() || k == pi.surface || k == b ||
        m_geo.twin(k) == pi.surface || m_geo.twin(k) == b)
        return true;
    // Every patch of b lies in the quad of b's corners, so every pair's hull lies in this one;
    // the slack keeps rounding from proving here what the pair's own test would not.
    const std::array<Vec3, 8> hull = {pi.corners[0],      pi.corners[1],      pi.corners[2],
                                      pi.corners[3],      sb.point(0.0, 0.0), sb.point(1.0, 0.0),
                                      sb.point(1.0, 1.0), sb.point(0.0, 1.0)};
    const double slack = 1e-9 * m_geo.scale();
    if (const auto sph = sk.sphere()) {
        const std::array<Vec3, 1> c = {sph->center};
        const double margin = sph->radius + m_eps + slack;
        return !(convex_distance(hull, c, margin) > margin);
    }
    if (sk.plane() && sk.patches_are_polygons()) {
        const std::array<Vec3, 4> q = {sk.point(0, 0), sk.point(1, 0), sk.point(1, 1), sk.point(0, 1)};
        return !(convex_distance(hull, q, m_eps + slack) > m_eps + slack);
    }
    return true;
}

// True when a slab between two parallel planes holds both patches and surface k lies outside
// it (touching allowed): then no segment between the patches meets k. The slabs tried are
// normal to the axes and to the line between the patches' centres; the ranges are exact
// (Surface::linear_range), so a table top under a lamp is told apart from the lamp.
bool Culling::slab_separates(int i, int j, int k) const {
    const Patch& pi = m_geo.patch(i);
    const Patch& pj = m_geo.patch(j);
    auto apart = [&](std::pair<double, double> ri, std::pair<double, double> rj,
                     std::pair<double, double> rk) {
        const double lo = std::min(ri.first, rj.first), hi = std::max(ri.second, rj.second);
        return rk.second <= lo + m_eps || rk.first >= hi - m_eps;
    };
    for (int a = 0; a < 3; ++a)
        if (apart(m_patch_axes[static_cast<std::size_t>(i)][a], m_patch_axes[static_cast<std::size_t>(j)][a],
                  m_surface_axes[static_cast<std::size_t>(k)][a]))
            return true;
    const Vec3 between = pj.bound.center - pi.bound.center;
    const double len = glm::length(between);
    const Vec3 a = len > 0.0 ? between / len : Vec3(1, 0, 0);
    return apart(m_geo.surface(pi.surface).linear_range(a, pi.s0, pi.s1, pi.t0, pi.t1),
                 m_geo.surface(pj.surface).linear_range(a, pj.s0, pj.s1, pj.t0, pj.t1),
                 m_geo.surface(k).linear_range(a, 0.0, 1.0, 0.0, 1.0));
}

bool own_surface_clear(const SceneGeometry& g, int a, int b, int k, bool* own) {
    const Surface& s = g.surface(k);
    const bool on_a = a == k, on_b = b == k;
    // The other side of an end's own surface: the same geometry, which the segment leaves
    // from its back.
    const bool back_a = g.twin(k) >= 0 && g.twin(k) == a, back_b = g.twin(k) >= 0 && g.twin(k) == b;
    *own = on_a || on_b || back_a || back_b;
    if ((on_a || back_a) && (on_b || back_b)) return s.chords_never_cross();
    if (on_a || on_b) return s.front_segments_escape();
    if (back_a || back_b) return s.back_segments_escape();
    return false;
}

bool Culling::can_block(int i, int j, int k) const {
    const Patch& pi = m_geo.patch(i);
    const Patch& pj = m_geo.patch(j);
    const Surface& s = m_geo.surface(k);
    bool own = false;
    if (own_surface_clear(m_geo, pi.surface, pj.surface, k, &own)) return false;
    if (auto pl = s.plane(); pl && one_side_of_plane(extent(m_geo, pi, *pl), extent(m_geo, pj, *pl), m_eps))
        return false;
    // Every point of a segment between the patches lies within `reach` of the segment between
    // their bounding centres.
    const double reach = std::max(pi.bound.radius, pj.bound.radius);
    const BoundingSphere& b = m_geo.surface_bound(k);
    if (distance_to_segment(b.center, pi.bound.center, pj.bound.center) > b.radius + reach) return false;
    if (own) return true;
    if (slab_separates(i, j, k)) return false;
    return !(pi.polygon && pj.polygon && hull_misses(pi, pj, s));
}

// Surfaces that might block a segment between the two patches; the rest are proven
// unable to and skip the per-point tests.
void Culling::occluders(int i, int j, bool culling, std::vector<int>* out, FormFactorStats* st) const {
    out->clear();
    for (int k = 0; k < m_geo.surface_count(); ++k) {
        ++st->occluder_checks;
        if (!culling) {
            out->push_back(k);
            continue;
        }
        const bool blocks = can_block(i, j, k);
        // The two sides of a two-sided surface are one set of points: a segment crosses both or
        // neither, so a back side (listed right after its front) is not tested again.
        const bool front_listed =
            m_geo.twin(k) >= 0 && m_geo.twin(k) < k && !out->empty() && out->back() == m_geo.twin(k);
        if (blocks && !front_listed)
            out->push_back(k);
        else if (!blocks)
            ++st->occluders_culled;
    }
    if (out->empty()) ++st->pairs_unoccluded;
}

}  // namespace radiosa
