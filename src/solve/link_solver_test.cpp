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
