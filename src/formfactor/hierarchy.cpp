#include "formfactor/hierarchy.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "formfactor/blocker_set.h"
#include "formfactor/culling.h"
#include "formfactor/cubature.h"
#include "util/gauss_legendre.h"
#include "util/stopwatch.h"

namespace radiosa {
namespace {

// The smallest sphere found by growing a onto b (not the minimal one, but never smaller than
// both, which is all a bound needs).
BoundingSphere enclose(const BoundingSphere& a, const BoundingSphere& b) {
    const Vec3 d = b.center - a.center;
    const double dist = glm::length(d);
    if (dist + b.radius <= a.radius) return a;
    if (dist + a.radius <= b.radius) return b;
    const double r = 0.5 * (dist + a.radius + b.radius);
    return {a.center + d * ((r - a.radius) / dist), r};
}

// A ball holding the part [s0, s1] x [t0, t1] of a spherical surface, tighter than its own
// bound() (the whole sphere): the cap about the direction u0 of the middle azimuth and polar
// angle that holds the part. cos(angle to u0) >= cos(theta) cos(theta_m) + sin(theta) sin(theta_m)
// cos(span / 2), a sinusoid in theta whose least value on [theta0, theta1] is at an end or at its
// trough; a cap of angle alpha <= pi / 2 lies in the ball of radius R sin(alpha) about c + R
// cos(alpha) u0. Otherwise `fallback`.
BoundingSphere cap_bound(const Surface& surface, double s0, double s1, double t0, double t1,
                         const BoundingSphere& fallback) {
    const auto ball = surface.sphere();
    if (!ball) return fallback;
    const auto [pa, ta] = surface.sphere_angles(s0, t0);
    const auto [pb, tb] = surface.sphere_angles(s1, t1);
    const double th0 = std::min(ta, tb), th1 = std::max(ta, tb);
    const double half = 0.5 * std::abs(pb - pa), pm = 0.5 * (pa + pb), tm = 0.5 * (th0 + th1);
    if (half > kPi) return fallback;
    const double A = std::cos(tm), B = std::sin(tm) * std::cos(half);
    const auto f = [&](double th) { return A * std::cos(th) + B * std::sin(th); };
    double cos_alpha = std::min(f(th0), f(th1));
    const double trough = std::atan2(B, A) + kPi;  // f's least value, -sqrt(A^2 + B^2)
    for (const double th : {trough, trough - 2.0 * kPi})
        if (th > th0 && th < th1) cos_alpha = std::min(cos_alpha, f(th));
    if (!(cos_alpha > 0.0)) return fallback;
    const Vec3 u0 =
        surface.sphere_axes() * Vec3(std::sin(tm) * std::cos(pm), std::sin(tm) * std::sin(pm), std::cos(tm));
    const double r = ball->radius * std::sqrt(std::max(0.0, 1.0 - cos_alpha * cos_alpha));
    const BoundingSphere cap{ball->center + ball->radius * cos_alpha * u0,
                             r * (1.0 + 1e-12) + 1e-15 * ball->radius};
    return cap.radius < fallback.radius ? cap : fallback;
}

// A link's slopes (Link::gs, gt, cs, ct).
struct Slopes {
    double gs = 0.0, gt = 0.0, cs = 0.0, ct = 0.0;
};

struct Sample {
    Vec3 x;
    Vec3 n;       // unit front normal
    double w;     // area weight
    double u, v;  // where in the node, each in [-1, 1] along s and t
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
    double ms = 0.0, mt = 0.0;  // sum_a w_a F_a (u_a - u_mean), and along v
};
LinearFit fit_plane(const Sample* xs, const std::vector<double>& F) {
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
        const double r = F[a] - fm - fit.gs * (xs[a].u - um) - fit.gt * (xs[a].v - vm);
        lo = a == 0 ? r : std::min(lo, r);
        hi = a == 0 ? r : std::max(hi, r);
    }
    fit.residual_spread = hi - lo;
    return fit;
}

// The nodes of one surface's patch grid: a binary tree halving the longer side.
void build_nodes(const SceneGeometry& g, Hierarchy* h) {
    const int surfaces = g.surface_count();
    h->roots = surfaces;
    h->nodes.resize(static_cast<std::size_t>(surfaces));
    h->leaf_of_patch.assign(static_cast<std::size_t>(g.patch_count()), -1);
    for (int k = 0; k < surfaces; ++k) {
        HierarchyNode& r = h->nodes[static_cast<std::size_t>(k)];
        r.surface = k;
        r.is1 = g.ns(k);
        r.it1 = g.nt(k);
    }
    // Breadth-first: children always come after their parent.
    for (std::size_t i = 0; i < h->nodes.size(); ++i) {
        HierarchyNode n = h->nodes[i];
        const int ws = n.is1 - n.is0, wt = n.it1 - n.it0;
        if (ws == 1 && wt == 1) {
            n.patch = g.patch_index(n.surface, n.is0, n.it0);
            h->leaf_of_patch[static_cast<std::size_t>(n.patch)] = static_cast<int>(i);
            h->nodes[i] = n;
            continue;
        }
        HierarchyNode a = n, b = n;
        if (ws >= wt)
            a.is1 = b.is0 = n.is0 + ws / 2;
        else
            a.it1 = b.it0 = n.it0 + wt / 2;
        h->nodes[i].child[0] = static_cast<int>(h->nodes.size());
        h->nodes[i].child[1] = static_cast<int>(h->nodes.size() + 1);
        h->nodes.push_back(a);
        h->nodes.push_back(b);
    }
    // Areas and bounds, leaves up.
    for (std::size_t i = h->nodes.size(); i-- > 0;) {
        HierarchyNode& n = h->nodes[i];
        if (n.leaf()) {
            const Patch& pt = g.patch(n.patch);
            n.area = pt.area;
            n.bound = cap_bound(g.surface(n.surface), pt.s0, pt.s1, pt.t0, pt.t1, pt.bound);
            continue;
        }
        const HierarchyNode& a = h->nodes[static_cast<std::size_t>(n.child[0])];
        const HierarchyNode& b = h->nodes[static_cast<std::size_t>(n.child[1])];
        n.area = a.area + b.area;
        const Patch& lo = g.patch(g.patch_index(n.surface, n.is0, n.it0));
        const Patch& hi = g.patch(g.patch_index(n.surface, n.is1 - 1, n.it1 - 1));
        n.bound = cap_bound(g.surface(n.surface), lo.s0, hi.s1, lo.t0, hi.t1, enclose(a.bound, b.bound));
    }
}

struct Rect {
    double s0, s1, t0, t1;
};

Rect node_rect(const SceneGeometry& g, const HierarchyNode& n) {
    const Patch& lo = g.patch(g.patch_index(n.surface, n.is0, n.it0));
    const Patch& hi = g.patch(g.patch_index(n.surface, n.is1 - 1, n.it1 - 1));
    return {lo.s0, hi.s1, lo.t0, hi.t1};
}

// m x m Gauss points of every node, node after node.
std::vector<Sample> node_samples(const SceneGeometry& g, const Hierarchy& h, int m) {
    const GaussRule rule = gauss_legendre(m);
    std::vector<Sample> out;
    out.reserve(h.nodes.size() * static_cast<std::size_t>(m * m));
    for (const HierarchyNode& n : h.nodes) {
        Patch rect_only;  // quadrature_points reads the parameter rectangle only
        const Rect r = node_rect(g, n);
        rect_only.s0 = r.s0, rect_only.s1 = r.s1, rect_only.t0 = r.t0, rect_only.t1 = r.t1;
        const std::vector<QuadPoint> qs = quadrature_points(g.surface(n.surface), rect_only, rule);
        for (std::size_t k = 0; k < qs.size(); ++k) {  // s inner, t outer (cubature.h)
            const double w = glm::length(qs[k].nw);
            out.push_back({qs[k].x, w > 0.0 ? qs[k].nw / w : Vec3(0.0), w,
                           rule.x[k % static_cast<std::size_t>(m)], rule.x[k / static_cast<std::size_t>(m)]});
        }
    }
    return out;
}

// Each node's area centroid in its own (u, v), from m x m Gauss points.
void node_centroids(const SceneGeometry& g, int m, Hierarchy* h) {
    const std::vector<Sample> samples = node_samples(g, *h, m);
    const std::size_t mm = static_cast<std::size_t>(m * m);
    for (std::size_t i = 0; i < h->nodes.size(); ++i) {
        double w = 0.0, wu = 0.0, wv = 0.0;
        for (std::size_t a = i * mm; a < (i + 1) * mm; ++a) {
            w += samples[a].w;
            wu += samples[a].w * samples[a].u;
            wv += samples[a].w * samples[a].v;
        }
        if (w > 0.0) h->nodes[i].cu = wu / w, h->nodes[i].cv = wv / w;
    }
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
        std::size_t total = 0;
        for (const auto& local : m_links)
            for (const auto& chunk : local) total += chunk.size();
        h->links.reserve(h->links.size() + total);
        for (auto& local : m_links)
            for (auto& chunk : local) {
                h->links.insert(h->links.end(), chunk.begin(), chunk.end());
                std::vector<Link>().swap(chunk);
            }
        tbb::parallel_sort(h->links.begin(), h->links.end(), [](const Link& a, const Link& b) {
            return a.receiver != b.receiver ? a.receiver < b.receiver : a.source < b.source;
        });
        for (const FormFactorStats& s : m_leaf_stats) h->leaf_stats += s;
        h->stats.node_pairs = m_node_pairs;
        h->stats.kernel_samples = m_kernel_samples;
        h->stats.dropped = m_dropped;
        h->stats.leaf_links = m_leaf_links;
    }

private:
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

    // A link r <- s's slopes from the fits of F(x -> s) over r and of F(y -> r) over s.
    static Slopes slopes(const HierarchyNode& r, const LinearFit& over_r, const HierarchyNode& s,
                         const LinearFit& over_s) {
        Slopes k;
        if (!r.leaf()) k.gs = over_r.gs, k.gt = over_r.gt;
        if (!s.leaf()) k.cs = over_s.ms / r.area, k.ct = over_s.mt / r.area;
        return k;
    }
    bool add(int r, int s, double f, double e, const Slopes& k = {}) {
        if (f == 0.0 && e == 0.0) return false;
        auto& local = m_links.local();
        if (local.empty() || local.back().size() == kChunkLinks) local.emplace_back().reserve(kChunkLinks);
        local.back().push_back({r, s, f, e, k.gs, k.gt, k.cs, k.ct});
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
            const double reach =
                glm::length(a.center + t * e - ball.center) + (1.0 - t) * a.radius + t * b.radius;
            if (reach < ball.radius - m_eps &&
                glm::length(a.center - ball.center) > ball.radius + a.radius + m_eps &&
                glm::length(b.center - ball.center) > ball.radius + b.radius + m_eps)
                return true;
        }
        return false;
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
        std::vector<int> out;
        for (int k = 0; k < m_g.surface_count(); ++k) {
            bool own = false;
            if (own_surface_clear(m_g, node(p).surface, node(q).surface, k, &own)) continue;
            if (const auto pl = m_g.surface(k).plane()) {
                const auto range = [&](const HierarchyNode& n, const Rect& r) {
                    const auto [lo, hi] = m_g.surface(n.surface).linear_range(pl->normal, r.s0, r.s1, r.t0, r.t1);
                    return std::pair{lo - pl->offset, hi - pl->offset};
                };
                if (one_side_of_plane(range(node(p), rp), range(node(q), rq), m_cull_eps)) continue;
            }
            const BoundingSphere& s = m_g.surface_bound(k);
            const Vec3 oc = s.center - a.center;
            const double t = l2 > 0.0 ? std::clamp(glm::dot(oc, e) / l2, 0.0, 1.0) : 0.0;
            const double reach = s.radius + std::max(a.radius, b.radius) + m_eps;
            if (glm::length(oc - t * e) <= reach) out.push_back(k);
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
    };
    Coupling sample(int p, int q) const {
        const std::size_t mm = static_cast<std::size_t>(m_m * m_m);
        const BlockerSet guard(m_g, m_leaf.visibility ? blockers(p, q) : std::vector<int>{});
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
        const Coupling c = sample(p, q);
        // The error of p's gather over the link, per unit of radiosity: each side's plane carries
        // its slopes (the receiver's, and the source's against its radiosity slopes), so what the
        // planes leave is the estimate: the receiver's residual (none when p is one patch), the
        // source's per unit area of p (none when q is one patch), and the quadrature's.
        const double rp = a.leaf() ? 0.0 : c.fit_p.residual_spread;
        const double rq = b.leaf() ? 0.0 : c.fit_q.residual_spread;
        const double e_pq = rp + (rq * b.area + c.quadrature) / a.area;
        const double e_qp = rq + (rp * a.area + c.quadrature) / b.area;
        if (c.any && !c.horizon && std::max(e_pq, e_qp) <= m_o.tolerance) {
            add(p, q, c.g / a.area, e_pq, slopes(a, c.fit_p, b, c.fit_q));
            add(q, p, c.g / b.area, e_qp, slopes(b, c.fit_q, a, c.fit_p));
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
        // Split the larger node (a leaf is never split).
        const bool split_a = !a.leaf() && (b.leaf() || a.area >= b.area);
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
    // Each thread's links in chunks of kChunkLinks, never one array that doubles: a chunk is
    // large enough that malloc maps it apart (its untouched tail costs nothing resident), and
    // freeing it returns its memory.
    static constexpr std::size_t kChunkLinks = std::size_t{1} << 20;  // 56 MB
    tbb::enumerable_thread_specific<std::vector<std::vector<Link>>> m_links;
    tbb::enumerable_thread_specific<FormFactorStats> m_leaf_stats;
    mutable std::atomic<long long> m_node_pairs{0}, m_kernel_samples{0}, m_dropped{0}, m_leaf_links{0};
};

}  // namespace

namespace {

template <class T>
std::vector<T> irradiance_of(const Hierarchy& h, const std::vector<T>& B) {
    const std::size_t n = h.nodes.size();
    std::vector<T> b(n, T(0.0)), bs(n, T(0.0)), bt(n, T(0.0));
    for (std::size_t i = n; i-- > 0;) {  // pull: children come after their parent
        const HierarchyNode& d = h.nodes[i];
        if (d.leaf()) {
            b[i] = B[static_cast<std::size_t>(d.patch)];
            continue;
        }
        const std::size_t k0 = static_cast<std::size_t>(d.child[0]),
                          k1 = static_cast<std::size_t>(d.child[1]);
        const double a0 = h.nodes[k0].area / d.area, a1 = h.nodes[k1].area / d.area;
        b[i] = a0 * b[k0] + a1 * b[k1];
        // The halves' area centroids lie centroid_gap apart in the node's u (or v).
        const bool along_s = h.nodes[k0].is1 != d.is1;
        (along_s ? bs : bt)[i] = (b[k1] - b[k0]) / h.centroid_gap(d);
        (along_s ? bt : bs)[i] = a0 * (along_s ? bt : bs)[k0] + a1 * (along_s ? bt : bs)[k1];
    }
    std::vector<T> hh(n, T(0.0)), hs(n, T(0.0)), ht(n, T(0.0));
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t r) {
        T sum(0.0), ss(0.0), st(0.0);
        for (auto l = h.first_link[r]; l < h.first_link[r + 1]; ++l) {
            const Link& k = h.links[static_cast<std::size_t>(l)];
            const std::size_t q = static_cast<std::size_t>(k.source);
            sum += k.f * b[q] + k.cs * bs[q] + k.ct * bt[q];
            ss += k.gs * b[q];
            st += k.gt * b[q];
        }
        hh[r] = sum, hs[r] = ss, ht[r] = st;
    });
    return h.push_linear(std::move(hh), std::move(hs), std::move(ht));
}

}  // namespace

std::vector<double> Hierarchy::irradiance(const std::vector<double>& B) const {
    return irradiance_of(*this, B);
}
std::vector<Rgb> Hierarchy::irradiance(const std::vector<Rgb>& B) const { return irradiance_of(*this, B); }

std::vector<double> Hierarchy::row_sums() const {
    return irradiance(std::vector<double>(leaf_of_patch.size(), 1.0));
}

FormFactors expand_links(const Hierarchy& h, const SceneGeometry& g) {
    const int n = g.patch_count();
    const std::size_t un = static_cast<std::size_t>(n);
    FormFactors ff;
    ff.F = DenseMatrix(n);
    ff.error.assign(un * un, 0.0);
    for (int i = 0; i < n; ++i) ff.area.push_back(g.patch(i).area);
    // Column j: the irradiance from radiosity 1 on patch j alone, as the solve gathers it.
    std::vector<double> unit(un, 0.0);
    for (std::size_t j = 0; j < un; ++j) {
        unit[j] = 1.0;
        const std::vector<double> column = h.irradiance(unit);
        unit[j] = 0.0;
        for (std::size_t i = 0; i < un; ++i) ff.F.data[i * un + j] = column[i];
    }
    // Estimates: each link's, shared by area among its source's patches, at each receiver patch.
    const auto patches = [&](const HierarchyNode& a) {
        std::vector<int> out;
        for (int it = a.it0; it < a.it1; ++it)
            for (int is = a.is0; is < a.is1; ++is) out.push_back(g.patch_index(a.surface, is, it));
        return out;
    };
    for (const Link& l : h.links) {
        const HierarchyNode& q = h.nodes[static_cast<std::size_t>(l.source)];
        const std::vector<int> js = patches(q);
        for (const int i : patches(h.nodes[static_cast<std::size_t>(l.receiver)]))
            for (const int j : js)
                ff.error[static_cast<std::size_t>(i) * un + static_cast<std::size_t>(j)] +=
                    l.error * ff.area[static_cast<std::size_t>(j)] / q.area;
    }
    ff.stats = h.leaf_stats;
    return ff;
}

std::size_t hierarchy_bytes(const Hierarchy& h) {
    return h.nodes.capacity() * sizeof(HierarchyNode) + h.links.capacity() * sizeof(Link) +
           h.first_link.capacity() * sizeof(std::int64_t) + h.leaf_of_patch.capacity() * sizeof(int);
}

FormFactorChecks check_hierarchy(const Hierarchy& h, double leaf_tolerance) {
    FormFactorChecks c;
    const std::vector<double> rows = h.row_sums();
    for (std::size_t i = 0; i < rows.size(); ++i)
        if (const double e = std::abs(rows[i] - 1.0); c.closure_worst_patch < 0 || e > c.closure_max_error) {
            c.closure_max_error = e;
            c.closure_worst_patch = static_cast<int>(i);
        }
    std::vector<double> node_err(h.nodes.size(), 0.0);
    for (const Link& l : h.links) {
        const HierarchyNode& p = h.nodes[static_cast<std::size_t>(l.receiver)];
        const HierarchyNode& q = h.nodes[static_cast<std::size_t>(l.source)];
        node_err[static_cast<std::size_t>(l.receiver)] += l.error;
        c.min_entry = std::min(c.min_entry, l.f);
        c.max_error_estimate = std::max(c.max_error_estimate, l.error);
        const double target =
            p.leaf() && q.leaf() ? leaf_tolerance * std::min(p.area, q.area) / p.area : h.options.tolerance;
        if (l.error > target) {
            ++c.entries_over_tolerance;
            if (l.error / target > c.worst_miss_ratio) {
                c.worst_miss_ratio = l.error / target;
                c.worst_miss_estimate = l.error;
                c.worst_miss_i = p.leaf() ? p.patch : -1;
                c.worst_miss_j = q.leaf() ? q.patch : -1;
            }
        }
        // The reverse link, if any (a pair proven or sampled to exchange nothing has neither).
        const auto b = h.links.begin() + h.first_link[static_cast<std::size_t>(l.source)];
        const auto e = h.links.begin() + h.first_link[static_cast<std::size_t>(l.source) + 1];
        const auto r = std::lower_bound(b, e, l.receiver, [](const Link& k, int v) { return k.source < v; });
        const double g = p.area * l.f, g_rev = r != e && r->source == l.receiver ? q.area * r->f : 0.0;
        if (const double top = std::max(g, g_rev); top > 0.0) {
            c.reciprocity_max_error = std::max(c.reciprocity_max_error, std::abs(g - g_rev) / top);
            c.reciprocity_abs_error = std::max(c.reciprocity_abs_error, std::abs(g - g_rev) / p.area);
            const double est =
                p.area * l.error + (r != e && r->source == l.receiver ? q.area * r->error : 0.0);
            if (est > 0.0)
                c.reciprocity_vs_estimate = std::max(c.reciprocity_vs_estimate, std::abs(g - g_rev) / est);
        }
    }
    const std::vector<double> row_err = h.to_patches(std::move(node_err));
    for (const double e : row_err) c.max_row_error_estimate = std::max(c.max_row_error_estimate, e);
    return c;
}

Hierarchy hierarchy_nodes(const SceneGeometry& geometry, const HierarchyOptions& options) {
    Hierarchy h;
    h.options = options;
    build_nodes(geometry, &h);
    node_centroids(geometry, options.samples, &h);
    h.first_link.assign(h.nodes.size() + 1, 0);
    return h;
}

void index_links(Hierarchy* h) {
    h->first_link.assign(h->nodes.size() + 1, 0);
    for (const Link& l : h->links) ++h->first_link[static_cast<std::size_t>(l.receiver) + 1];
    for (std::size_t i = 1; i < h->first_link.size(); ++i) h->first_link[i] += h->first_link[i - 1];
    h->stats.links = static_cast<long long>(h->links.size());
}

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
