#include "formfactor/form_factor.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include "../tests/test_scenes.h"
#include "formfactor/analytic.h"
#include "formfactor/point_polygon.h"
#include "geometry/scene_geometry.h"
#include "util/gauss_legendre.h"

namespace radiosa {

using test::quad;
using test::scene_of;

namespace {
FormFactors form_factors(const Scene& scene, int p, bool visibility = true) {
    return compute_form_factors(SceneGeometry(scene), FormFactorOptions::gauss(p, visibility));
}
double row_sum(const FormFactors& ff, int i) {
    double s = 0;
    for (int j = 0; j < ff.F.n; ++j) s += ff.F(i, j);
    return s;
}
}  // namespace

TEST(FormFactor, ParallelOpposedSquaresMatchAnalytic) {
    const Scene s = scene_of(quad("a", test::kFloor) + quad("b", test::kCeiling));
    const double exact = analytic::parallel_rectangles(1, 1, 1);
    EXPECT_NEAR(exact, 0.1998248957, 1e-10);  // the tabulated value
    EXPECT_NEAR(form_factors(s, 4).F(0, 1), exact, 1e-5);
    EXPECT_NEAR(form_factors(s, 8).F(0, 1), exact, 1e-10);
    EXPECT_NEAR(form_factors(s, 12).F(1, 0), exact, 1e-13);
}

TEST(FormFactor, ParallelRectanglesOfOtherProportions) {
    // 2 x 1 rectangles at distance 0.5: X = 4, Y = 2 (a harder, closer pair).
    const Scene s = scene_of(quad("a", "[[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]]") +
                             quad("b", "[[0, 0, 0.5], [0, 1, 0.5], [2, 1, 0.5], [2, 0, 0.5]]"));
    const double exact = analytic::parallel_rectangles(2, 1, 0.5);
    EXPECT_NEAR(form_factors(s, 16).F(0, 1), exact, 5e-7);  // measured 2.3e-7
    EXPECT_NEAR(form_factors(s, 24).F(0, 1), exact, 1e-9);  // measured 8.6e-11
}

TEST(FormFactor, PerpendicularSquaresSharingAnEdgeConvergeSlowly) {
    // The 1/L^4 kernel is singular along the shared edge: plain Gauss quadrature converges
    // only algebraically here (7 % error at p = 6). This is the known limit of the fixed
    // rule, measured so that it cannot silently get worse.
    const Scene s = scene_of(quad("floor", test::kFloor) + quad("wall", test::kWall));
    const double exact = analytic::perpendicular_rectangles(1, 1, 1);
    EXPECT_NEAR(exact, 0.2000437761, 1e-10);
    double previous = 1.0;
    for (int p : {2, 4, 8, 16, 32}) {
        const double err = std::abs(form_factors(s, p).F(0, 1) - exact);
        EXPECT_LT(err, previous) << "p=" << p;
        previous = err;
    }
    EXPECT_LT(previous, 0.025);  // p = 32
}

TEST(FormFactor, SphereInteriorIsAreaRatio) {
    // Inside a sphere the kernel cos cos / (pi L^2) is the constant 1/(4 pi R^2), so
    // F_ij = A_j / (4 pi R^2) for every pair, F_ii included (the patch sees itself).
    const Scene s = parse_scene(
        "surfaces:\n  - name: shell\n    type: sphere\n    center: [1, 2, 3]\n    radius: 2\n"
        "    facing: inward\n    patches: [8, 4]\n    reflectance: [0.5, 0.5, 0.5]\n",
        "shell.yaml");
    const SceneGeometry geo(s);
    // p = 8: the only error left is the Gauss rule's integral of the area element
    // (sin theta), 1.5e-10 relative at p = 4.
    const FormFactors ff = compute_form_factors(geo, FormFactorOptions::gauss(8, true));
    const double total = 4 * kPi * 4.0;
    for (int i = 0; i < 32; ++i) {
        for (int j = 0; j < 32; ++j)
            EXPECT_NEAR(ff.F(i, j), geo.patch(j).area / total, 1e-13) << i << "," << j;
        EXPECT_NEAR(row_sum(ff, i), 1.0, 1e-13);
    }
    EXPECT_GT(ff.F(0, 0), 0.0);
}

TEST(FormFactor, SphereInCubeSeesEachFaceEqually) {
    // A sphere centred in a cube sends 1/6 of its energy to each face (symmetry, closure).
    const Scene scene = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    const SceneGeometry geo(scene);
    const FormFactors ff = compute_form_factors(geo, FormFactorOptions::gauss(6, true));
    const int sphere = scene.find_surface("sphere");
    double to_face[6] = {0};
    for (int i = geo.first_patch(sphere); i < geo.first_patch(sphere) + 32; ++i) {
        EXPECT_NEAR(row_sum(ff, i), 1.0, 1e-4);  // measured 3.0e-5 at p = 6
        for (int k = 0; k < 6; ++k)
            for (int j = geo.first_patch(k); j < geo.first_patch(k) + 9; ++j)
                to_face[k] += geo.patch(i).area * ff.F(i, j) / (4 * kPi);
    }
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(to_face[k], 1.0 / 6.0, 2e-5) << geo.surface_name(k);
}

TEST(FormFactor, SeedSceneReciprocityClosureAndSigns) {
    const Scene scene = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    const FormFactors ff = form_factors(scene, 6);
    const FormFactorChecks c = check_form_factors(ff);
    EXPECT_LT(c.reciprocity_max_error, 1e-13);
    EXPECT_GE(c.min_entry, 0.0);
    // Closure is limited by patches that share an edge across the cube's edges (see
    // PerpendicularSquaresSharingAnEdgeConvergeSlowly): the fixed rule overestimates those
    // factors, so box rows sum to more than 1; measured max 1.142 at p = 6.
    EXPECT_LT(c.closure_max_error, 0.15);
    EXPECT_GT(c.closure_max_error, 0.10);
    for (int i = 0; i < ff.F.n; ++i) EXPECT_LE(row_sum(ff, i), 1.15);
    // Patches of one face never exchange energy.
    EXPECT_EQ(ff.F(0, 1), 0.0);
}

TEST(FormFactor, CoplanarAndBackToBackPairsAreCulled) {
    const Scene s = scene_of(quad("a", test::kFloor, 2, 2) +
                             quad("under", "[[0, 0, -1], [0, 1, -1], [1, 1, -1], [1, 0, -1]]"));
    const FormFactors ff = form_factors(s, 4);
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) EXPECT_EQ(ff.F(i, j), 0.0);
    // 4*5/2 = 10 unordered distinct pairs plus 5 self pairs; all 10 distinct ones culled.
    EXPECT_EQ(ff.stats.pairs, 15);
    EXPECT_EQ(ff.stats.pairs_culled, 10);
    EXPECT_EQ(ff.stats.segment_tests, 0);
}

TEST(FormFactor, OccluderBlocksAndVisibilityCanBeTurnedOff) {
    // A large two-sided blocker between two opposed squares.
    const std::string two = quad("a", test::kFloor) + quad("b", test::kCeiling);
    const std::string blocker = quad("mid", "[[-1, -1, 0.5], [2, -1, 0.5], [2, 2, 0.5], [-1, 2, 0.5]]");
    const Scene s = scene_of(two + blocker);
    EXPECT_EQ(form_factors(s, 6).F(0, 1), 0.0);
    EXPECT_NEAR(form_factors(s, 8, false).F(0, 1), analytic::parallel_rectangles(1, 1, 1), 1e-10);
    // A sphere between them takes away part, not all.
    const Scene ball = scene_of(two +
                                "  - name: ball\n    type: sphere\n    center: [0.5, 0.5, 0.5]\n"
                                "    radius: 0.2\n    patches: [4, 2]\n    reflectance: [0, 0, 0]\n");
    const FormFactors fb = form_factors(ball, 8);
    EXPECT_LT(fb.F(0, 1), 0.9 * analytic::parallel_rectangles(1, 1, 1));
    EXPECT_GT(fb.F(0, 1), 0.5 * analytic::parallel_rectangles(1, 1, 1));
    EXPECT_GT(fb.stats.segment_tests, 0);
}

namespace {
std::string ball(const std::string& name, double x, double y, double z, double r) {
    return "  - {name: " + name + ", type: sphere, center: [" + std::to_string(x) + ", " + std::to_string(y) +
           ", " + std::to_string(z) + "], radius: " + std::to_string(r) +
           ", patches: [4, 2], reflectance: [0, 0, 0]}\n";
}
}  // namespace

// Two balls between a floor of small patches and a one-patch ceiling, far enough apart that
// from no point of the floor do their shadows overlap, both between most floor patches and the
// ceiling: the parts they hide add up, so every floor-to-ceiling entry with both equals the
// entry with one plus the entry with the other minus the entry with neither, to the four
// estimates. With both balls every integral meets the tight tolerance (the closed-form shadow
// of each ball; the numeric path would stop at its region cap).
TEST(FormFactor, ShadowsOfBallsApartAddUp) {
    const std::string plates = quad("a", test::kFloor, 8, 8) + quad("b", test::kCeiling);
    const std::string b1 = ball("b1", 0.3, 0.5, 0.5, 0.05), b2 = ball("b2", 0.7, 0.45, 0.5, 0.05);
    const FormFactorOptions o = FormFactorOptions::adaptive(1e-9);
    const auto ff = [&](const std::string& extra) {
        return compute_form_factors(SceneGeometry(scene_of(plates + extra)), o);
    };
    const FormFactors f0 = ff(""), f1 = ff(b1), f2 = ff(b2), both = ff(b1 + b2);
    EXPECT_EQ(both.stats.capped, 0);
    int shadowed = 0;
    const int j = 64;  // the ceiling
    for (int i = 0; i < 64; ++i) {
        const auto at = [&](const FormFactors& f) { return f.F(i, j); };
        const auto err = [&](const FormFactors& f) {
            return f.error[static_cast<std::size_t>(i) * f.F.n + j];
        };
        EXPECT_NEAR(at(both), at(f1) + at(f2) - at(f0), err(both) + err(f1) + err(f2) + err(f0)) << i;
        EXPECT_LE(err(both), 1e-9) << i;
        shadowed += at(f0) - at(f1) > 1e-4 && at(f0) - at(f2) > 1e-4;
    }
    EXPECT_GT(shadowed, 20);  // floor patches both balls take something from
}

// Two balls one above the other: from the floor their shadows overlap, and the part they hide
// together is less than the sum of their parts (here by 14 % of the upper one's part).
TEST(FormFactor, ShadowsOfBallsThatOverlapAreNotAddedUp) {
    const std::string plates = quad("a", test::kFloor, 2, 2) + quad("b", test::kCeiling, 2, 2);
    const std::string low = ball("low", 0.5, 0.5, 0.3, 0.1), high = ball("high", 0.5, 0.5, 0.7, 0.1);
    const FormFactorOptions o = FormFactorOptions::adaptive(1e-7);
    const auto total = [&](const std::string& extra) {  // the floor's exchange with the ceiling
        const FormFactors f = compute_form_factors(SceneGeometry(scene_of(plates + extra)), o);
        double t = 0.0;
        for (int i = 0; i < 4; ++i)
            for (int j = 4; j < 8; ++j) t += f.area[static_cast<std::size_t>(i)] * f.F(i, j);
        return t;
    };
    const double t0 = total(""), tl = total(low), th = total(high), both = total(low + high);
    EXPECT_LT(both, tl);                                // the upper ball still hides something
    EXPECT_GT(both - (tl + th - t0), 0.1 * (t0 - th));  // but part of its shadow is already dark
}

// The same kind of pair with its shadows overlapping takes the balls' union in closed form
// (point_to_polygon_blocked_by_balls) instead of the numeric path: at tolerance 1e-8 no integral
// stops at its cap and each floor patch's entry toward the ceiling is, within its estimate, what
// a fine product rule over the patch (48 x 48 squares of 8 x 8 Gauss points) of the same closed
// form gives (that rule is within about 2e-9: 16 x 16 squares were 3e-8 off).
TEST(FormFactor, OverlappingShadowsOfBallsAreTheirUnionInClosedForm) {
    const std::string plates = quad("a", test::kFloor, 2, 2) + quad("b", test::kCeiling);
    const BoundingSphere balls[2] = {{{0.45, 0.5, 0.3}, 0.12}, {{0.6, 0.45, 0.65}, 0.12}};
    std::string extra;
    for (int k = 0; k < 2; ++k)
        extra += ball("b" + std::to_string(k), balls[k].center.x, balls[k].center.y, balls[k].center.z,
                      balls[k].radius);
    const FormFactors f =
        compute_form_factors(SceneGeometry(scene_of(plates + extra)), FormFactorOptions::adaptive(1e-8));
    EXPECT_EQ(f.stats.numeric, 0);
    EXPECT_EQ(f.stats.capped, 0);
    const Vec3 ceiling[4] = {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}};
    const GaussRule g = gauss_legendre(8);
    for (int i = 0; i < 4; ++i) {
        const double x0 = 0.5 * (i % 2), y0 = 0.5 * (i / 2), h = 0.5 / 48;
        double sum = 0.0;
        for (int a = 0; a < 48 * 8; ++a)
            for (int b = 0; b < 48 * 8; ++b) {
                const std::size_t ka = static_cast<std::size_t>(a % 8), kb = static_cast<std::size_t>(b % 8);
                const Vec3 x(x0 + h * ((a / 8) + 0.5 * (g.x[ka] + 1.0)),
                             y0 + h * ((b / 8) + 0.5 * (g.x[kb] + 1.0)), 0.0);
                const Vec3 n(0.0, 0.0, 1.0);
                sum += 0.25 * h * h * g.w[ka] * g.w[kb] *
                       (point_to_polygon(x, n, ceiling, 4, nullptr) -
                        point_to_polygon_blocked_by_balls(x, n, ceiling, 4, balls, 2));
            }
        const double err = f.error[static_cast<std::size_t>(i) * f.F.n + 4];
        EXPECT_LE(err, 1e-8) << i;
        EXPECT_NEAR(f.F(i, 4), sum / 0.25, err + 5e-9) << i;  // the product rule's own error: 2e-9
    }
}

// A dome (the upper half of a sphere) between two plates hides less than the whole ball: lines
// that cross only the ball's lower half pass under the dome. It is not a solid ball, so its
// shadow is not taken as a ball's cap (it was, and F came out as the ball's, 0.0839).
TEST(FormFactor, ADomeIsNotASolidBall) {
    const std::string plates = quad("a", test::kFloor) + quad("b", test::kCeiling);
    const std::string shape =
        "  - {name: d, type: sphere, center: [0.5, 0.5, 0.5], radius: 0.3, patches: [4, 2], ";
    const auto f_ab = [&](const std::string& extra) {
        return compute_form_factors(SceneGeometry(scene_of(plates + shape + extra)),
                                    FormFactorOptions::adaptive(1e-6))
            .F(0, 1);
    };
    const double whole = f_ab("reflectance: [0, 0, 0]}\n"),
                 dome = f_ab("polar_deg: [0, 90], reflectance: [0, 0, 0]}\n");
    EXPECT_NEAR(whole, 0.0839119, 1e-6);
    EXPECT_GT(dome, whole + 1e-3);
    EXPECT_LT(dome, analytic::parallel_rectangles(1, 1, 1));
}

// One thread and more threads than cores (8 on 2) give bit-identical matrices, for the fixed
// rule and for error control.
TEST(FormFactor, ResultDoesNotDependOnThreadCount) {
    const Scene scene = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    const SceneGeometry g(scene);
    for (const FormFactorOptions& o : {FormFactorOptions::gauss(4), FormFactorOptions::adaptive(1e-5)}) {
        auto with = [&](int threads) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
            return compute_form_factors(g, o);
        };
        const FormFactors single = with(1), many = with(8);
        EXPECT_EQ(many.F.data, single.F.data) << describe(o);
        EXPECT_EQ(many.error, single.error) << describe(o);
    }
}

namespace {

// A weighted sum of every entry and estimate: moves when any of them moves.
std::pair<double, double> fingerprint(const FormFactors& ff) {
    double f = 0.0, e = 0.0;
    for (int i = 0; i < ff.F.n; ++i)
        for (int j = 0; j < ff.F.n; ++j) {
            const double w = 1.0 + ((31 * i + 17 * j) % 97) / 97.0;
            f += w * ff.F(i, j);
            e += w * ff.error[static_cast<std::size_t>(i) * ff.F.n + j];
        }
    return {f, e};
}

}  // namespace

// A cached matrix is trusted by its key, and the key holds kFormFactorAlgorithmVersion: a change
// that moves computed form factors must bump it, or caches written before hand back the old
// values. These fingerprints of scenes that take every path (the seed scene's quads and ball;
// a disk, a tube, a cone and a dome in a box, two-sided; two balls in a box whose shadows
// overlap) were recorded at version 18 (19 moved only estimates larger than their entries can
// be off, which these scenes do not have; 20 only pairs past balls whose shadows overlap, the
// balls' box, recorded at 20; 21 only pairs of a ball and a flat patch whose bounding ball
// reaches into it, and the insides of closed cones, which none of them has; 22 and 23 only flat
// receivers within a twentieth of a region's size, which none of them has either; 24 only
// segments that reach or graze a Bezier patch or a torus, which none of them has). When
// one moves, bump kFormFactorAlgorithmVersion (and kHierarchyAlgorithmVersion if the links move
// too), say so in CHANGELOG.md, and record the new values here.
TEST(FormFactor, ValuesMoveOnlyWithTheAlgorithmVersion) {
    static_assert(kFormFactorAlgorithmVersion == 24, "record this test's fingerprints for the new version");
    const std::string box = test::cube_faces(1.0, 0.0, 1);
    const std::string two = ", patches: [4, 1], reflectance: [0.8, 0.8, 0.8], two_sided: true}\n";
    const std::array<std::pair<std::string, std::string>, 5> boxes = {{
        {"disk", "  - {name: o, type: disk, center: [0.1, 0, 0], normal: [0.2, 0.1, 1], radius: 0.4" + two},
        {"tube",
         "  - {name: o, type: cylinder, base: [0, 0.1, -0.4], axis: [0.1, 0, 0.8], radius: 0.3" + two},
        {"cone",
         "  - {name: o, type: cone, base: [0, 0, -0.5], axis: [0, 0, 1], radius: 0.4, top_radius: 0.1" + two},
        {"dome",
         "  - {name: o, type: sphere, center: [0.1, 0, -0.2], radius: 0.4, polar_deg: [0, 100]" + two},
        {"balls",
         "  - {name: a, type: sphere, center: [0, 0, -0.2], radius: 0.2, patches: [4, 2], reflectance: [0.8, "
         "0.8, "
         "0.8]}\n  - {name: b, type: sphere, center: [0.15, 0.05, 0.25], radius: 0.2, patches: [4, 2], "
         "reflectance: [0.8, 0.8, 0.8]}\n"},
    }};
    // name, F fingerprint, estimates' fingerprint
    const std::array<std::tuple<std::string, double, double>, 6> recorded = {{
        {"seed", 128.11620716431042, 0.0023466940653353668},
        {"disk", 20.552590821900168, 5.4882913142710576e-05},
        {"tube", 21.384210817776694, 8.9984871033004158e-05},
        {"cone", 21.244687512352776, 9.6849319695091791e-05},
        {"dome", 21.303830815105396, 9.8625180232149719e-05},
        {"balls", 32.961830499548441, 0.00021682049199114295},
    }};
    std::vector<std::pair<double, double>> now;
    now.push_back(fingerprint(
        compute_form_factors(SceneGeometry(load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml")),
                             FormFactorOptions::adaptive(1e-6))));
    for (const auto& [name, occluder] : boxes)
        now.push_back(fingerprint(
            compute_form_factors(SceneGeometry(parse_scene("surfaces:\n" + box + occluder, name + ".yaml")),
                                 FormFactorOptions::adaptive(1e-6))));
    for (std::size_t k = 0; k < recorded.size(); ++k) {
        const auto& [name, f, e] = recorded[k];
        char line[160];
        std::snprintf(line, sizeof line, "{\"%s\", %.17g, %.17g},", name.c_str(), now[k].first,
                      now[k].second);
        EXPECT_NEAR(now[k].first, f, 1e-10 * std::abs(f)) << "now " << line;
        EXPECT_NEAR(now[k].second, e, 1e-10 * std::abs(e)) << "now " << line;
    }
}

// The checks on deliberately wrong matrices: rows above and below 1 count by their distance
// from 1, reciprocity by the absolute difference in either order, estimates by their largest
// entry and row.
TEST(FormFactorChecks, WrongMatricesAreMeasuredNotExcused) {
    FormFactors ff;
    ff.F = DenseMatrix(3);
    ff.area = {1.0, 2.0, 4.0};
    // Row 0 sums to 0.9, row 1 to 1.2, row 2 to 1.0.
    ff.F(0, 1) = 0.3, ff.F(0, 2) = 0.6;
    ff.F(1, 0) = 0.5, ff.F(1, 2) = 0.7;
    ff.F(2, 0) = 0.15, ff.F(2, 1) = 0.35, ff.F(2, 2) = 0.5;
    ff.error = {0, 1e-3, 2e-3, 1e-3, 0, 5e-3, 1e-4, 1e-4, 0};
    const FormFactorChecks c = check_form_factors(ff);
    EXPECT_NEAR(c.closure_max_error, 0.2, 1e-15);
    EXPECT_EQ(c.closure_worst_patch, 1);
    // Pairs: (0,1): A0 F01 = 0.3, A1 F10 = 1.0; (0,2): 0.6 vs 0.6; (1,2): 1.4 vs 1.4.
    EXPECT_NEAR(c.reciprocity_max_error, 0.7 / 1.0, 1e-15);
    EXPECT_NEAR(c.reciprocity_abs_error, 0.7 / 1.0, 1e-15);
    EXPECT_NEAR(c.reciprocity_vs_estimate, 0.7 / (1.0 * 1e-3 + 2.0 * 1e-3), 1e-9);
    EXPECT_EQ(c.max_error_estimate, 5e-3);
    EXPECT_NEAR(c.max_row_error_estimate, 6e-3, 1e-15);
    // The same with the pair's directions swapped, and the row furthest from 1 below it: the
    // differences' signs do not matter.
    std::swap(ff.F(0, 1), ff.F(1, 0));
    ff.F(0, 2) = 0.2, ff.F(1, 2) = 0.8;  // rows 0.7 and 1.1
    const FormFactorChecks d = check_form_factors(ff);
    EXPECT_NEAR(d.closure_max_error, 0.3, 1e-15);
    EXPECT_EQ(d.closure_worst_patch, 0);
    // (0,1): 0.5 vs 0.6, (0,2): 0.2 vs 0.6, (1,2): 1.6 vs 1.4; over the smaller area, and
    // relative to the larger side.
    EXPECT_NEAR(d.reciprocity_abs_error, 0.4, 1e-15);
    EXPECT_NEAR(d.reciprocity_max_error, 0.4 / 0.6, 1e-15);
    ff.F(0, 0) = -0.25;
    EXPECT_EQ(check_form_factors(ff).min_entry, -0.25);
}

}  // namespace radiosa
