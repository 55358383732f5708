// The hierarchy's nodes: a binary tree over each surface's patch grid, with areas, bounding
// spheres (caps on spheres) and area centroids (formfactor/hierarchy.h).
#include "formfactor/hierarchy_nodes.h"

#include <algorithm>
#include <cmath>

#include "util/gauss_legendre.h"

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

}  // namespace

Rect node_rect(const SceneGeometry& g, const HierarchyNode& n) {
    const Patch& lo = g.patch(g.patch_index(n.surface, n.is0, n.it0));
    const Patch& hi = g.patch(g.patch_index(n.surface, n.is1 - 1, n.it1 - 1));
    return {lo.s0, hi.s1, lo.t0, hi.t1};
}

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

namespace {

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

}  // namespace

Hierarchy hierarchy_nodes(const SceneGeometry& geometry, const HierarchyOptions& options) {
    Hierarchy h;
    h.options = options;
    build_nodes(geometry, &h);
    node_centroids(geometry, options.samples, &h);
    h.first_link.assign(h.nodes.size() + 1, 0);
    return h;
}

}  // namespace radiosa
