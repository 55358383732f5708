#include "formfactor/hierarchy.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>

#include "formfactor/blocker_set.h"
#include "formfactor/cubature.h"
#include "formfactor/culling.h"
#include "formfactor/hierarchy_nodes.h"
#include "formfactor/point_polygon.h"
#include "util/convex_distance.h"
#include "util/stopwatch.h"

namespace radiosa {
namespace {

// A link's slopes (Link::gs, gt, cs, ct) as stored, in single precision, and what storing them
// so costs the link's gather per unit of radiosity.
struct Slopes {
    float gs = 0.0f, gt = 0.0f, cs = 0.0f, ct = 0.0f;
    double rounding = 0.0;
};

// The unoccluded kernel cos_x cos_y / (pi r^2) per unit area of both samples, and the segment
// e = y - x; 0 when the two do not face each other.
double facing_kernel(const Sample& x, const Sample& y, Vec3* e) {
    *e = y.x - x.x;
    const double l2 = glm::dot(*e, *e);
    const double cx = glm::dot(x.n, *e), cy = -glm::dot(y.n, *e);
    return cx > 0.0 && cy > 0.0 && l2 > 0.0 ? cx * cy / (kPi * l2 * l2) : 0.0;
}

// A weighted least-squares plane through values F_a at the samples: F ~ mean + gs (u - u_mean)
// + gt (v - v_mean) (u and v fitted separately: on a product Gauss grid they are nearly
// uncorrelated), and the spread of what the plane leaves.
struct LinearFit {
    double gs = 0.0, gt = 0.0;
    double residual_spread = 0.0;
    double ms = 0.0, mt = 0.0;            // sum_a w_a F_a (u_a - u_mean), and along v
    double um = 0.0, vm = 0.0, fm = 0.0;  // the weighted means of u, v and F
    double residual(const Sample& x, double f) const { return f - fm - gs * (x.u - um) - gt * (x.v - vm); }
};
// With `more`, the spread is also taken at those points (values *more_F), which the plane does
// not go through.
LinearFit fit_plane(const Sample* xs, const std::vector<double>& F, const Sample* more = nullptr,
                    const std::vector<double>* more_F = nullptr) {
    double w = 0.0, wu = 0.0, wv = 0.0, wf = 0.0;
    for (std::size_t a = 0; a < F.size(); ++a) {
        w += xs[a].w;
        wu += xs[a].w * xs[a].u;
        wv += xs[a].w * xs[a].v;
        wf += xs[a].w * F[a];
    }
    LinearFit fit;
    if (!(w > 0.0)) return fit;
    const double um = wu / w, vm = wv / w, fm = wf / w;
    fit.um = um;
    fit.vm = vm;
    fit.fm = fm;
    double suu = 0.0, svv = 0.0, suf = 0.0, svf = 0.0;
    for (std::size_t a = 0; a < F.size(); ++a) {
        const double du = xs[a].u - um, dv = xs[a].v - vm, df = F[a] - fm;
        suu += xs[a].w * du * du;
        svv += xs[a].w * dv * dv;
        suf += xs[a].w * du * df;
        svf += xs[a].w * dv * df;
    }
    fit.ms = suf;
    fit.mt = svf;
    fit.gs = suu > 0.0 ? suf / suu : 0.0;
    fit.gt = svv > 0.0 ? svf / svv : 0.0;
    double lo = 0.0, hi = 0.0;
    for (std::size_t a = 0; a < F.size(); ++a) {
        const double r = fit.residual(xs[a], F[a]);
        lo = a == 0 ? r : std::min(lo, r);
        hi = a == 0 ? r : std::max(hi, r);
    }
    for (std::size_t a = 0; more && a < more_F->size(); ++a) {
        lo = std::min(lo, fit.residual(more[a], (*more_F)[a]));
        hi = std::max(hi, fit.residual(more[a], (*more_F)[a]));
    }
    fit.residual_spread = hi - lo;
    return fit;
}

class Refiner {
public:
    Refiner(const SceneGeometry& g, const HierarchyOptions& o, const FormFactorOptions& leaf,
            const PairProgress& progress, Hierarchy* h)
        : m_g(g), m_o(o), m_leaf(leaf), m_rows(g, leaf), m_h(*h), m_m(o.samples), m_progress(progress) {
        m_samples = node_samples(g, *h, m_m);
        m_coarse = node_samples(g, *h, m_m - 1);
        m_eps = 1e-9 * g.scale();
        m_cull_eps = 1e-12 * g.scale();  // as Culling's
        for (int k = 0; k < g.surface_count(); ++k)
            if (const auto ball = g.surface(k).sphere(); ball && g.surface(k).whole_sphere())
                m_balls.emplace_back(k, *ball);
    }

    // Every pair of surfaces, and each surface that sees itself with itself.
    void run() {
        std::vector<std::pair<int, int>> tops;
        for (int k = 0; k < m_h.roots; ++k)
            for (int l = k; l < m_h.roots; ++l) {
                if (k == l && !m_g.surface(k).sees_itself()) {
                    done(k, k);
                    continue;
                }
                tops.emplace_back(k, l);
            }
        tbb::parallel_for(std::size_t{0}, tops.size(),
                          [&](std::size_t i) { refine(tops[i].first, tops[i].second); });
    }

    // The threads' links into one vector of exactly their count, each thread's chunk freed
    // once copied: the links are held about once, not three times (the threads' doubling
    // vectors, then a doubling copy), which was most of the peak memory of a large scene.
    void collect(Hierarchy* h) {
        gather(m_links, &h->links);
        gather(m_pair_links, &h->pair_links);
        for (const FormFactorStats& s : m_leaf_stats) h->leaf_stats += s;
        h->stats.node_pairs = m_node_pairs;
        h->stats.kernel_samples = m_kernel_samples;
        h->stats.dropped = m_dropped;
        h->stats.leaf_links = m_leaf_links;
    }

private:
    // Each thread's links of one kind in chunks of kChunkLinks, never one array that doubles: a
    // chunk is large enough that malloc maps it apart (its untouched tail costs nothing
    // resident), and freeing it returns its memory.
    template <class L>
    using Chunks = tbb::enumerable_thread_specific<std::vector<std::vector<L>>>;
    static constexpr std::size_t kChunkLinks = std::size_t{1} << 20;  // 24 or 40 MB

    // The threads' chunks into `out`, sorted by (receiver, source).
    template <class L>
    static void gather(Chunks<L>& chunks, std::vector<L>* out) {
        std::size_t total = 0;
        for (const auto& local : chunks)
            for (const auto& chunk : local) total += chunk.size();
        out->reserve(out->size() + total);
        for (auto& local : chunks)
            for (auto& chunk : local) {
                out->insert(out->end(), chunk.begin(), chunk.end());
                std::vector<L>().swap(chunk);
            }
        tbb::parallel_sort(out->begin(), out->end(), link_before<L, L>);
    }
    template <class L>
    static void append(Chunks<L>& chunks, const L& l) {
        auto& local = chunks.local();
        if (local.empty() || local.back().size() == kChunkLinks) local.emplace_back().reserve(kChunkLinks);
        local.back().push_back(l);
    }

    const HierarchyNode& node(int i) const { return m_h.nodes[static_cast<std::size_t>(i)]; }

    // The coupling from the (m - 1) x (m - 1) points of each node.
    double coarse_coupling(int p, int q, const BlockerSet& guard, long long* tests) const {
        const std::size_t mm = static_cast<std::size_t>((m_m - 1) * (m_m - 1));
        const Sample* xs = &m_coarse[static_cast<std::size_t>(p) * mm];
        const Sample* ys = &m_coarse[static_cast<std::size_t>(q) * mm];
        double g = 0.0;
        for (std::size_t a = 0; a < mm; ++a)
            for (std::size_t b = 0; b < mm; ++b) {
                Vec3 e;
                const double k = facing_kernel(xs[a], ys[b], &e);
                if (k > 0.0 && !guard.blocked(xs[a].x, e, 1e-9, 1.0 - 1e-9, tests))
                    g += xs[a].w * ys[b].w * k;
            }
        return g;
    }

    // A link r <- s's slopes from the fits of F(x -> s) over r and of F(y -> r) over s, rounded
    // to single precision. The rounding is exact to measure: a receiver slope's is what the
    // plane loses at the node's edge (u = +-1), a source slope's is multiplied by the source's
    // radiosity slope, at most (max B) / centroid_gap per unit of radiosity (its children's
    // difference over their centroids' distance).
    Slopes slopes(const HierarchyNode& r, const LinearFit& over_r, const HierarchyNode& s,
                  const LinearFit& over_s) const {
        Slopes k;
        const auto round = [&k](double x, float* out, double weight) {
            *out = static_cast<float>(x);
            k.rounding += weight * std::abs(x - static_cast<double>(*out));
        };
        if (!r.leaf()) round(over_r.gs, &k.gs, 1.0), round(over_r.gt, &k.gt, 1.0);
        if (!s.leaf()) {
            const double per_slope = 1.0 / std::max(1e-3, m_h.centroid_gap(s));
            round(over_s.ms / r.area, &k.cs, per_slope), round(over_s.mt / r.area, &k.ct, per_slope);
        }
        return k;
    }
    // A link r <- s; between two patches, a PairLink (no slopes).
    bool add(int r, int s, double f, double e, const Slopes& k = {}) {
        if (f == 0.0 && e == 0.0) return false;
        if (node(r).leaf() && node(s).leaf())
            append(m_pair_links, PairLink{r, s, f, e});
        else
            append(m_links, Link{r, s, f, e, k.gs, k.gt, k.cs, k.ct});
        return true;
    }

    // Proven to exchange nothing: one of the two lies behind (or in) the other's plane, the
    // two sides of a surface whose chords stay off it, or one surface that cannot see itself.
    bool proven_zero(int p, int q) const {
        const HierarchyNode& a = node(p);
        const HierarchyNode& b = node(q);
        if (a.surface == b.surface && !m_g.surface(a.surface).sees_itself()) return true;
        if (m_g.twin(a.surface) == b.surface && m_g.surface(a.surface).chords_never_cross()) return true;
        for (const auto& [x, y] : {std::pair{p, q}, std::pair{q, p}}) {
            const Surface& sx = m_g.surface(node(x).surface);
            const Surface& sy = m_g.surface(node(y).surface);
            const Rect r = node_rect(m_g, node(y));
            if (const auto pl = sx.plane()) {
                const auto range = sy.linear_range(pl->normal, r.s0, r.s1, r.t0, r.t1);
                if (range.second - pl->offset <= m_eps) return true;
            } else if (const auto ball = sx.sphere(); ball && !sx.sees_itself() && behind_ball(x, *ball, y)) {
                return true;
            }
        }
        return false;
    }

    // Node y lies behind the tangent plane of every point of node x, a piece of the outward
    // sphere `ball` (centre c, radius R): (P_y - c) . (P_x - c) <= R^2 for all points. The
    // directions u = (P_x - c) / R lie in a cone about u0, the direction of x's bounding sphere
    // (centre b, radius r), with cos(alpha) = (R^2 + |b - c|^2 - r^2) / (2 R |b - c|); those of
    // P_y - c within gamma of the direction of y's bounding sphere; so (P_y - c) . (P_x - c) <=
    // R max |P_y - c| cos(max(0, beta - alpha - gamma)), beta the angle between the two axes.
    bool behind_ball(int x, const BoundingSphere& ball, int y) const {
        const BoundingSphere& bx = node(x).bound;
        const BoundingSphere& by = node(y).bound;
        const Vec3 dx = bx.center - ball.center, dy = by.center - ball.center;
        const double lx = glm::length(dx), ly = glm::length(dy), R = ball.radius;
        if (!(lx > 1e-9 * R) || !(ly > by.radius)) return false;
        const double cos_alpha = (R * R + lx * lx - bx.radius * bx.radius) / (2.0 * R * lx);
        if (!(cos_alpha > -1.0)) return false;
        const double alpha = std::acos(std::min(1.0, cos_alpha)), gamma = std::asin(by.radius / ly);
        const double beta = std::acos(std::clamp(glm::dot(dx, dy) / (lx * ly), -1.0, 1.0));
        const double gap = std::max(0.0, beta - alpha - gamma);
        if (gap >= 0.5 * kPi) return true;
        const Rect r = node_rect(m_g, node(y));
        const double far =
            m_g.surface(node(y).surface).max_distance_from_point(ball.center, r.s0, r.s1, r.t0, r.t1);
        return far * std::cos(gap) <= R - m_eps;
    }

    // Every segment between the two nodes passes through the inside of a whole sphere (a
    // solid, so the segment crosses its surface), both nodes lying outside it: they exchange
    // exactly nothing. At a fraction t along the segment from x in p's bounding ball (centre
    // a, radius r_a) to y in q's (b, r_b), the point (1 - t) x + t y lies within (1 - t) r_a +
    // t r_b of (1 - t) a + t b; with t where the centre line passes nearest the ball's centre.
    // Flat nodes whose balls leave that in doubt are tried by their corners
    // (segments_through_ball): a rectangle's bounding ball reaches past its sides, and on the
    // seed room at 5,216 patches a fifth of the wall pairs shadowed by the ball were wholly
    // hidden, yet integrated.
    bool hidden_by_ball(int p, int q) const {
        if (!m_leaf.visibility) return false;
        const BoundingSphere& a = node(p).bound;
        const BoundingSphere& b = node(q).bound;
        const Vec3 e = b.center - a.center;
        const double l2 = glm::dot(e, e);
        if (!(l2 > 0.0)) return false;
        for (const auto& [k, ball] : m_balls) {
            if (k == node(p).surface || k == node(q).surface) continue;
            const double t = glm::dot(ball.center - a.center, e) / l2;
            if (!(t > 0.0 && t < 1.0)) continue;
            const double miss = glm::length(a.center + t * e - ball.center);
            if (!(miss < ball.radius - m_eps) || !outside(p, ball) || !outside(q, ball)) continue;
            if (miss + (1.0 - t) * a.radius + t * b.radius < ball.radius - m_eps) return true;
            if (const auto cp = flat_corners(p))
                if (const auto cq = flat_corners(q); cq && segments_through_ball(*cp, *cq, ball, m_eps))
                    return true;
        }
        return false;
    }
    // Node n lies wholly outside the ball: its bounding ball does, or its plane passes by it.
    bool outside(int n, const BoundingSphere& ball) const {
        const BoundingSphere& nb = node(n).bound;
        if (glm::length(nb.center - ball.center) > ball.radius + nb.radius + m_eps) return true;
        const auto pl = m_g.surface(node(n).surface).plane();
        return pl && std::abs(pl->signed_distance(ball.center)) > ball.radius + m_eps;
    }
    // The corners of a node of a surface whose patches are polygons: the node is the polygon
    // they bound.
    std::optional<std::array<Vec3, 4>> flat_corners(int n) const {
        const Surface& s = m_g.surface(node(n).surface);
        if (!s.patches_are_polygons()) return std::nullopt;
        const Rect r = node_rect(m_g, node(n));
        return std::array<Vec3, 4>{s.point(r.s0, r.t0), s.point(r.s1, r.t0), s.point(r.s1, r.t1),
                                   s.point(r.s0, r.t1)};
    }

    // Surfaces whose bounding spheres come near the segments between the two nodes, less those
    // proven unable to block them as the dense path proves it for two patches (culling.h): the
    // nodes' own surfaces whose segments escape them, and planes with both nodes on one side
    // (the walls of a room, which every pair's bounding spheres come near).
    std::vector<int> blockers(int p, int q) const {
        const BoundingSphere& a = node(p).bound;
        const BoundingSphere& b = node(q).bound;
        const Vec3 e = b.center - a.center;
        const double l2 = glm::dot(e, e);
        const Rect rp = node_rect(m_g, node(p)), rq = node_rect(m_g, node(q));
        std::optional<std::array<Vec3, 8>> corners;
        if (const auto cp = flat_corners(p))
            if (const auto cq = flat_corners(q))
                corners = std::array<Vec3, 8>{(*cp)[0], (*cp)[1], (*cp)[2], (*cp)[3],
                                              (*cq)[0], (*cq)[1], (*cq)[2], (*cq)[3]};
        std::vector<int> out;
        for (int k = 0; k < m_g.surface_count(); ++k) {
            bool own = false;
            if (own_surface_clear(m_g, node(p).surface, node(q).surface, k, &own)) continue;
            if (const auto pl = m_g.surface(k).plane()) {
                const auto range = [&](const HierarchyNode& n, const Rect& r) {
                    const auto [lo, hi] =
                        m_g.surface(n.surface).linear_range(pl->normal, r.s0, r.s1, r.t0, r.t1);
                    return std::pair{lo - pl->offset, hi - pl->offset};
                };
                if (one_side_of_plane(range(node(p), rp), range(node(q), rq), m_cull_eps)) continue;
            }
            const BoundingSphere& s = m_g.surface_bound(k);
            const Vec3 oc = s.center - a.center;
            const double t = l2 > 0.0 ? std::clamp(glm::dot(oc, e) / l2, 0.0, 1.0) : 0.0;
            const double reach = s.radius + std::max(a.radius, b.radius) + m_eps;
            if (!(glm::length(oc - t * e) <= reach)) continue;
            // Two flat nodes: every segment between them lies in the hull of their corners.
            if (corners && convex_distance(*corners, std::span<const Vec3>(&s.center, 1), s.radius + m_eps) >
                               s.radius + m_eps)
                continue;
            out.push_back(k);
        }
        return out;
    }

    // The coupling of two nodes from m x m samples on each: G = A_p F_pq = A_q F_qp, and how the
    // point-to-node factors vary over each node: F(x -> q) over the samples x of p, and F(y -> p)
    // over those of q.
    struct Coupling {
        double g = 0.0;
        double quadrature = 0.0;  // |g - g'|, g' from (m - 1) x (m - 1) points: g's own error
        // F(x -> q) over p and F(y -> p) over q as planes in the nodes' (u, v): the links carry
        // the slopes, so what the planes leave is the error.
        LinearFit fit_p, fit_q;
        bool any = false;  // some sample pair sees each other
        // The largest point-to-node factor F(x -> q) over p's samples, and F(y -> p) over q's,
        // without occlusion: what a pair whose samples are all hidden could still exchange.
        double open_p = 0.0, open_q = 0.0;
        // Some sample pairs face each other and some do not: a horizon crosses the pair and
        // the kernel's clipped cosines are not smooth there, so samples say little.
        bool horizon = false;
        int lone_blocker = -1;  // the one surface that may come between the nodes, if one
    };
    Coupling sample(int p, int q) const {
        const std::size_t mm = static_cast<std::size_t>(m_m * m_m);
        const std::vector<int> near = m_leaf.visibility ? blockers(p, q) : std::vector<int>{};
        const BlockerSet guard(m_g, near);
        const Sample* xs = &m_samples[static_cast<std::size_t>(p) * mm];
        const Sample* ys = &m_samples[static_cast<std::size_t>(q) * mm];
        std::vector<double> to_q(mm, 0.0), to_p(mm, 0.0);      // sum_b w_b K(x_a, y_b), sum_a w_a K
        std::vector<double> open_q(mm, 0.0), open_p(mm, 0.0);  // the same without occlusion
        Coupling c;
        long long tests = 0;
        std::size_t away = 0;
        for (std::size_t a = 0; a < mm; ++a)
            for (std::size_t b = 0; b < mm; ++b) {
                Vec3 e;
                const double k = facing_kernel(xs[a], ys[b], &e);
                if (!(k > 0.0)) {
                    ++away;
                    continue;
                }
                open_q[a] += ys[b].w * k;
                open_p[b] += xs[a].w * k;
                if (guard.blocked(xs[a].x, e, 1e-9, 1.0 - 1e-9, &tests)) continue;
                to_q[a] += ys[b].w * k;
                to_p[b] += xs[a].w * k;
                c.g += xs[a].w * ys[b].w * k;
                c.any = true;
            }
        c.horizon = away > 0 && away < mm * mm;
        c.fit_p = fit_plane(xs, to_q);
        c.fit_q = fit_plane(ys, to_p);
        c.open_p = *std::max_element(open_q.begin(), open_q.end());
        c.open_q = *std::max_element(open_p.begin(), open_p.end());
        if (c.any) c.quadrature = std::abs(c.g - coarse_coupling(p, q, guard, &tests));
        m_kernel_samples += static_cast<long long>(mm * mm);
        if (near.size() == 1) c.lone_blocker = near[0];
        return c;
    }

    // The planes through the m x m points, checked at the (m - 1) x (m - 1) points between them too.
    LinearFit checked_fit(int n, const std::vector<double>& fine, const std::vector<double>& coarse) const {
        const std::size_t mm = static_cast<std::size_t>(m_m * m_m),
                          cm = static_cast<std::size_t>((m_m - 1) * (m_m - 1));
        const Sample* xs = &m_samples[static_cast<std::size_t>(n) * mm];
        return fit_plane(xs, fine, &m_coarse[static_cast<std::size_t>(n) * cm], &coarse);
    }

    // The corners of a flat node, counter-clockwise about its front normal.
    std::optional<std::array<Vec3, 4>> front_corners(int n) const {
        const auto v = flat_corners(n);
        if (!v) return std::nullopt;
        const Rect r = node_rect(m_g, node(n));
        return SceneGeometry::facing(
            *v, m_g.surface(node(n).surface).normal(0.5 * (r.s0 + r.s1), 0.5 * (r.t0 + r.t1)));
    }

    // Two flat nodes, each wholly in front of the other's plane, that only a ball (an outward
    // whole sphere, in front of both planes) can come between: its shadow's outline may pass
    // between the kernel's samples (at 2,700 patches 0.5 % of such links were off by up to 7.4
    // times their estimates), but F(x -> node) past a ball has a closed form
    // (point_to_polygon), so the point-to-node factors are exact at each side's samples. The
    // coupling is the mean of the two sides' m x m outer Gauss rules; its quadrature estimate
    // their difference plus the larger of each one's against its (m - 1) x (m - 1) rule, and
    // each plane is checked at those (m - 1) x (m - 1) points too. (Two nodes that meet, whose
    // kernel is singular where they do, are left to the samples.) nullopt when the pair is not
    // of that kind.
    std::optional<Coupling> shadowed_flats(int p, int q, int k) const {
        const Surface& sk = m_g.surface(k);
        if (!sk.whole_sphere() || sk.sees_itself()) return std::nullopt;
        const auto vp = front_corners(p), vq = front_corners(q);
        if (!vp || !vq) return std::nullopt;
        const BoundingSphere ball = *sk.sphere();
        for (const auto& [x, y] : {std::pair{p, q}, std::pair{q, p}}) {
            const auto pl = m_g.surface(node(x).surface).plane();
            if (!pl || !(pl->signed_distance(ball.center) > ball.radius + m_eps)) return std::nullopt;
            const Rect r = node_rect(m_g, node(y));
            if (m_g.surface(node(y).surface).linear_range(pl->normal, r.s0, r.s1, r.t0, r.t1).first <
                pl->offset)
                return std::nullopt;
        }
        // sum_a w_a F(x_a -> the other node) over the n x n samples of node `from`.
        const auto rule = [&](const std::vector<Sample>& set, int n, int from, std::vector<double>* values) {
            const std::size_t count = static_cast<std::size_t>(n * n);
            const Sample* xs = &set[static_cast<std::size_t>(from) * count];
            const std::array<Vec3, 4>& v = from == p ? *vq : *vp;
            values->assign(count, 0.0);
            double g = 0.0;
            for (std::size_t a = 0; a < count; ++a) {
                (*values)[a] = point_to_polygon(xs[a].x, xs[a].n, v.data(), 4, &ball);
                g += xs[a].w * (*values)[a];
            }
            return g;
        };
        std::vector<double> to_q, to_p, coarse_q, coarse_p;
        const double gp = rule(m_samples, m_m, p, &to_q), gq = rule(m_samples, m_m, q, &to_p);
        const double cp = rule(m_coarse, m_m - 1, p, &coarse_q), cq = rule(m_coarse, m_m - 1, q, &coarse_p);
        Coupling c;
        c.g = 0.5 * (gp + gq);
        c.quadrature = std::abs(gp - gq) + std::max(std::abs(gp - cp), std::abs(gq - cq));
        c.fit_p = checked_fit(p, to_q, coarse_q);
        c.fit_q = checked_fit(q, to_p, coarse_p);
        c.open_p = *std::max_element(to_q.begin(), to_q.end());
        c.open_q = *std::max_element(to_p.begin(), to_p.end());
        c.any = c.g > 0.0;
        return c;
    }

    void leaf_pair(int p, int q) {
        FormFactorStats& st = m_leaf_stats.local();
        const PairEntries e = m_rows.pair(node(p).patch, node(q).patch, &st);
        m_leaf_links += add(p, q, e.f_ij, e.e_ij) + (p != q && add(q, p, e.f_ji, e.e_ji));
        done(p, q);
    }

    // Two pair refinements, in parallel while the nodes are large (the split points do not
    // depend on the threads, and the links are sorted afterwards).
    template <class A, class B>
    void both(int size, const A& a, const B& b) {
        if (size > kParallelPatches)
            tbb::parallel_invoke(a, b);
        else {
            a();
            b();
        }
    }
    static int patches(const HierarchyNode& n) { return (n.is1 - n.is0) * (n.it1 - n.it0); }
    // Tells the progress the pairs of patches under nodes p and q (p == q: each pair once).
    void done(int p, int q) const {
        if (!m_progress) return;
        const long long a = patches(node(p)), b = patches(node(q));
        m_progress(p == q ? a * (a + 1) / 2 : a * b);
    }

    // A link's estimates both ways from a coupling, and whether they meet the tolerances.
    struct Judgement {
        double rp = 0.0, rq = 0.0;  // the receivers' misfits (none for a patch)
        double e_pq = 0.0, e_qp = 0.0;
        Slopes k_pq, k_qp;
        bool fits = false, receivers_fit = false;
    };
    Judgement judge(const HierarchyNode& a, const HierarchyNode& b, const Coupling& c) const {
        Judgement j;
        // The error of p's gather over the link, per unit of radiosity: each side's plane carries
        // its slopes (the receiver's, and the source's against its radiosity slopes), so what the
        // planes leave is the estimate: the receiver's residual (none when p is one patch), the
        // source's per unit area of p (none when q is one patch), and the quadrature's.
        j.rp = a.leaf() ? 0.0 : c.fit_p.residual_spread;
        j.rq = b.leaf() ? 0.0 : c.fit_q.residual_spread;
        // The slopes are stored in single precision, and their rounding counts too.
        j.k_pq = slopes(a, c.fit_p, b, c.fit_q);
        j.k_qp = slopes(b, c.fit_q, a, c.fit_p);
        j.e_pq = j.rp + (j.rq * b.area + c.quadrature) / a.area + j.k_pq.rounding;
        j.e_qp = j.rq + (j.rp * a.area + c.quadrature) / b.area + j.k_qp.rounding;
        // With a receiver tolerance, each side's misfit as a receiver is held to it too.
        j.receivers_fit = !(m_o.receiver_tolerance > 0.0) || std::max(j.rp, j.rq) <= m_o.receiver_tolerance;
        j.fits = c.any && !c.horizon && std::max(j.e_pq, j.e_qp) <= m_o.tolerance;
        return j;
    }

    void refine(int p, int q) {
        ++m_node_pairs;
        const HierarchyNode& a = node(p);
        const HierarchyNode& b = node(q);
        if (p == q) {
            if (a.leaf()) return leaf_pair(p, p);
            const int c0 = a.child[0], c1 = a.child[1];
            both(
                patches(a), [&] { refine(c0, c0); }, [&] { refine(c1, c1); });
            return refine(c0, c1);
        }
        const bool hidden = hidden_by_ball(p, q);
        if (a.leaf() && b.leaf() && !hidden) return leaf_pair(p, q);
        if (hidden || proven_zero(p, q)) {
            ++m_dropped;
            return done(p, q);
        }
        Coupling c = sample(p, q);
        Judgement j = judge(a, b, c);
        // A link between flat nodes that only a ball can come between is made only if the
        // exact point-to-node factors (shadowed_flats) meet the tolerances too, and from them.
        if (j.fits && j.receivers_fit && c.lone_blocker >= 0)
            if (const auto exact = shadowed_flats(p, q, c.lone_blocker)) {
                c = *exact;
                j = judge(a, b, c);
            }
        if (j.fits && j.receivers_fit) {
            add(p, q, c.g / a.area, j.e_pq, j.k_pq);
            add(q, p, c.g / b.area, j.e_qp, j.k_qp);
            return done(p, q);
        }
        // Every sample pair hidden: a zero coupling whose estimate is what the open view
        // could carry. (A pair whose samples all face away is split until a proof or the
        // patches' own integral settles it.)
        if (!c.any && !c.horizon && c.open_p > 0.0 && std::max(c.open_p, c.open_q) <= m_o.tolerance) {
            ++m_dropped;
            add(p, q, 0.0, c.open_p);
            add(q, p, 0.0, c.open_q);
            return done(p, q);
        }
        // Split the larger node (a leaf is never split); or, when only a receiver's misfit is
        // over the receiver tolerance, the node with the larger misfit.
        const bool split_a = !a.leaf() && (b.leaf() || (j.fits ? j.rp >= j.rq : a.area >= b.area));
        const HierarchyNode& s = split_a ? a : b;
        const int other = split_a ? q : p, c0 = s.child[0], c1 = s.child[1];
        both(
            patches(a) + patches(b), [&] { refine(c0, other); }, [&] { refine(c1, other); });
    }

    static constexpr int kParallelPatches = 256;
    const SceneGeometry& m_g;
    HierarchyOptions m_o;
    FormFactorOptions m_leaf;
    FormFactorRows m_rows;
    Hierarchy& m_h;
    int m_m;
    double m_eps = 0.0, m_cull_eps = 0.0;
    const PairProgress& m_progress;
    std::vector<Sample> m_samples, m_coarse;
    std::vector<std::pair<int, BoundingSphere>> m_balls;  // whole spheres: solids that can hide a pair
    Chunks<Link> m_links;
    Chunks<PairLink> m_pair_links;
    tbb::enumerable_thread_specific<FormFactorStats> m_leaf_stats;
    mutable std::atomic<long long> m_node_pairs{0}, m_kernel_samples{0}, m_dropped{0}, m_leaf_links{0};
};

}  // namespace

Hierarchy build_hierarchy(const SceneGeometry& geometry, const HierarchyOptions& options,
                          const FormFactorOptions& leaf, const PairProgress& progress) {
    const Stopwatch clock;
    Hierarchy h = hierarchy_nodes(geometry, options);
    FormFactorOptions pairs = leaf;  // the pairs of patches are integrated as the adaptive method's
    if (pairs.method == FormFactorMethod::Hierarchical) pairs.method = FormFactorMethod::Adaptive;
    pairs.one_direction = true;  // links are reciprocal: half the work of the dense path's pairs
    Refiner refiner(geometry, options, pairs, progress, &h);
    refiner.run();
    refiner.collect(&h);
    index_links(&h);
    h.stats.seconds = clock.seconds();
    return h;
}

}  // namespace radiosa
