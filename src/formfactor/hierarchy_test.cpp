// Hierarchical form factors and the link solve against the dense path, on scenes whose
// answers are known: the dense matrix (itself checked against closed forms elsewhere), exact
// reciprocity, closure of closed scenes, and parallel squares' closed form.
#include "formfactor/hierarchy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "../tests/test_scenes.h"
#include "formfactor/analytic.h"
#include "solve/link_solver.h"

namespace radiosa {
namespace {

// The seed scene with every face split f x f and the sphere split 2f x f... (sphere s x t).
Scene seed_scene(int face, int sphere_s, int sphere_t) {
    std::ifstream in(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = ss.str();
    const std::string faces = "patches: [3, 3]";
    for (std::size_t at = text.find(faces); at != std::string::npos; at = text.find(faces, at + 1))
        text.replace(at, faces.size(),
                     "patches: [" + std::to_string(face) + ", " + std::to_string(face) + "]");
    const std::string sph = "patches: [8, 4]";
    const std::size_t at = text.find(sph);
    if (at != std::string::npos)
        text.replace(at, sph.size(),
                     "patches: [" + std::to_string(sphere_s) + ", " + std::to_string(sphere_t) + "]");
    return parse_scene(text, "seed.yaml");
}

struct Compared {
    double max_rel = 0.0;  // max over channels of max |B_h - B_d| / max B_d
    Hierarchy h;
};

Compared compare_with_dense(const Scene& scene, const HierarchyOptions& ho) {
    const SceneGeometry g(scene);
    const Materials m = patch_materials(scene);
    const FormFactorOptions leaf = FormFactorOptions::adaptive(1e-6);
    Compared c;
    c.h = build_hierarchy(g, ho, leaf);
    const LinkSolution hs = solve_links(c.h, m.rho, m.E);
    const FormFactors ff = compute_form_factors(g, leaf);
    const RadiositySolver solver(ff.F, m.rho, SolverMethod::LU);
    const std::vector<Rgb> bd = solver.solve(m.E);
    for (int ch = 0; ch < 3; ++ch) {
        double top = 0.0, diff = 0.0;
        for (std::size_t i = 0; i < bd.size(); ++i) {
            top = std::max(top, bd[i][ch]);
            diff = std::max(diff, std::abs(hs.B[i][ch] - bd[i][ch]));
        }
        if (top > 0.0) c.max_rel = std::max(c.max_rel, diff / top);
    }
    std::printf(
        "patches %zu nodes %zu links %lld (leaf %lld) dense pairs %d: max |dB|/max B = %.3g, hier %.3f s, "
        "dense %.3f s, sweeps %d\n",
        bd.size(), c.h.nodes.size(), c.h.stats.links, c.h.stats.leaf_links,
        g.patch_count() * (g.patch_count() + 1) / 2, c.max_rel, c.h.stats.seconds, ff.stats.seconds,
        hs.sweeps);
    return c;
}

// At 86 patches every link joins two patches: this checks the link solve (gather, push, pull,
// stopping rule) against LU on the same entries; the next test covers links between nodes.
TEST(Hierarchy, SeedSceneMatchesTheDenseSolve) {
    const Compared c = compare_with_dense(seed_scene(3, 8, 4), {});
    EXPECT_LE(c.max_rel, 1e-4);
}

TEST(Hierarchy, LinksAreReciprocalAndRowsCloseInAClosedScene) {
    const Scene scene = seed_scene(6, 16, 8);  // 344 patches: enough for links above them
    const SceneGeometry g(scene);
    HierarchyOptions o;
    o.tolerance = 1e-3;
    std::atomic<long long> covered{0};
    const Hierarchy h = build_hierarchy(g, o, FormFactorOptions::adaptive(1e-6),
                                        [&covered](long long pairs) { covered += pairs; });
    // The progress counts every pair of patches once, whether a link, a leaf pair or a proof
    // settled it (the progress bar ends at 100 %).
    const long long n = g.patch_count();
    EXPECT_EQ(covered.load(), n * (n + 1) / 2);
    EXPECT_GT(h.stats.dropped, 0);
    // Every link between two nodes has its reverse with A_p f_pq = A_q f_qp; the links between
    // two patches are held apart, without slopes.
    long long node_links = 0;
    for (const Link& l : h.links) {
        const HierarchyNode& p = h.nodes[static_cast<std::size_t>(l.receiver)];
        const HierarchyNode& q = h.nodes[static_cast<std::size_t>(l.source)];
        EXPECT_FALSE(p.leaf() && q.leaf());
        ++node_links;
        const auto b = h.links.begin() + h.first_link[static_cast<std::size_t>(l.source)];
        const auto e = h.links.begin() + h.first_link[static_cast<std::size_t>(l.source) + 1];
        const auto r = std::find_if(b, e, [&](const Link& k) { return k.source == l.receiver; });
        ASSERT_NE(r, e);
        EXPECT_NEAR(p.area * l.f, q.area * r->f, 1e-14 * p.area * l.f);
    }
    EXPECT_GT(node_links, 0);  // some coupling above the patches: not the dense matrix in disguise
    for (const PairLink& l : h.pair_links) {
        EXPECT_TRUE(h.nodes[static_cast<std::size_t>(l.receiver)].leaf());
        EXPECT_TRUE(h.nodes[static_cast<std::size_t>(l.source)].leaf());
    }
    EXPECT_EQ(static_cast<long long>(h.pair_links.size()), h.stats.leaf_links);
    EXPECT_EQ(h.link_count(), h.stats.links);
    // The cube is closed: each patch's links (its own and its ancestors') sum to 1 within the
    // sum of their estimates.
    std::vector<double> node_err(h.nodes.size(), 0.0);
    h.for_each_link([&](int r, int, double e) { node_err[static_cast<std::size_t>(r)] += e; });
    const std::vector<double> err = h.to_patches(std::move(node_err));
    const std::vector<double> rows = h.row_sums();
    for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_NEAR(rows[i], 1.0, err[i]) << i;
}

// Every node's bounding sphere holds its part of the surface: on spheres, whole, partial and
// placed, each node's cap bound (tighter than the patches' own, the whole sphere) is checked
// against a 9 x 9 grid of its points, and is smaller than the whole sphere.
TEST(Hierarchy, NodeBoundsHoldTheirSurface) {
    const Scene scene = parse_scene(
        "closed: false\nsurfaces:\n"
        "  - {name: ball, type: sphere, center: [0, 0, 0], radius: 1, patches: [16, 8], reflectance: [0.5, "
        "0.5, "
        "0.5]}\n"
        "  - {name: dome, type: sphere, center: [4, 0, 0], radius: 2, facing: inward, polar_deg: [20, 110],\n"
        "     angles_deg: [30, 300], patches: [7, 5], reflectance: [0.5, 0.5, 0.5],\n"
        "     transform: {scale: 0.5, rotate_deg: {axis: [1, 1, 0], angle: 40}, translate: [0, 3, 1]}}\n",
        "bounds.yaml");
    const SceneGeometry g(scene);
    HierarchyOptions o;
    o.tolerance = 0.1;  // the nodes are what is checked, not the links
    const Hierarchy h = build_hierarchy(g, o, FormFactorOptions::adaptive(1e-3));
    int tighter = 0;
    for (const HierarchyNode& n : h.nodes) {
        const Patch& lo = g.patch(g.patch_index(n.surface, n.is0, n.it0));
        const Patch& hi = g.patch(g.patch_index(n.surface, n.is1 - 1, n.it1 - 1));
        for (int a = 0; a <= 8; ++a)
            for (int b = 0; b <= 8; ++b) {
                const Vec3 x = g.surface(n.surface).point(lo.s0 + (hi.s1 - lo.s0) * a / 8.0,
                                                          lo.t0 + (hi.t1 - lo.t0) * b / 8.0);
                ASSERT_LE(glm::length(x - n.bound.center), n.bound.radius * (1.0 + 1e-12))
                    << g.surface_name(n.surface) << " [" << n.is0 << ", " << n.is1 << ") x [" << n.it0 << ", "
                    << n.it1 << ")";
            }
        tighter += n.bound.radius < 0.99 * g.surface_bound(n.surface).radius;
    }
    EXPECT_GT(tighter, static_cast<int>(h.nodes.size()) * 3 / 4);
}

}  // namespace
}  // namespace radiosa

namespace radiosa {
namespace {

// Two parallel 2 x 2 squares 1 apart, 16 x 16 patches each: links join groups of patches, and
// the row sums F(patch -> other square), pushed down with the links' slopes, follow the
// patches' own integrals; their area-weighted sum is the closed form for the squares.
TEST(Hierarchy, SlopesCarryTheFactorAcrossALink) {
    const Scene scene = parse_scene(
        "closed: false\nsurfaces:\n"
        "  - {name: low, type: quad, corners: [[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], patches: [16, "
        "16],\n"
        "     reflectance: [0.5, 0.5, 0.5]}\n"
        "  - {name: high, type: quad, corners: [[0, 0, 1], [0, 2, 1], [2, 2, 1], [2, 0, 1]], patches: [16, "
        "16],\n"
        "     reflectance: [0.5, 0.5, 0.5]}\n",
        "squares.yaml");
    const SceneGeometry g(scene);
    HierarchyOptions o;
    o.tolerance = 1e-4;
    const Hierarchy h = build_hierarchy(g, o, FormFactorOptions::adaptive(1e-6));
    EXPECT_LT(h.stats.leaf_links, h.stats.links / 2);  // most coupling is between groups
    const FormFactors dense = compute_form_factors(g, FormFactorOptions::adaptive(1e-6));
    const std::vector<double> rows = h.row_sums();
    double worst = 0.0, total = 0.0, area = 0.0;
    for (int i = 0; i < g.patch_count(); ++i) {
        double d = 0.0;
        for (int j = 0; j < g.patch_count(); ++j) d += dense.F(i, j);
        worst = std::max(worst, std::abs(rows[static_cast<std::size_t>(i)] - d));
        if (g.patch(i).surface == 0) {
            total += g.patch(i).area * rows[static_cast<std::size_t>(i)];
            area += g.patch(i).area;
        }
    }
    std::printf("links %lld (%lld between patches), max |row - dense row| %.2e\n", h.stats.links,
                h.stats.leaf_links, worst);
    EXPECT_LT(worst, 2e-4);
    EXPECT_NEAR(total / area, analytic::parallel_rectangles(2.0, 2.0, 1.0), 1e-5);
}

// Two facing squares with a whole ball between them: with a ball of radius 1 every segment
// between them passes through it (the exact factor is 0), which a bound on the nodes' balls
// proves once for the whole pair of surfaces, so no link and no pair of patches joins them;
// with a ball of radius 0.3 part of each square sees the other, and the links give the dense
// matrix's entries.
TEST(Hierarchy, ABallBetweenTwoSquaresHidesThemWhollyOrInPart) {
    for (const double radius : {1.0, 0.3}) {
        const Scene scene = parse_scene(
            "closed: false\nsurfaces:\n"
            "  - {name: low, type: quad, corners: [[-0.5, -0.5, -2], [0.5, -0.5, -2], [0.5, 0.5, -2], "
            "[-0.5, 0.5, -2]],\n     patches: [4, 4], reflectance: [0.5, 0.5, 0.5]}\n"
            "  - {name: high, type: quad, corners: [[-0.5, -0.5, 2], [-0.5, 0.5, 2], [0.5, 0.5, 2], "
            "[0.5, -0.5, 2]],\n     patches: [4, 4], reflectance: [0.5, 0.5, 0.5]}\n"
            "  - {name: ball, type: sphere, center: [0, 0, 0], radius: " +
                std::to_string(radius) + ", patches: [8, 4], reflectance: [0.5, 0.5, 0.5]}\n",
            "ball-between.yaml");
        const SceneGeometry g(scene);
        HierarchyOptions o;
        o.tolerance = 1e-4;
        const Hierarchy h = build_hierarchy(g, o, FormFactorOptions::adaptive(1e-6));
        long long between = 0;
        h.for_each_link([&](int r, int s, double) {
            between +=
                h.nodes[static_cast<std::size_t>(r)].surface + h.nodes[static_cast<std::size_t>(s)].surface ==
                1;
        });
        const FormFactors links = expand_links(h, g);
        const FormFactors dense = compute_form_factors(g, FormFactorOptions::adaptive(1e-6));
        double worst = 0.0, most = 0.0;
        for (int i = 0; i < 16; ++i)
            for (int j = 16; j < 32; ++j) {
                worst = std::max(worst, std::abs(links.F(i, j) - dense.F(i, j)));
                most = std::max(most, dense.F(i, j));
            }
        if (radius == 1.0) {
            EXPECT_EQ(between, 0);
            EXPECT_GE(h.stats.dropped, 1);
            EXPECT_LT(most, 1e-12);  // the dense path agrees: nothing passes
        } else {
            EXPECT_GT(between, 0);
            EXPECT_GT(most, 1e-4);
        }
        EXPECT_LT(worst, 1e-4) << radius;
    }
}

// The pairs of patches under a hierarchy are integrated in one direction at a tenth of the link
// tolerance: each one's value is within its estimate of a reference at tolerance 1e-9, on the
// kinds of pairs the 20,000-patch room is made of: a ball's patches toward squares past their
// horizons, squares partly in the ball's shadow, squares side by side.
// Every link within its tolerance still leaves a patch the sum of its ancestors' links' misfits,
// of one sign along the edges where two walls meet (a kernel convex across its receiver lies
// above the fitted plane at the receiver's ends): the seed room at 1,376 patches and link
// tolerance 2e-4 has rows off by 1.5e-3. A receiver tolerance of an eighth holds each link's
// misfit as a receiver to it, and the rows close 4 times better (measured: 3.6e-4), every row
// within the sum of its links' estimates both ways.
TEST(Hierarchy, AReceiverToleranceClosesTheRows) {
    const SceneGeometry g(seed_scene(12, 32, 16));
    HierarchyOptions plain;
    plain.tolerance = 2e-4;
    HierarchyOptions held = plain;
    held.receiver_tolerance = plain.tolerance / 8.0;
    const FormFactorOptions leaf = FormFactorOptions::hierarchical(plain.tolerance);
    double closure[2] = {0.0, 0.0};
    long long links[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
        const Hierarchy h = build_hierarchy(g, k == 0 ? plain : held, leaf);
        const FormFactorChecks c = check_hierarchy(h, leaf.tolerance);
        closure[k] = c.closure_max_error;
        links[k] = h.link_count();
        EXPECT_LE(c.closure_max_error, c.max_row_error_estimate);
    }
    std::printf("closure %.3g -> %.3g, links %lld -> %lld\n", closure[0], closure[1], links[0], links[1]);
    EXPECT_GT(closure[0], 1e-3);
    EXPECT_LT(closure[1], closure[0] / 3.0);
    EXPECT_GT(links[1], links[0]);
}

TEST(Hierarchy, PairsOfPatchesAreWithinTheirEstimates) {
    const Scene scene = test::scene_of(test::ball_beside_walls());
    const SceneGeometry g(scene);
    HierarchyOptions o;
    o.tolerance = 1e-4;
    const Hierarchy h = build_hierarchy(g, o, FormFactorOptions::adaptive(1e-6));
    const FormFactors exact = compute_form_factors(g, FormFactorOptions::adaptive(1e-9));
    int checked = 0, shadowed = 0;
    for (const PairLink& l : h.pair_links) {
        const HierarchyNode& r = h.nodes[static_cast<std::size_t>(l.receiver)];
        const HierarchyNode& s = h.nodes[static_cast<std::size_t>(l.source)];
        const double err = std::abs(l.f - exact.F(r.patch, s.patch));
        const double ref = exact.error[static_cast<std::size_t>(r.patch) * exact.F.n + s.patch];
        EXPECT_LE(err, l.error + ref + 1e-15) << r.patch << " <- " << s.patch;
        ++checked;
        shadowed += r.surface + s.surface == 1 && l.error > 1e-12;  // floor and ceiling
    }
    std::printf("%d pairs of patches, %d floor-ceiling with an estimate\n", checked, shadowed);
    EXPECT_GT(checked, 500);
    EXPECT_GT(shadowed, 50);
}

// The patches under node n.
std::vector<int> patches_under(const Hierarchy& h, int n) {
    std::vector<int> out, stack{n};
    while (!stack.empty()) {
        const HierarchyNode& k = h.nodes[static_cast<std::size_t>(stack.back())];
        stack.pop_back();
        if (k.leaf())
            out.push_back(k.patch);
        else
            stack.insert(stack.end(), {k.child[0], k.child[1]});
    }
    return out;
}

// A ball's shadow on a wall can fall between a node's samples. In the seed room at 830 patches
// and link tolerance 1e-4, with the coupling of two wall nodes from kernel samples, 162 of the
// 47,678 links between wall nodes were off by more than their estimates (up to 1.9 times); with
// the exact point-to-node factors past the ball (point_to_polygon), none. Each link is pushed
// down to its receiver's patches (its plane) and compared with the sum of the patches' own
// factors to the source's patches at tolerance 1e-10 (what a uniform source gives), on every
// 20th link between two wall nodes.
TEST(Hierarchy, LinksPastABallAreWithinTheirEstimates) {
    const SceneGeometry g(seed_scene(10, 23, 10));
    HierarchyOptions o;
    o.tolerance = 1e-4;
    const Hierarchy h = build_hierarchy(g, o, FormFactorOptions::hierarchical(o.tolerance));
    const FormFactorRows exact(g, FormFactorOptions::adaptive(1e-10));
    const int ball = 6;
    int walls = 0, checked = 0;
    for (const Link& l : h.links) {
        const HierarchyNode& r = h.nodes[static_cast<std::size_t>(l.receiver)];
        const HierarchyNode& s = h.nodes[static_cast<std::size_t>(l.source)];
        if (r.surface == ball || s.surface == ball || walls++ % 20 != 0) continue;
        std::vector<double> f(h.nodes.size(), 0.0), fs(f), ft(f);
        f[static_cast<std::size_t>(l.receiver)] = l.f;
        fs[static_cast<std::size_t>(l.receiver)] = l.gs;
        ft[static_cast<std::size_t>(l.receiver)] = l.gt;
        const std::vector<double> pushed = h.push_linear(f, fs, ft);
        for (const int i : patches_under(h, l.receiver)) {
            double sum = 0.0;
            for (const int j : patches_under(h, l.source)) {
                FormFactorStats st;
                sum += exact.pair(i, j, &st).f_ij;
            }
            EXPECT_LE(std::abs(pushed[static_cast<std::size_t>(i)] - sum), l.error)
                << "patch " << i << " of link " << l.receiver << " <- " << l.source;
        }
        ++checked;
    }
    std::printf("%d links between wall nodes, %d checked\n", walls, checked);
    EXPECT_GT(checked, 2000);
}

}  // namespace
}  // namespace radiosa
