#include "formfactor/hierarchy.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "formfactor/blocker_set.h"
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

struct Sample {
    Vec3 x;
    Vec3 n;    // unit front normal
    double w;  // area weight
};

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
            n.area = g.patch(n.patch).area;
            n.bound = g.patch(n.patch).bound;
            continue;
        }
        const HierarchyNode& a = h->nodes[static_cast<std::size_t>(n.child[0])];
        const HierarchyNode& b = h->nodes[static_cast<std::size_t>(n.child[1])];
        n.area = a.area + b.area;
        n.bound = enclose(a.bound, b.bound);
    }
}

struct Rect {
    double s0, s1, t0, t1;
};

class Refiner {
public:
    Refiner(const SceneGeometry& g, const HierarchyOptions& o, const FormFactorOptions& leaf, Hierarchy* h)
        : m_g(g), m_o(o), m_leaf(leaf), m_rows(g, leaf), m_h(*h), m_m(o.samples) {
        const GaussRule rule = gauss_legendre(m_m);
        m_samples.reserve(h->nodes.size() * static_cast<std::size_t>(m_m * m_m));
        for (std::size_t i = 0; i < h->nodes.size(); ++i) {
            Patch rect_only;  // quadrature_points reads the parameter rectangle only
            const Rect r = rect(static_cast<int>(i));
            rect_only.s0 = r.s0, rect_only.s1 = r.s1, rect_only.t0 = r.t0, rect_only.t1 = r.t1;
            for (const QuadPoint& q : quadrature_points(g.surface(h->nodes[i].surface), rect_only, rule)) {
                const double w = glm::length(q.nw);
                m_samples.push_back({q.x, w > 0.0 ? q.nw / w : Vec3(0.0), w});
            }
        }
        m_eps = 1e-9 * g.scale();
    }

    // Every pair of surfaces, and each surface that sees itself with itself.
    void run() {
        std::vector<std::pair<int, int>> tops;
        for (int k = 0; k < m_h.roots; ++k)
            for (int l = k; l < m_h.roots; ++l) {
                if (k == l && !m_g.surface(k).sees_itself()) continue;
                tops.emplace_back(k, l);
            }
        tbb::parallel_for(std::size_t{0}, tops.size(),
                          [&](std::size_t i) { refine(tops[i].first, tops[i].second); });
    }

    void collect(Hierarchy* h) {
        for (auto& local : m_links) h->links.insert(h->links.end(), local.begin(), local.end());
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
    Rect rect(int node) const {
        const HierarchyNode& n = m_h.nodes[static_cast<std::size_t>(node)];
        const Patch& lo = m_g.patch(m_g.patch_index(n.surface, n.is0, n.it0));
        const Patch& hi = m_g.patch(m_g.patch_index(n.surface, n.is1 - 1, n.it1 - 1));
        return {lo.s0, hi.s1, lo.t0, hi.t1};
    }
    const HierarchyNode& node(int i) const { return m_h.nodes[static_cast<std::size_t>(i)]; }

    void add(int r, int s, double f, double e) {
        if (f == 0.0 && e == 0.0) return;
        m_links.local().push_back({r, s, f, e});
    }

    // Proven to exchange nothing: one of the two lies behind (or in) the other's plane, the
    // two sides of a surface whose chords stay off it, or one surface that cannot see itself.
    bool proven_zero(int p, int q) const {
        const HierarchyNode& a = node(p);
        const HierarchyNode& b = node(q);
        if (a.surface == b.surface && !m_g.surface(a.surface).sees_itself()) return true;
        if (m_g.twin(a.surface) == b.surface && m_g.surface(a.surface).chords_never_cross()) return true;
        for (const auto& [x, y] : {std::pair{p, q}, std::pair{q, p}}) {
            const auto pl = m_g.surface(node(x).surface).plane();
            if (!pl) continue;
            const Rect r = rect(y);
            const auto range = m_g.surface(node(y).surface).linear_range(pl->normal, r.s0, r.s1, r.t0, r.t1);
            if (range.second - pl->offset <= m_eps) return true;
        }
        return false;
    }

    // Surfaces whose bounding spheres come near the segments between the two nodes.
    std::vector<int> blockers(int p, int q) const {
        const BoundingSphere& a = node(p).bound;
        const BoundingSphere& b = node(q).bound;
        const Vec3 e = b.center - a.center;
        const double l2 = glm::dot(e, e);
        std::vector<int> out;
        for (int k = 0; k < m_g.surface_count(); ++k) {
            const BoundingSphere& s = m_g.surface_bound(k);
            const Vec3 oc = s.center - a.center;
            const double t = l2 > 0.0 ? std::clamp(glm::dot(oc, e) / l2, 0.0, 1.0) : 0.0;
            const double reach = s.radius + std::max(a.radius, b.radius) + m_eps;
            if (glm::length(oc - t * e) <= reach) out.push_back(k);
        }
        return out;
    }

    // The coupling of two nodes from m x m samples on each: G = A_p F_pq = A_q F_qp, and how much
    // the point-to-node factors vary over each node: F(x -> q) over the samples x of p, and
    // F(y -> p) over those of q. A link hands every point of p the same F_pq, so that spread is
    // the error it makes in p's irradiance from a uniform q, per unit of q's radiosity.
    struct Coupling {
        double g = 0.0;
        double spread_p = 0.0, spread_q = 0.0;
        bool any = false;  // some sample pair sees each other
    };
    Coupling sample(int p, int q) const {
        const std::size_t mm = static_cast<std::size_t>(m_m * m_m);
        const BlockerSet guard(m_g, m_leaf.visibility ? blockers(p, q) : std::vector<int>{});
        const Sample* xs = &m_samples[static_cast<std::size_t>(p) * mm];
        const Sample* ys = &m_samples[static_cast<std::size_t>(q) * mm];
        std::vector<double> to_q(mm, 0.0), to_p(mm, 0.0);  // sum_b w_b K(x_a, y_b), sum_a w_a K
        Coupling c;
        long long tests = 0;
        for (std::size_t a = 0; a < mm; ++a)
            for (std::size_t b = 0; b < mm; ++b) {
                const Vec3 e = ys[b].x - xs[a].x;
                const double l2 = glm::dot(e, e);
                const double cx = glm::dot(xs[a].n, e), cy = -glm::dot(ys[b].n, e);
                if (!(cx > 0.0 && cy > 0.0 && l2 > 0.0)) continue;
                if (guard.blocked(xs[a].x, e, 1e-9, 1.0 - 1e-9, &tests)) continue;
                const double k = cx * cy / (kPi * l2 * l2);
                to_q[a] += ys[b].w * k;
                to_p[b] += xs[a].w * k;
                c.g += xs[a].w * ys[b].w * k;
                c.any = true;
            }
        const auto spread = [](const std::vector<double>& v) {
            const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
            return *hi - *lo;
        };
        c.spread_p = spread(to_q);
        c.spread_q = spread(to_p);
        m_kernel_samples += static_cast<long long>(mm * mm);
        return c;
    }

    void leaf_pair(int p, int q) {
        FormFactorStats& st = m_leaf_stats.local();
        const PairEntries e = m_rows.pair(node(p).patch, node(q).patch, &st);
        ++m_leaf_links;
        add(p, q, e.f_ij, e.e_ij);
        if (p != q) add(q, p, e.f_ji, e.e_ji);
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
        if (a.leaf() && b.leaf()) return leaf_pair(p, q);
        if (proven_zero(p, q)) {
            ++m_dropped;
            return;
        }
        const Coupling c = sample(p, q);
        if (c.any && std::max(c.spread_p, c.spread_q) <= m_o.tolerance) {
            add(p, q, c.g / a.area, c.spread_p);
            add(q, p, c.g / b.area, c.spread_q);
            return;
        }
        if (!c.any && far_apart(a.bound, b.bound)) {
            ++m_dropped;
            return;
        }
        // Split the larger node (a leaf is never split).
        const bool split_a = !a.leaf() && (b.leaf() || a.area >= b.area);
        const HierarchyNode& s = split_a ? a : b;
        const int other = split_a ? q : p, c0 = s.child[0], c1 = s.child[1];
        both(
            patches(a) + patches(b), [&] { refine(c0, other); }, [&] { refine(c1, other); });
    }
    static bool far_apart(const BoundingSphere& a, const BoundingSphere& b) {
        return a.radius + b.radius < kFarApart * glm::length(a.center - b.center);
    }

    static constexpr int kParallelPatches = 256;
    static constexpr double kFarApart = 0.25;
    const SceneGeometry& m_g;
    HierarchyOptions m_o;
    FormFactorOptions m_leaf;
    FormFactorRows m_rows;
    Hierarchy& m_h;
    int m_m;
    double m_eps = 0.0;
    std::vector<Sample> m_samples;
    tbb::enumerable_thread_specific<std::vector<Link>> m_links;
    tbb::enumerable_thread_specific<FormFactorStats> m_leaf_stats;
    mutable std::atomic<long long> m_node_pairs{0}, m_kernel_samples{0}, m_dropped{0}, m_leaf_links{0};
};

}  // namespace

std::vector<double> Hierarchy::row_sums() const {
    std::vector<double> node_sum(nodes.size(), 0.0);
    for (const Link& l : links) node_sum[static_cast<std::size_t>(l.receiver)] += l.f;
    return to_patches(std::move(node_sum));
}

Hierarchy build_hierarchy(const SceneGeometry& geometry, const HierarchyOptions& options,
                          const FormFactorOptions& leaf) {
    const Stopwatch clock;
    Hierarchy h;
    h.options = options;
    build_nodes(geometry, &h);
    Refiner refiner(geometry, options, leaf, &h);
    refiner.run();
    refiner.collect(&h);
    h.first_link.assign(h.nodes.size() + 1, 0);
    for (const Link& l : h.links) ++h.first_link[static_cast<std::size_t>(l.receiver) + 1];
    for (std::size_t i = 1; i < h.first_link.size(); ++i) h.first_link[i] += h.first_link[i - 1];
    h.stats.links = static_cast<long long>(h.links.size());
    h.stats.seconds = clock.seconds();
    return h;
}

}  // namespace radiosa
