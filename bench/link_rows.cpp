// radiosa_link_rows SCENE SURFACE IS IT [RECEIVER_TOLERANCE] [--links]: what each link into one patch's
// row gives that patch, against the point-to-polygon formula integrated over the patch, level
// by level up its ancestors (docs/scale.md, "Receiver tolerance"). For rooms of quads around at
// most one whole ball, the seed scene's kind: the factor toward a quad node past the ball is
// Lambert's formula less the ball's cap (formfactor/point_polygon.h), integrated at 16 x 16
// points of the patch; links toward other surfaces are counted but not checked. The
// hierarchy is built at the scene's link tolerance (default 2e-5) with the given receiver
// tolerance (default none). --links also lists each link off by more than 3e-6.
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "cache/link_file.h"
#include "formfactor/hierarchy.h"
#include "formfactor/hierarchy_nodes.h"
#include "formfactor/point_polygon.h"
#include "scene/scene.h"

namespace radiosa {
namespace {

// F(patch -> the quad node q), past the ball when there is one, by the midpoint rule at n x n
// points of the patch.
double patch_to_node(const SceneGeometry& g, const Patch& p, const HierarchyNode& q,
                     const BoundingSphere* ball, int n) {
    const Surface& s = g.surface(p.surface);
    const Surface& qs = g.surface(q.surface);
    const Rect r = node_rect(g, q);
    const std::array<Vec3, 4> v = {qs.point(r.s0, r.t0), qs.point(r.s1, r.t0), qs.point(r.s1, r.t1),
                                   qs.point(r.s0, r.t1)};
    const std::array<Vec3, 4> w = {v[0], v[3], v[2], v[1]};  // either turn: the front one counts
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const double ps = p.s0 + (i + 0.5) / n * (p.s1 - p.s0), pt = p.t0 + (j + 0.5) / n * (p.t1 - p.t0);
            const Vec3 x = s.point(ps, pt), nx = glm::normalize(s.normal(ps, pt));
            sum += std::max(point_to_polygon(x, nx, v.data(), 4, ball),
                            point_to_polygon(x, nx, w.data(), 4, ball));
        }
    return sum / (n * n);
}

// What the links into receiver node r give patch p, what they should (patch_to_node), and how
// many there are; with `list`, each link off by more than 3e-6 is printed.
struct NodeRow {
    double given = 0.0, exact = 0.0;
    int count = 0;
};
NodeRow node_row(const Scene& scene, const SceneGeometry& g, const Hierarchy& h, int r, const Patch& p,
                 const BoundingSphere* ball, bool list) {
    const HierarchyNode& n = h.nodes[static_cast<std::size_t>(r)];
    const Rect rr = node_rect(g, n);
    // The patch's means of u and v over the node (the receiver's plane at the patch).
    const double mu = (p.s0 + p.s1 - rr.s0 - rr.s1) / (rr.s1 - rr.s0),
                 mv = (p.t0 + p.t1 - rr.t0 - rr.t1) / (rr.t1 - rr.t0);
    NodeRow row;
    const auto check = [&](int source, double value) {
        const HierarchyNode& q = h.nodes[static_cast<std::size_t>(source)];
        if (!g.surface(q.surface).plane()) return;
        const double e = patch_to_node(g, p, q, ball, 16);
        if (list && std::abs(value - e) > 3e-6)
            std::printf("  link from node %d (%s, %dx%d): %.4e, exact %.4e, %+.2e\n", source,
                        scene.surfaces[static_cast<std::size_t>(q.surface)].name.c_str(), q.is1 - q.is0,
                        q.it1 - q.it0, value, e, value - e);
        row.given += value, row.exact += e;
        ++row.count;
    };
    for (auto l = h.first_link[static_cast<std::size_t>(r)];
         l < h.first_link[static_cast<std::size_t>(r) + 1]; ++l) {
        const Link& k = h.links[static_cast<std::size_t>(l)];
        check(k.source, k.f + k.gs * (mu - n.cu) + k.gt * (mv - n.cv));
    }
    for (auto l = h.first_pair_link[static_cast<std::size_t>(r)];
         l < h.first_pair_link[static_cast<std::size_t>(r) + 1]; ++l)
        check(h.pair_links[static_cast<std::size_t>(l)].source, h.pair_links[static_cast<std::size_t>(l)].f);
    return row;
}

int run(int argc, char** argv) {
    if (argc < 5) {
        std::fprintf(stderr, "usage: radiosa_link_rows SCENE SURFACE IS IT [RECEIVER_TOLERANCE] [--links]\n");
        return 1;
    }
    const Scene scene = load_scene(argv[1]);
    const SceneGeometry g(scene);
    bool list = false;
    std::optional<double> receivers;
    for (int a = 5; a < argc; ++a) {
        if (std::string(argv[a]) == "--links")
            list = true;
        else
            receivers = std::atof(argv[a]);
    }
    const FormFactorOptions o = resolve_form_factor_options(scene.form_factors, "hierarchical", std::nullopt,
                                                            std::nullopt, std::nullopt, receivers);
    std::optional<BoundingSphere> ball;
    for (int k = 0; k < g.surface_count(); ++k) {
        const Surface& s = g.surface(k);
        if (s.plane() && s.patches_are_polygons()) continue;
        if (const auto b = s.sphere(); b && s.whole_sphere() && !ball) {
            ball = b;
            continue;
        }
        std::fprintf(stderr, "error: %s: quads around at most one whole ball only\n", argv[1]);
        return 1;
    }
    int surface = -1;
    for (int k = 0; k < g.surface_count(); ++k)
        if (scene.surfaces[static_cast<std::size_t>(k)].name == argv[2]) surface = k;
    const int is = std::atoi(argv[3]), it = std::atoi(argv[4]);
    if (surface < 0 || is < 0 || it < 0 || is >= g.ns(surface) || it >= g.nt(surface)) {
        std::fprintf(stderr, "error: no patch %s[%s,%s] in %s\n", argv[2], argv[3], argv[4], argv[1]);
        return 1;
    }
    const Hierarchy h = build_hierarchy(g, hierarchy_options(o), o);
    const int patch = g.patch_index(surface, is, it);
    const Patch& p = g.patch(patch);
    std::vector<int> parent(h.nodes.size(), -1);
    for (std::size_t i = 0; i < h.nodes.size(); ++i)
        for (const int c : h.nodes[i].child)
            if (c >= 0) parent[static_cast<std::size_t>(c)] = static_cast<int>(i);
    std::printf("%s[%d,%d], link tolerance %g, receiver tolerance %g\n", argv[2], is, it, o.link_tolerance,
                o.receiver_tolerance);
    std::printf("%-8s %-7s %6s %12s %12s %12s\n", "node", "patches", "links", "they give", "exact",
                "difference");
    double total = 0.0, total_exact = 0.0;
    for (int r = h.leaf_of_patch[static_cast<std::size_t>(patch)]; r >= 0;
         r = parent[static_cast<std::size_t>(r)]) {
        const HierarchyNode& n = h.nodes[static_cast<std::size_t>(r)];
        const NodeRow row = node_row(scene, g, h, r, p, ball ? &*ball : nullptr, list);
        if (row.count > 0)
            std::printf("%-8d %-7s %6d %12.4e %12.4e %+12.3e\n", r,
                        fmt::format("{}x{}", n.is1 - n.is0, n.it1 - n.it0).c_str(), row.count, row.given,
                        row.exact, row.given - row.exact);
        total += row.given, total_exact += row.exact;
    }
    std::printf(
        "toward the quads: %.6e, exact %.6e, difference %+.3e (pairs of touching patches: the\n"
        "midpoint rule is coarse there)\n",
        total, total_exact, total - total_exact);
    return 0;
}

}  // namespace
}  // namespace radiosa

int main(int argc, char** argv) {
    try {
        return radiosa::run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}
