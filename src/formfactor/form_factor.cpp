#include "formfactor/form_factor.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>

#include "formfactor/blocker_set.h"
#include "formfactor/contour_receiver.h"
#include "formfactor/cubature.h"
#include "formfactor/culling.h"
#include "formfactor/events.h"
#include "formfactor/point_polygon.h"
#include "formfactor/polygon_polygon.h"
#include "formfactor/sphere_receiver.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/convex_distance.h"
#include "util/gauss_legendre.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {

// Adds the time between its construction and destruction (one pair's work) to
// stats->seconds_by_surface, half to each patch's surface.
class PairClock {
public:
    PairClock(const SceneGeometry& g, int i, int j, FormFactorStats* st)
        : m_si(g.patch(i).surface), m_sj(g.patch(j).surface), m_st(st) {
        if (st->seconds_by_surface.empty()) st->seconds_by_surface.assign(g.surface_count(), 0.0);
    }
    PairClock(const PairClock&) = delete;
    PairClock& operator=(const PairClock&) = delete;
    ~PairClock() {
        const double half = 0.5 * m_clock.seconds();
        m_st->seconds_by_surface[static_cast<std::size_t>(m_si)] += half;
        m_st->seconds_by_surface[static_cast<std::size_t>(m_sj)] += half;
    }

private:
    Stopwatch m_clock;
    int m_si, m_sj;
    FormFactorStats* m_st;
};

// The centroid of the points and the largest distance from it.
BoundingSphere bound_of(const std::vector<QuadPoint>& pts) {
    Vec3 c(0.0);
    for (const QuadPoint& p : pts) c += p.x;
    c /= static_cast<double>(std::max<std::size_t>(pts.size(), 1));
    double r2 = 0.0;
    for (const QuadPoint& p : pts) r2 = std::max(r2, glm::dot(p.x - c, p.x - c));
    return {c, std::sqrt(r2)};
}

class Integrator {
public:
    Integrator(const SceneGeometry& g, const FormFactorOptions& o) : m_geo(g), m_opt(o), m_cull(g) {
        // The fixed rule's points of every patch; the error-controlled method makes its own (it
        // uses this class for culling only); at 101,070 patches leaving them out lowered the peak
        // from 4,244 to 4,084 MB (docs/scale.md).
        if (o.method != FormFactorMethod::Fixed) return;
        const GaussRule rule = gauss_legendre(o.gauss_points);
        const GaussRule offset_rule = gauss_legendre(o.gauss_points + 1);
        m_points.resize(g.patch_count());
        m_self_points.resize(g.patch_count());
        for (int i = 0; i < g.patch_count(); ++i) {
            const Patch& p = g.patch(i);
            const Surface& surf = g.surface(p.surface);
            m_points[i] = quadrature_points(surf, p, rule);
            // A patch that sees itself is integrated against a rule with other nodes, so no
            // term pairs a point with itself (L = 0).
            if (surf.sees_itself()) m_self_points[i] = quadrature_points(surf, p, offset_rule);
        }
    }

    bool culled(int i, int j) const { return m_opt.culling && m_cull.culled(i, j); }
    double eps() const { return m_cull.eps(); }  // lengths below this are zero at the scene's scale
    void occluders(int i, int j, std::vector<int>* out, FormFactorStats* st) const {
        m_cull.occluders(i, j, m_opt.culling, out, st);
    }

    // The double integral of the symmetric kernel: G_ij = pi A_i F_ij = pi A_j F_ji.
    double integrate(const std::vector<QuadPoint>& a_pts, const std::vector<QuadPoint>& b_pts,
                     const std::vector<int>& blockers, FormFactorStats* st) const {
        // Segment ends are excluded from the occlusion test by this fraction of their length.
        constexpr double kEndEps = 1e-9;
        const BlockerSet guard(m_geo, m_opt.visibility ? blockers : std::vector<int>{});
        // The ball holding b's nodes: a blocker far from every segment from a node a to it is
        // left out of that node's tests.
        BoundingSphere ends{Vec3(0.0), 0.0};
        if (!guard.empty()) ends = bound_of(b_pts);
        double sum = 0.0;
        long long tests = 0;
        for (const QuadPoint& a : a_pts) {
            const std::uint64_t mask = guard.empty() ? 0 : guard.near(a.x, ends.center, ends.radius);
            for (const QuadPoint& b : b_pts) {
                const Vec3 e = b.x - a.x;
                const double ci = glm::dot(a.nw, e);
                if (ci <= 0.0) continue;  // b is behind a's tangent plane (or on it)
                const double cj = -glm::dot(b.nw, e);
                if (cj <= 0.0) continue;
                if (!guard.empty() && guard.blocked(a.x, e, kEndEps, 1.0 - kEndEps, &tests, mask)) continue;
                const double l2 = glm::dot(e, e);
                sum += ci * cj / (l2 * l2);
            }
        }
        st->segment_tests += tests;
        return sum;
    }

    // F(i, j) and F(j, i), j >= i, into entries that hold zeros (they are zeroed first).
    void pair(int i, int j, PairEntries* out, std::vector<int>& blockers, FormFactorStats* st) const {
        *out = PairEntries{};
        ++st->pairs;
        const bool self = i == j;
        if (self ? m_self_points[i].empty() : culled(i, j)) {
            if (!self) ++st->pairs_culled;
            return;
        }
        const PairClock clock(m_geo, i, j, st);  // pairs proven zero cost nothing worth timing
        occluders(i, j, &blockers, st);
        const double g = integrate(m_points[i], self ? m_self_points[i] : m_points[j], blockers, st);
        out->f_ij = g / (kPi * m_geo.patch(i).area);
        if (!self) out->f_ji = g / (kPi * m_geo.patch(j).area);
    }

private:
    const SceneGeometry& m_geo;
    const FormFactorOptions& m_opt;
    std::vector<std::vector<QuadPoint>> m_points, m_self_points;
    Culling m_cull;
};

// ---- error-controlled form factors ----

class AdaptiveIntegrator {
public:
    AdaptiveIntegrator(const SceneGeometry& g, const FormFactorOptions& o, const Integrator& base)
        : m_geo(g),
          m_opt(o),
          m_base(base),
          m_outer(gauss_legendre(4)),
          m_inner(gauss_legendre(5)),
          m_inner_fine(gauss_legendre(7)) {}

    // The planar polygon of patch j, counter-clockwise about its front normal.
    std::array<Vec3, 4> polygon(int j) const { return m_geo.front_polygon(j); }

    // A_i F_ij = A_j F_ji exactly (to round-off, with its rounding estimate), when a closed
    // form covers the pair: two polygons nothing can come between (the contour integral), or two
    // patches of the inside of one sphere with nothing in the way (every point sees every other
    // at cos_i cos_j / (pi r^2) = 1 / (4 pi R^2), so F_ij = A_j / (4 pi R^2), F_ii included).
    std::optional<Estimate> closed_form(int i, int j, const std::vector<int>& blockers) const {
        if (const auto e = nested_spheres(m_geo, i, j, blockers, m_opt.visibility)) return e;
        if (m_opt.visibility && !blockers.empty()) return std::nullopt;
        const Patch& pi = m_geo.patch(i);
        const Patch& pj = m_geo.patch(j);
        Estimate e;
        if (pi.polygon && pj.polygon && i != j) {
            const std::array<Vec3, 4> a = polygon(i), b = polygon(j);
            const PolygonPair p = polygon_to_polygon(a.data(), 4, b.data(), 4);
            e.value = p.value;
            e.error = p.error;
            return e;
        }
        const Surface& s = m_geo.surface(pi.surface);
        if (pi.surface != pj.surface || !s.sees_itself()) return std::nullopt;
        if (const auto sph = s.sphere()) {
            e.value = pi.area * pj.area / (4.0 * kPi * sph->radius * sph->radius);
            e.error = 8 * std::numeric_limits<double>::epsilon() * e.value;
            return e;
        }
        return std::nullopt;
    }

    // What may block the pair on the semi-analytic path: balls whose shadows never overlap as
    // seen from patch i (so the parts they hide add up), or a few flat quads.
    struct Shadow {
        std::vector<BoundingSphere> spheres;
        std::vector<std::array<Vec3, 4>> flats;  // each occluder's outline
    };
    static constexpr std::size_t kMaxShadowBalls = 8;

    // Whether two balls' shadows are apart from every point x of a patch in the ball `patch`
    // (centre p, radius rho): from x, the directions to their centres must be further apart
    // than the sum of the balls' angular radii. From x instead of p, the direction to a centre
    // at distance L turns by at most asin(rho / L), and a ball of radius r looks at most
    // asin(r / (L - rho)) wide.
    static bool shadows_apart(const BoundingSphere& patch, const BoundingSphere& a, const BoundingSphere& b) {
        const Vec3 da = a.center - patch.center, db = b.center - patch.center;
        const double la = glm::length(da), lb = glm::length(db);
        if (!(la - patch.radius > a.radius && lb - patch.radius > b.radius)) return false;
        const double apart = std::acos(std::clamp(glm::dot(da, db) / (la * lb), -1.0, 1.0));
        const double turn = std::asin(patch.radius / la) + std::asin(patch.radius / lb);
        const double wide =
            std::asin(a.radius / (la - patch.radius)) + std::asin(b.radius / (lb - patch.radius));
        return apart - turn - wide > 1e-9;
    }

    // Can F_ij use the closed-form inner integral? j must be planar and nothing may block the
    // pair except balls that lie wholly between patch i and j's plane, whose shadows from
    // patch i never overlap (at most kMaxShadowBalls), or at most kMaxFlatOccluders planar
    // convex quads (whose shadows on j are polygons).
    bool semi_analytic(int i, int j, const std::vector<int>& blockers, Shadow* shadow) const {
        const Patch& pj = m_geo.patch(j);
        if (!pj.polygon) return false;
        *shadow = Shadow{};
        if (!m_opt.visibility || blockers.empty()) return true;
        const Patch& pi = m_geo.patch(i);
        if (blockers.size() <= kMaxFlatOccluders) {
            for (int k : blockers) {
                const Surface& s = m_geo.surface(k);
                if (!s.plane() || !s.patches_are_polygons() || k == pi.surface) {
                    shadow->flats.clear();
                    break;
                }
                shadow->flats.push_back({s.point(0, 0), s.point(1, 0), s.point(1, 1), s.point(0, 1)});
            }
            if (!shadow->flats.empty()) return true;
        }
        if (blockers.size() > kMaxShadowBalls) return false;
        const auto plane = m_geo.surface(pj.surface).plane();
        if (!plane) return false;
        for (int k : blockers) {
            // A solid ball: a whole sphere (a dome's shadow is not a cap).
            const auto sph = m_geo.surface(k).sphere();
            if (!sph || !m_geo.surface(k).whole_sphere() || k == pi.surface ||
                plane->signed_distance(sph->center) < sph->radius)
                return false;
            // Every point of patch i must lie outside the sphere: exactly for a polygon, by its
            // bounding sphere otherwise.
            if (pi.polygon ? distance_to_polygon(sph->center, polygon(i)) <= sph->radius
                           : glm::length(pi.bound.center - sph->center) <= sph->radius + pi.bound.radius)
                return false;
            for (const BoundingSphere& other : shadow->spheres)
                if (!shadows_apart(pi.bound, other, *sph)) return false;
            shadow->spheres.push_back(*sph);
        }
        return true;
    }

    // A_i F_ij with the inner integral in closed form; error estimate on the same scale. The
    // target is tol x min(A_i, A_j), not tol x A_i: the energy two patches exchange is then
    // accurate to tol times what the smaller one sends, so a big patch's entry for a tiny
    // emitter (a 1e-8 spark of radiosity 1e8) is as good as the emitter's own row.
    Estimate area_times_f_semi(int i, int j, const Shadow& shadow, double tol) const {
        if ((!shadow.spheres.empty() || !shadow.flats.empty()) && m_geo.patch(i).polygon)
            return area_times_f_shadowed(i, j, shadow, tol);
        const Patch& pi = m_geo.patch(i);
        const Surface& si = m_geo.surface(pi.surface);
        const std::array<Vec3, 4> v = polygon(j);
        const BoundingSphere* b = shadow.spheres.empty() ? nullptr : &shadow.spheres[0];
        auto g = [&](double s, double t) {
            const Vec3 nrm = si.normal(s, t);
            const double da = glm::length(nrm);
            if (!(da > 0.0)) return 0.0;
            const Vec3 x = si.point(s, t);
            double hidden =
                shadow.flats.empty() ? 0.0 : point_to_polygon_hidden(x, nrm / da, v.data(), 4, shadow.flats);
            // The other balls' shadows never overlap the first's or each other's.
            for (std::size_t k = 1; k < shadow.spheres.size(); ++k)
                hidden += point_to_polygon_blocked(x, nrm / da, v.data(), 4, shadow.spheres[k]);
            return da * (point_to_polygon(x, nrm / da, v.data(), 4, b) - hidden);
        };
        // A region much larger than its distance to the receiver may hide a near-singularity
        // between its Gauss nodes (patches a hair apart): split it along the direction in which
        // that distance changes most, until it is no larger than the distance. Touching
        // patches (distance 0) are left to the error estimate: their integrand is bounded.
        EventSet events;
        if (!pi.polygon) {
            events.add_horizons(v);
            // Points of a curved patch may pass behind the receiver's plane.
            events.add_plane(glm::cross(v[1] - v[0], v[2] - v[0]) + glm::cross(v[2] - v[0], v[3] - v[0]),
                             v[0]);
        }
        for (const BoundingSphere& ball : shadow.spheres) events.add_sphere(v, ball);
        events.add_flats(v, shadow.flats);
        auto geometric = [&](const Rect& r, double fine) {
            // A shadow's edge makes the integrand only once differentiable where it sweeps
            // across the patch; nested estimates on the whole patch can miss that, so shadowed
            // pairs start from quarters.
            if (b || !shadow.flats.empty()) {
                if (const Cut c = quarter_of(Rect{pi.s0, pi.s1, pi.t0, pi.t1}, r); c.dir >= 0) return c;
            }
            if (const Cut c = events.cut_along(si, r); c.dir >= 0) return c;
            // Every node of the region sees nothing, yet an event crosses it: a sliver of it sees
            // the receiver past a horizon (the top of a sphere grazing a long floor). Split it
            // until its nodes find the sliver, down to 1e-6 of the patch. Not under a sphere's
            // shadow: its event crosses the shadowed regions, whose nodes all see nothing, and
            // the search split each of them to the cap (a ball's patches toward the walls past
            // the seed room's sphere: 4,096 regions a pair, 30 s instead of 3.5 s for the room,
            // entries moving by 8e-8 at tolerance 1e-6); the kink test below still refines
            // where a shadow's edge crosses.
            if (fine == 0.0 && !b && !events.empty() &&
                std::max((r.s1 - r.s0) / (pi.s1 - pi.s0), (r.t1 - r.t0) / (pi.t1 - pi.t0)) > 1e-6 &&
                events.crosses(si, r)) {
                const double ls = glm::length(si.point(r.s1, 0.5 * (r.t0 + r.t1)) -
                                              si.point(r.s0, 0.5 * (r.t0 + r.t1))),
                             lt = glm::length(si.point(0.5 * (r.s0 + r.s1), r.t1) -
                                              si.point(0.5 * (r.s0 + r.s1), r.t0));
                return Cut{events.split_toward(si, r, ls >= lt ? 0 : 1)};
            }
            const Vec3 c00 = si.point(r.s0, r.t0), c10 = si.point(r.s1, r.t0), c01 = si.point(r.s0, r.t1),
                       c11 = si.point(r.s1, r.t1);
            const double d00 = distance_to_polygon(c00, v), d10 = distance_to_polygon(c10, v),
                         d01 = distance_to_polygon(c01, v), d11 = distance_to_polygon(c11, v);
            const double dmin = std::min({d00, d10, d01, d11});
            if (!(dmin > 0.0)) return Cut{};
            const double var_s = std::abs(d10 - d00) + std::abs(d11 - d01),
                         var_t = std::abs(d01 - d00) + std::abs(d11 - d10);
            const int dir = var_t > var_s ? 1 : 0;
            const double size = dir == 0 ? std::max(glm::length(c10 - c00), glm::length(c11 - c01))
                                         : std::max(glm::length(c01 - c00), glm::length(c11 - c10));
            return Cut{size > dmin ? dir : -1};
        };
        const double region_tol = tol * std::min(pi.area, m_geo.patch(j).area);
        return adaptive_rect(g, Rect{pi.s0, pi.s1, pi.t0, pi.t1}, region_tol, kMaxOuterRegions, m_outer,
                             geometric, [&](const Rect& r, double fine) {
                                 const double fraction =
                                     shadow.flats.empty() ? kSphereKinkFraction : kFlatKinkFraction;
                                 return std::abs(fine) * fraction > region_tol && events.crosses(si, r);
                             });
    }

    // A_i F_ij for two polygons with a sphere or flat quads between them: the unblocked
    // exchange in closed form (the contour integral) minus the shadow, integrated over patch i
    // with the shadow's inner integral in closed form (a cap of directions for a sphere,
    // projected polygons for quads). The shadow's integrand is free of the near-singularities of
    // patches that touch or nearly touch (those are in the closed form), so what is left to the
    // cubature is smooth except where an occluder's outline meets the polygon's edges.
    Estimate area_times_f_shadowed(int i, int j, const Shadow& shadow, double tol) const {
        const Patch& pi = m_geo.patch(i);
        const Surface& si = m_geo.surface(pi.surface);
        const std::array<Vec3, 4> vi = polygon(i), vj = polygon(j);
        // The unblocked exchange to a share of the pair's tolerance, not to round-off: on the
        // 20,000-patch room most of the hierarchy's time went to this contour integral's last
        // digits, which the shadow's cubature then could not match.
        const double pair_tol = tol * std::min(pi.area, m_geo.patch(j).area);
        const PolygonPair open = polygon_to_polygon(vi.data(), 4, vj.data(), 4, kOpenShare * pair_tol);
        const Vec3 unit = glm::normalize(si.normal(0.5 * (pi.s0 + pi.s1), 0.5 * (pi.t0 + pi.t1)));
        auto g = [&](double s, double t) {
            const double da = glm::length(si.normal(s, t));
            const Vec3 x = si.point(s, t);
            if (shadow.spheres.empty())
                return da * point_to_polygon_hidden(x, unit, vj.data(), 4, shadow.flats);
            double blocked = 0.0;  // the balls' shadows never overlap: their parts add up
            for (const BoundingSphere& ball : shadow.spheres)
                blocked += point_to_polygon_blocked(x, unit, vj.data(), 4, ball);
            return da * blocked;
        };
        // Does some segment from the region to patch j meet an occluder? Every such segment
        // lies in the convex hull of the region's corners and j's.
        // The region is shrunk by 1e-6 of its size first: after a cut along a shadow's edge, the
        // region on the lit side touches that edge's plane and would "reach" at its boundary.
        auto reaches = [&](const Rect& full) {
            const double ds = 1e-6 * (full.s1 - full.s0), dt = 1e-6 * (full.t1 - full.t0);
            const Rect r{full.s0 + ds, full.s1 - ds, full.t0 + dt, full.t1 - dt};
            const std::array<Vec3, 8> hull = {si.point(r.s0, r.t0),
                                              si.point(r.s1, r.t0),
                                              si.point(r.s1, r.t1),
                                              si.point(r.s0, r.t1),
                                              vj[0],
                                              vj[1],
                                              vj[2],
                                              vj[3]};
            for (const BoundingSphere& ball : shadow.spheres) {
                const std::array<Vec3, 1> c = {ball.center};
                if (convex_distance(hull, c, ball.radius) <= ball.radius) return true;
            }
            for (const auto& q : shadow.flats)
                if (convex_distance(hull, q, m_base.eps()) <= m_base.eps()) return true;
            return false;
        };
        // A shadow's edge makes the integrand only once differentiable where it sweeps across
        // the patch: the regions it crosses are cut along it (events) or checked by the 3 x 3
        // split (the kink test below). Forcing quarters on top of that was measured: 1.7x the
        // time on the seed geometry at 344 patches (tolerance 1e-6), and no estimate's cover
        // changed (hard-scene table, validation set, analytic tests: docs/accuracy.md).
        // A region whose nodes all see no shadow although some segment from it to patch j
        // meets an occluder holds a sliver of penumbra between its nodes: split it until they
        // see it (down to 1e-6 of the patch).
        const double s_len = glm::length(si.point(pi.s1, pi.t0) - si.point(pi.s0, pi.t0)),
                     t_len = glm::length(si.point(pi.s0, pi.t1) - si.point(pi.s0, pi.t0));
        EventSet events;
        for (const BoundingSphere& ball : shadow.spheres) events.add_sphere(vj, ball);
        events.add_flats(vj, shadow.flats);
        auto geometric = [&](const Rect& r, double fine) {
            const double ws = (r.s1 - r.s0) / (pi.s1 - pi.s0), wt = (r.t1 - r.t0) / (pi.t1 - pi.t0);
            if (const Cut c = events.cut_along(si, r); c.dir >= 0) return c;
            // No event crossing the region: whether x sees the shadow cannot change inside it.
            if (fine != 0.0 || std::max(ws, wt) < 1e-6 || !reaches(r) || !events.crosses(si, r)) return Cut{};
            return Cut{events.split_toward(si, r, ws * s_len >= wt * t_len ? 0 : 1)};
        };
        const double region_tol = pair_tol - open.error;
        const double fraction = shadow.spheres.empty() ? kFlatKinkFraction : kSphereKinkFraction;
        Estimate hidden =
            adaptive_rect(g, Rect{pi.s0, pi.s1, pi.t0, pi.t1}, region_tol, kMaxOuterRegions, m_outer,
                          geometric, [&](const Rect& r, double fine) {
                              // A region worth less than its tolerance, with an event crossing it and
                              // segments that may meet the occluder, may be the onset of a shadow whose tip
                              // its nodes barely see (measured: nodes saw 3e-13 of 1.1e-9, seed scene at
                              // 1e-10), so its value says nothing about its error: the 3 x 3 split looks too.
                              return events.crosses(si, r) && (std::abs(fine) * fraction > region_tol ||
                                                               (std::abs(fine) <= region_tol && reaches(r)));
                          });
        hidden.value = std::max(0.0, open.value - hidden.value);
        hidden.error += open.error;
        return hidden;
    }

    // A_i F_ij with both integrals by adaptive quadrature (any surfaces, any occluders).
    Estimate area_times_f_numeric(int i, int j, const std::vector<int>& blockers, double tol,
                                  FormFactorStats* st) const {
        const Patch& pi = m_geo.patch(i);
        const Patch& pj = m_geo.patch(j);
        const Surface& si = m_geo.surface(pi.surface);
        const Surface& sj = m_geo.surface(pj.surface);
        const BlockerSet guard(m_geo, m_opt.visibility ? blockers : std::vector<int>{});
        double inner_err = 0.0;
        long long tests = 0;
        auto g = [&](double s, double t) {
            const Vec3 ni = si.normal(s, t);
            const double da = glm::length(ni);
            if (!(da > 0.0)) return 0.0;
            const Vec3 x = si.point(s, t);
            auto h = [&](double u, double w) {
                const Vec3 y = sj.point(u, w);
                const Vec3 e = y - x;
                const double ci = glm::dot(ni, e);
                if (ci <= 0.0) return 0.0;
                const Vec3 nj = sj.normal(u, w);
                const double cj = -glm::dot(nj, e);
                if (cj <= 0.0) return 0.0;
                const double l2 = glm::dot(e, e);
                if (!(l2 > 1e-24 * m_geo.scale() * m_geo.scale())) return 0.0;
                if (!guard.empty() && guard.blocked(x, e, 1e-9, 1.0 - 1e-9, &tests)) return 0.0;
                return ci * cj / (kPi * da * l2 * l2);
            };
            // The inner integral by two Gauss rules over the whole receiver: their difference
            // estimates its error. (Adaptive inner integration with visibility tests costs
            // orders of magnitude more and is left out; this path serves curved receivers and
            // general occluders, where the closed form does not apply.)
            const double hs = 0.5 * (pj.s1 - pj.s0), ht = 0.5 * (pj.t1 - pj.t0);
            auto rule_sum = [&](const GaussRule& rule) {
                double sum = 0.0;
                for (std::size_t b = 0; b < rule.x.size(); ++b)
                    for (std::size_t a = 0; a < rule.x.size(); ++a)
                        sum += rule.w[a] * rule.w[b] *
                               h(pj.s0 + hs * (rule.x[a] + 1.0), pj.t0 + ht * (rule.x[b] + 1.0));
                return sum * hs * ht;
            };
            const double fine = rule_sum(m_inner_fine), coarse = rule_sum(m_inner);
            inner_err = std::max(inner_err, kSafety * std::abs(fine - coarse));
            return da * fine;
        };
        Estimate e =
            adaptive_rect(g, Rect{pi.s0, pi.s1, pi.t0, pi.t1}, 0.5 * tol * std::min(pi.area, pj.area),
                          kMaxNumericRegions, m_outer, [](const Rect&, double) { return -1; });
        e.error += inner_err * pi.area;
        st->segment_tests += tests;
        return e;
    }

    // F_ij (fwd) and F_ji (bwd) by `integrate(a, b)` (A_a F_ab). Both directions are integrated
    // independently (so that reciprocity checks them) only for patches of comparable size.
    // Otherwise the smaller patch is the outer domain and the larger one's entry follows by
    // reciprocity: integrating over a large patch toward a small receiver to the same
    // tol x A_small costs far more regions (the accuracy study's cube face toward a sphere of
    // 512 facets: 82 s, not 0.11 s). A self pair is one direction.
    template <class Integrate, class Set>
    void directions(int i, int j, bool fwd, bool bwd, const Integrate& integrate, const Set& set,
                    FormFactorStats* st) const {
        const double ai = m_geo.patch(i).area, aj = m_geo.patch(j).area;
        if (fwd && bwd &&
            (m_opt.one_direction || std::max(ai, aj) > kIndependentAreaRatio * std::min(ai, aj))) {
            if (ai <= aj)
                bwd = false;
            else
                fwd = false;
        }
        for (const int a : {i, j}) {
            if (!(a == i ? fwd : bwd)) continue;
            const int b = a == i ? j : i;
            const Estimate e = integrate(a, b);
            st->regions += e.regions;
            st->capped += e.capped;
            ++st->semi_analytic;
            set(a, b, e, m_geo.patch(a).area);
            if (a != b && !(a == i ? bwd : fwd)) {
                set(b, a, e, m_geo.patch(b).area);
                ++st->by_reciprocity;
            }
            if (a == b) break;
        }
    }

    // F(i, j) and F(j, i), j >= i, and their estimates (zeroed first).
    void pair(int i, int j, PairEntries* out, std::vector<int>& blockers, FormFactorStats* st) const {
        *out = PairEntries{};
        const double tol = m_opt.tolerance;
        ++st->pairs;
        const bool self = i == j;
        const double ai = m_geo.patch(i).area, aj = m_geo.patch(j).area;
        if (self ? !m_geo.surface(m_geo.patch(i).surface).sees_itself() : m_base.culled(i, j)) {
            if (!self) ++st->pairs_culled;
            return;
        }
        const PairClock clock(m_geo, i, j, st);  // pairs proven zero cost nothing worth timing
        m_base.occluders(i, j, &blockers, st);
        // Entry (a, b): (i, j) when a is i (a self pair included), else (j, i).
        auto set = [&](int a, int /*b*/, const Estimate& e, double area_a) {
            const bool forward = a == i;
            (forward ? out->f_ij : out->f_ji) = e.value / area_a;
            (forward ? out->e_ij : out->e_ji) = e.error / area_a;
        };
        if (const std::optional<Estimate> e = closed_form(i, j, blockers)) {
            ++st->closed_form;
            set(i, j, *e, ai);
            if (!self) set(j, i, *e, aj);
            return;
        }
        Shadow bij, bji;
        const bool fwd = !self && semi_analytic(i, j, blockers, &bij);
        const bool bwd = !self && semi_analytic(j, i, blockers, &bji);
        if (fwd || bwd) {
            directions(
                i, j, fwd, bwd,
                [&](int a, int b) { return area_times_f_semi(a, b, a == i ? bij : bji, tol); }, set, st);
            return;
        }
        // A sphere receiver with nothing in the way that the cuts of its contour do not
        // account for (nested spheres).
        const auto sf = sphere_receiver(m_geo, i, j, blockers, m_opt.visibility);
        const auto sb =
            self ? std::optional<SphereReceiver>{} : sphere_receiver(m_geo, j, i, blockers, m_opt.visibility);
        if (sf || sb) {
            directions(
                i, j, sf.has_value(), sb.has_value(),
                [&](int a, int b) {
                    return area_times_f_sphere(m_geo, a, b, a == i ? *sf : *sb, tol, m_outer,
                                               kMaxOuterRegions);
                },
                set, st);
            return;
        }
        // A receiver bounded by segments and arcs (disks, cylinders) that all of the other
        // patch sees whole.
        const auto cf = contour_receiver(m_geo, i, j, blockers, m_opt.visibility);
        const auto cb = self ? std::optional<ContourReceiver>{}
                             : contour_receiver(m_geo, j, i, blockers, m_opt.visibility);
        if (cf || cb) {
            directions(
                i, j, cf.has_value(), cb.has_value(),
                [&](int a, int b) {
                    return area_times_f_contour(m_geo, a, b, a == i ? *cf : *cb, tol, m_outer,
                                                kMaxOuterRegions);
                },
                set, st);
            return;
        }
        // Neither direction has a planar receiver free of general occluders: one symmetric
        // numeric integral gives both entries.
        const Estimate e = area_times_f_numeric(i, j, blockers, tol, st);
        st->regions += e.regions;
        st->capped += e.capped;
        ++st->numeric;
        set(i, j, e, ai);
        if (!self) set(j, i, e, aj);
    }

private:
    static constexpr int kMaxOuterRegions = 4096;
    // The share of a shadowed pair's tolerance its unblocked exchange may use.
    static constexpr double kOpenShare = 0.125;
    static constexpr double kIndependentAreaRatio = 4.0;
    static constexpr int kMaxNumericRegions = 64;
    const SceneGeometry& m_geo;
    const FormFactorOptions& m_opt;
    const Integrator& m_base;
    GaussRule m_outer, m_inner, m_inner_fine;
};

}  // namespace

struct FormFactorRows::Impl {
    Impl(const SceneGeometry& g, const FormFactorOptions& o)
        : geometry(g), options(o), integrator(g, options), adaptive(g, options, integrator) {}
    const SceneGeometry& geometry;
    FormFactorOptions options;
    Integrator integrator;
    AdaptiveIntegrator adaptive;
};

FormFactorRows::FormFactorRows(const SceneGeometry& geometry, const FormFactorOptions& options)
    : m(std::make_unique<Impl>(geometry, options)) {}
FormFactorRows::~FormFactorRows() = default;

int FormFactorRows::patch_count() const { return m->geometry.patch_count(); }

FormFactors FormFactorRows::zeros() const {
    const int n = patch_count();
    FormFactors ff;
    ff.F = DenseMatrix(n);
    ff.options = m->options;
    for (const Patch& p : m->geometry.patches()) ff.area.push_back(p.area);
    if (m->options.method != FormFactorMethod::Fixed) ff.error.assign(static_cast<std::size_t>(n) * n, 0.0);
    return ff;
}

void FormFactorRows::compute(int begin, int end, FormFactors* ff, FormFactorStats* stats,
                             const PairProgress& progress) const {
    compute_rows(begin, end, nullptr, ff, stats, progress);
}

void FormFactorRows::compute_pairs(const std::vector<std::vector<int>>& pairs, FormFactors* ff,
                                   FormFactorStats* stats) const {
    compute_rows(0, patch_count(), &pairs, ff, stats, {});
}

PairEntries FormFactorRows::pair(int i, int j, FormFactorStats* stats) const {
    if (j < i) {
        PairEntries e = pair(j, i, stats);
        std::swap(e.f_ij, e.f_ji);
        std::swap(e.e_ij, e.e_ji);
        return e;
    }
    PairEntries e;
    std::vector<int> blockers;
    if (m->options.method != FormFactorMethod::Fixed)
        m->adaptive.pair(i, j, &e, blockers, stats);
    else
        m->integrator.pair(i, j, &e, blockers, stats);
    return e;
}

void FormFactorRows::compute_rows(int begin, int end, const std::vector<std::vector<int>>* pairs,
                                  FormFactors* ff, FormFactorStats* stats,
                                  const PairProgress& progress) const {
    const bool controlled = m->options.method != FormFactorMethod::Fixed;
    const int n = patch_count();
    std::mutex merge;
    // Each task owns whole rows i and writes only F(i, j) and F(j, i) for j >= i, so no two
    // tasks write the same entry; results do not depend on the thread count.
    tbb::parallel_for(tbb::blocked_range<int>(begin, end, 1), [&](const tbb::blocked_range<int>& r) {
        FormFactorStats local;
        std::vector<int> blockers;
        const auto nn = static_cast<std::size_t>(n);
        auto one = [&](int i, int j) {
            PairEntries e;
            if (controlled)
                m->adaptive.pair(i, j, &e, blockers, &local);
            else
                m->integrator.pair(i, j, &e, blockers, &local);
            // A self pair (i == j) has one entry, f_ij: written last.
            ff->F(j, i) = e.f_ji;
            ff->F(i, j) = e.f_ij;
            if (controlled) {
                ff->error[static_cast<std::size_t>(j) * nn + static_cast<std::size_t>(i)] = e.e_ji;
                ff->error[static_cast<std::size_t>(i) * nn + static_cast<std::size_t>(j)] = e.e_ij;
            }
        };
        for (int i = r.begin(); i != r.end(); ++i) {
            if (pairs) {
                for (const int j : (*pairs)[static_cast<std::size_t>(i)]) one(i, j);
                continue;
            }
            for (int j = i; j < n; ++j) one(i, j);
            if (progress) progress(n - i);
        }
        std::lock_guard lock(merge);
        *stats += local;
    });
}

FormFactors compute_form_factors(const SceneGeometry& geometry, const FormFactorOptions& options,
                                 const PairProgress& progress) {
    const Stopwatch clock;
    const FormFactorRows rows(geometry, options);
    FormFactors ff = rows.zeros();
    rows.compute(0, rows.patch_count(), &ff, &ff.stats, progress);
    ff.stats.seconds = clock.seconds();
    return ff;
}

FormFactorStats& FormFactorStats::operator+=(const FormFactorStats& o) {
    // Both visits walk the same list in the same order: pair them up through a flat array.
    std::vector<long long> add;
    o.for_each_counter([&](const char*, long long v) { add.push_back(v); });
    std::size_t k = 0;
    for_each_counter([&](const char*, long long& v) { v += add[k++]; });
    seconds += o.seconds;
    if (seconds_by_surface.size() < o.seconds_by_surface.size())
        seconds_by_surface.resize(o.seconds_by_surface.size(), 0.0);
    for (std::size_t k = 0; k < o.seconds_by_surface.size(); ++k)
        seconds_by_surface[k] += o.seconds_by_surface[k];
    return *this;
}

}  // namespace radiosa
