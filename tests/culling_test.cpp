// Leaving out what a scene does not need: pairs that cannot see each other get no quadrature,
// surfaces that cannot come between a pair get no occlusion tests, identical channels share
// one solve. Culling must change the work, never the answer; the report counts what it saved.
#include "formfactor/culling.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "cli_run.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"

namespace radiosa {

namespace fs = std::filesystem;
using test::CliRun;
using test::fresh_dir;
using test::read_json;
using test::run;

namespace {

FormFactors seed(FormFactorOptions o) {
    return compute_form_factors(SceneGeometry(load_scene(test::kSeedScene)), o);
}

}  // namespace

// Two rectangles facing each other across a ball are wholly hidden from each other exactly
// when every segment between them passes through it, which their corners decide: the
// segment between matching corners of two squares of half-side h at z = -2 and z = 2 passes
// h sqrt(2) from the centre of a unit ball at the origin. Crossed rectangles 2 x 0.6 are
// hidden (each segment's middle lies within (1 + 0.3) / sqrt(2) = 0.92 of the centre), though
// their bounding balls (radius 1.04) could not show it; the same rectangles side by side are
// not (matching corners pass 1.04 from the centre).
TEST(Culling, SegmentsThroughABallAreProvenByTheCorners) {
    const BoundingSphere ball{Vec3(0.0), 1.0};
    const auto rect = [](double w, double h, double z) {
        return std::array<Vec3, 4>{Vec3(-w, -h, z), Vec3(w, -h, z), Vec3(w, h, z), Vec3(-w, h, z)};
    };
    EXPECT_TRUE(segments_through_ball(rect(0.70, 0.70, -2), rect(0.70, 0.70, 2), ball, 1e-12));
    EXPECT_FALSE(segments_through_ball(rect(0.71, 0.71, -2), rect(0.71, 0.71, 2), ball, 1e-12));
    EXPECT_TRUE(segments_through_ball(rect(1.0, 0.3, -2), rect(0.3, 1.0, 2), ball, 1e-12));
    EXPECT_FALSE(segments_through_ball(rect(1.0, 0.3, -2), rect(1.0, 0.3, 2), ball, 1e-12));
    // Off the middle: a ball of radius 0.5 at z = 1 hides a square of half-side 0.1 at z = -2
    // from one of half-side 0.3 at z = 2 (at t = 3/4 the corners' combinations lie within
    // sqrt(2) (0.1 / 4 + 0.3 * 3 / 4) = 0.35 of its centre), but not from one of half-side 0.5
    // (the segment from (0.1, 0.1, -2) to (0.5, 0.5, 2) passes 0.56 from it).
    const BoundingSphere off{Vec3(0, 0, 1), 0.5};
    EXPECT_TRUE(segments_through_ball(rect(0.1, 0.1, -2), rect(0.3, 0.3, 2), off, 1e-12));
    EXPECT_FALSE(segments_through_ball(rect(0.1, 0.1, -2), rect(0.5, 0.5, 2), off, 1e-12));
}

// The paper's fixed rule evaluates the same terms either way: a culled pair's terms are all
// zero and a culled occluder's tests all miss, so the matrices agree to the last bit.
TEST(Culling, ChangesTheWorkNotTheMatrix) {
    FormFactorOptions off = FormFactorOptions::gauss(4);
    off.culling = false;
    const FormFactors with = seed(FormFactorOptions::gauss(4)), without = seed(off);
    EXPECT_EQ(with.F.data, without.F.data);
    // 6 faces x C(9, 2) coplanar pairs + C(32, 2) pairs on the convex sphere, of 86 x 87 / 2.
    EXPECT_EQ(with.stats.pairs, 3741);
    EXPECT_EQ(with.stats.pairs_culled, 6 * 36 + 496);
    EXPECT_EQ(without.stats.pairs_culled, 0);
    // Every sphere-to-face pair (32 x 54) is proven free of occluders: the sphere's own
    // segments leave it, and both ends lie inside every face's plane.
    EXPECT_GE(with.stats.pairs_unoccluded, 32 * 54);
    EXPECT_EQ(without.stats.pairs_unoccluded, 0);
    EXPECT_EQ(without.stats.occluders_culled, 0);
    EXPECT_GT(without.stats.segment_tests, 10 * with.stats.segment_tests);
}

// In a convex scene nothing can come between two patches: no occlusion test at all, and every
// computed pair takes the closed-form inner integral.
TEST(Culling, ConvexSceneNeedsNoOcclusionTests) {
    std::string yaml = "closed: true\nsurfaces:\n";
    const char* faces[] = {
        "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]", "[[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]",
        "[[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]", "[[0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]]",
        "[[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]]", "[[1, 0, 0], [1, 0, 1], [1, 1, 1], [1, 1, 0]]"};
    for (int k = 0; k < 6; ++k)
        yaml += "  - name: f" + std::to_string(k) + "\n    type: quad\n    corners: " + faces[k] +
                "\n    patches: [2, 2]\n    reflectance: [0.5, 0.5, 0.5]\n";
    const SceneGeometry g(parse_scene(yaml, "cube.yaml"));
    const FormFactors ff = compute_form_factors(g, FormFactorOptions::adaptive(1e-6));
    EXPECT_EQ(ff.stats.pairs, 24 * 25 / 2);
    EXPECT_EQ(ff.stats.pairs_culled, 6 * 6);  // coplanar pairs
    // Every other pair but the 24 flat self pairs (F_ii = 0, never integrated).
    EXPECT_EQ(ff.stats.pairs_unoccluded, ff.stats.pairs - ff.stats.pairs_culled - 24);
    EXPECT_EQ(ff.stats.segment_tests, 0);
    EXPECT_EQ(ff.stats.numeric, 0);
    EXPECT_LT(check_form_factors(ff).closure_max_error, 1e-6);
}

// A whole-surface proof (the incremental update asks it once per patch and surface) holds for
// each of the surface's patches: a ball and a floating plate at many places in a box.
TEST(Culling, ASurfaceWideProofHoldsForEveryPatchOfTheSurface) {
    std::string walls;
    const char* faces[6] = {
        "[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]", "[[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]",
        "[[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]", "[[0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]]",
        "[[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]]", "[[1, 0, 0], [1, 0, 1], [1, 1, 1], [1, 1, 0]]"};
    for (int k = 0; k < 6; ++k)
        walls += "  - {name: f" + std::to_string(k) + ", type: quad, corners: " + faces[k] +
                 ", patches: [4, 4], reflectance: [0.5, 0.5, 0.5]}\n";
    long long proven = 0, pairs = 0;
    for (int place = 0; place < 8; ++place) {
        const double x = 0.2 + 0.6 * ((place * 37) % 8) / 7.0, y = 0.2 + 0.6 * ((place * 11) % 8) / 7.0;
        const std::string yaml =
            "closed: false\nsurfaces:\n" + walls + "  - {name: ball, type: sphere, center: [" +
            std::to_string(x) + ", " + std::to_string(y) +
            ", 0.15], radius: 0.12, patches: [4, 2], reflectance: [0.5, 0.5, 0.5]}\n" +
            "  - {name: plate, type: quad, corners: [[" + std::to_string(y) + ", 0.3, 0.6], [" +
            std::to_string(y + 0.2) + ", 0.3, 0.6], [" + std::to_string(y + 0.2) + ", 0.5, 0.7], [" +
            std::to_string(y) + ", 0.5, 0.7]], patches: [1, 1], reflectance: [0.5, 0.5, 0.5]}\n";
        const SceneGeometry g(parse_scene(yaml, "box.yaml"));
        const Culling c(g);
        for (const int k : {6, 7})
            for (int i = 0; i < 96; ++i)
                for (int b = 0; b < 6; ++b) {
                    if (c.can_block_any(i, b, k)) continue;
                    ++proven;
                    for (int j = 0; j < g.patch_count(); ++j)
                        if (g.patch(j).surface == b) {
                            ++pairs;
                            EXPECT_FALSE(c.can_block(i, j, k))
                                << "place " << place << " k " << k << " i " << i << " j " << j;
                        }
                }
    }
    // The proofs are used (and not only for surfaces out of the way).
    EXPECT_GT(proven, 1000);
    EXPECT_GT(pairs, 16 * proven - 1);
}

// The report's "left_out" block: the seed scene's culling counts and its shared solves (red and
// green have equal reflectance and emission: one factorisation and one substitution serve
// both); --no-culling neither reads nor writes the cache and says so.
TEST(Culling, ReportCountsWhatWasLeftOut) {
    const fs::path d = fresh_dir("radiosa_culling_report");
    const std::string cam = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml";
    CliRun r = run({"render", test::kSeedScene, "-c", cam, "-o", (d / "a.png").string(), "--width", "16",
                    "--height", "16", "-p", "3", "--report", (d / "on.json").string(), "--cache-dir",
                    (d / "cache").string(), "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    auto j = read_json(d / "on.json")["left_out"];
    EXPECT_EQ(j["culling"], true);
    EXPECT_EQ(j["pairs"], 3741);
    EXPECT_EQ(j["pairs_culled"], 712);
    EXPECT_GE(j["pairs_unoccluded"].get<int>(), 32 * 54);
    EXPECT_GT(j["occlusion_tests_skipped"].get<int>(), 0);
    EXPECT_EQ(j["factorisations"], 2);
    EXPECT_EQ(j["factorisations_shared"], 1);
    EXPECT_EQ(j["channel_solves"], 2);
    EXPECT_EQ(j["channel_solves_shared"], 1);
    EXPECT_EQ(j["solve_skipped"], false);

    fs::remove_all(d / "cache");
    r = run({"render", test::kSeedScene, "-c", cam, "-o", (d / "a.png").string(), "--width", "16", "--height",
             "16", "-p", "3", "--no-culling", "--report", (d / "off.json").string(), "--cache-dir",
             (d / "cache").string(), "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    const auto off = read_json(d / "off.json");
    EXPECT_EQ(off["left_out"]["culling"], false);
    EXPECT_EQ(off["left_out"]["pairs_culled"], 0);
    EXPECT_EQ(off["left_out"]["occlusion_tests_skipped"], 0);
    EXPECT_EQ(off["form_factor_cache"]["status"], "off");
    EXPECT_EQ(off["form_factor_cache"]["reason"], "--no-culling");
    EXPECT_FALSE(fs::exists(d / "cache") && !fs::is_empty(d / "cache"));
    EXPECT_EQ(off["closure_max_error"], read_json(d / "on.json")["closure_max_error"]);
    fs::remove_all(d);
}

}  // namespace radiosa
