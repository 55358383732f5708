// The link solve against answers known in advance: LU on the very matrix the links stand for
// (expand_links), plain Jacobi sweeps, and a furnace that cannot settle.
#include "solve/link_solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "../tests/test_scenes.h"
#include "formfactor/hierarchy.h"
#include "solve/solver.h"
#include "util/error.h"

namespace radiosa {
namespace {

using test::cube_faces;
using test::furnace;
using test::scene_of;

// A closed cube of 8 x 8 patches per face with links between groups of patches, lit from f1, with
// reflectances 0.5, 0.8 and 0.95 per channel (the last near the scenes that need most sweeps).
struct LitCube {
    Scene scene = scene_of(cube_faces(1.0, 0.0, 8), true);
    SceneGeometry g{scene};
    Hierarchy h;
    Materials m;
    LitCube() {
        HierarchyOptions o;
        o.tolerance = 1e-4;
        h = build_hierarchy(g, o, FormFactorOptions::adaptive(1e-6));
        m = patch_materials(scene);
        for (int i = 0; i < g.patch_count(); ++i) {
            m.rho[static_cast<std::size_t>(i)] = Rgb(0.5, 0.8, 0.95);
            m.E[static_cast<std::size_t>(i)] = Rgb(g.patch(i).surface == 1 ? 1.0 : 0.0);
        }
    }
};

// max over channels of max_i |a_i - b_i| / max_i b_i.
double max_rel(const std::vector<Rgb>& a, const std::vector<Rgb>& b) {
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) {
        double top = 0.0, diff = 0.0;
        for (std::size_t i = 0; i < b.size(); ++i) {
            top = std::max(top, b[i][c]);
            diff = std::max(diff, std::abs(a[i][c] - b[i][c]));
        }
        worst = std::max(worst, diff / top);
    }
    return worst;
}

TEST(LinkSolve, MatchesLUOnTheLinksOwnMatrixInHalfTheSweeps) {
    const LitCube cube;
    ASSERT_LT(cube.h.stats.leaf_links, cube.h.stats.links);  // links between groups too
    const FormFactors F = expand_links(cube.h, cube.g);
    const std::vector<Rgb> lu = RadiositySolver(F.F, cube.m.rho, SolverMethod::LU).solve(cube.m.E);
    LinkSolveOptions o;
    o.tolerance = 1e-13;
    const LinkSolution fast = solve_links(cube.h, cube.m.rho, cube.m.E, o);
    o.accelerate = false;
    const LinkSolution plain = solve_links(cube.h, cube.m.rho, cube.m.E, o);
    std::printf("sweeps: %d accelerated, %d plain; max |dB| / max B %.2e and %.2e\n", fast.sweeps,
                plain.sweeps, max_rel(fast.B, lu), max_rel(plain.B, lu));
    // The 0.95 channel's error is its last change times up to 1 / (1 - 0.95).
    EXPECT_LT(max_rel(fast.B, lu), 1e-11);
    EXPECT_LT(max_rel(plain.B, lu), 1e-11);
    EXPECT_LT(fast.sweeps, plain.sweeps / 2);
    // A warm start from the answer for other lights settles too, to the same answer.
    std::vector<Rgb> E2 = cube.m.E;
    for (int i = 0; i < cube.g.patch_count(); ++i)
        E2[static_cast<std::size_t>(i)] = Rgb(cube.g.patch(i).surface == 4 ? 2.0 : 0.0);
    const std::vector<Rgb> lu2 = RadiositySolver(F.F, cube.m.rho, SolverMethod::LU).solve(E2);
    o.accelerate = true;
    const LinkSolution warm = solve_links(cube.h, cube.m.rho, E2, o, &fast.B);
    EXPECT_LT(max_rel(warm.B, lu2), 1e-11);
}

TEST(LinkSolve, EmissionsSolvedTogetherAreEachOnesOwnAnswer) {
    // 2, 3 (one column of zeros beside them) and 8 emissions (faces lit in different colours,
    // one of them twice as an earlier one) in one run of sweeps: each is the LU answer on the
    // links' own matrix, as its separate solve is; the first, warm-started from another
    // answer, too. The gather for several is each one's own, bit for bit, and so are the error
    // estimates (to the digits their solves keep). Emission 0's green channel is dark and
    // warm-started from lit radiosities: its answer is 0.
    const LitCube cube;
    const FormFactors F = expand_links(cube.h, cube.g);
    const RadiositySolver lu(F.F, cube.m.rho, SolverMethod::LU);
    std::vector<std::vector<Rgb>> E;
    for (int k = 0; k < 8; ++k) {
        std::vector<Rgb> e(cube.m.E.size(), Rgb(0.0));
        for (int i = 0; i < cube.g.patch_count(); ++i)
            if (cube.g.patch(i).surface == k % 6)
                e[static_cast<std::size_t>(i)] = Rgb(1.0 + k, 0.5 * k, 2.0 - 0.2 * k);
        E.push_back(e);
    }
    LinkSolveOptions o;
    o.tolerance = 1e-13;
    const LinkSolution other = solve_links(cube.h, cube.m.rho, cube.m.E, o);
    for (const std::size_t k : {2, 3, 8}) {
        const std::vector<std::vector<Rgb>> some(E.begin(), E.begin() + static_cast<long>(k));
        const std::vector<LinkSolution> together =
            solve_links_together(cube.h, cube.m.rho, some, o, {&other.B});
        ASSERT_EQ(together.size(), k);
        std::vector<const std::vector<Rgb>*> B;
        for (std::size_t j = 0; j < k; ++j) {
            const LinkSolution alone = solve_links(cube.h, cube.m.rho, some[j], o);
            EXPECT_LT(max_rel(together[j].B, lu.solve(some[j])), 1e-11) << k << " " << j;
            EXPECT_LT(max_rel(together[j].B, alone.B), 1e-11) << k << " " << j;
            EXPECT_LE(together[j].change, 1e-13);
            if (j == 0) {  // the dark channel, warm-started from lit radiosities
                for (const Rgb& b : together[j].B) ASSERT_EQ(b.g, 0.0);
            }
            EXPECT_GE(together[j].sweeps, alone.sweeps - 3) << k << " " << j;  // one run for all
            B.push_back(&together[j].B);
        }
        const std::vector<std::vector<Rgb>> H = irradiance_together(cube.h, B);
        const std::vector<Rgb> est = link_error_estimates(cube.h, cube.m.rho, B);
        for (std::size_t j = 0; j < k; ++j) {
            EXPECT_EQ(H[j], cube.h.irradiance(*B[j])) << k << " " << j;
            const Rgb one = link_error_estimate(cube.h, {cube.m.rho, some[j]}, *B[j]);
            for (int c = 0; c < 3; ++c) {
                EXPECT_EQ(est[j][c] > 0.0, c != 1 || j != 0);  // emission 0 has no green
                EXPECT_NEAR(est[j][c], one[c], 1e-5 * one[c]) << k << " " << j;
            }
        }
    }
    EXPECT_THROW(solve_links_together(cube.h, cube.m.rho, std::vector<std::vector<Rgb>>(9, cube.m.E), o),
                 std::invalid_argument);
}

TEST(LinkSolve, AChannelTurnedDarkIsZeroNotWhatAWarmStartLeaves) {
    // The light turns red: green and blue have no emission left. Warm-started from the white
    // answer, those channels used to stop "settled" once their largest value had overshot
    // below 0: blue (rho 0.95) at down to -6.1e-4, green down to -1.3e-6, instead of 0.
    const LitCube cube;
    const LinkSolution white = solve_links(cube.h, cube.m.rho, cube.m.E);
    std::vector<Rgb> red = cube.m.E;
    for (Rgb& e : red) e = Rgb(e.r, 0.0, 0.0);
    const LinkSolution s = solve_links(cube.h, cube.m.rho, red, {}, &white.B);
    for (std::size_t i = 0; i < s.B.size(); ++i) {
        ASSERT_EQ(s.B[i].g, 0.0) << i;
        ASSERT_EQ(s.B[i].b, 0.0) << i;
        EXPECT_NEAR(s.B[i].r, white.B[i].r, 1e-9) << i;
    }
}

TEST(LinkSolve, AFurnaceThatCannotSettleIsAnError) {
    // test::furnace: B = E / (1 - rho).
    {
        const Scene s = furnace(0.9);
        const SceneGeometry g(s);
        const Hierarchy h = build_hierarchy(g, {}, FormFactorOptions::adaptive(1e-10));
        const Materials m = patch_materials(s);
        const LinkSolution sol = solve_links(h, m.rho, m.E);
        for (const Rgb& b : sol.B) EXPECT_NEAR(b[0], 10.0, 1e-6);
    }
    const Scene s = furnace(0.999999);
    const SceneGeometry g(s);
    const Hierarchy h = build_hierarchy(g, {}, FormFactorOptions::adaptive(1e-10));
    const Materials m = patch_materials(s);
    try {
        solve_links(h, m.rho, m.E);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("does not settle within 10000 sweeps"), std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace radiosa
