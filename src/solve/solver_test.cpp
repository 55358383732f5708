#include "solve/solver.h"

#include <gtest/gtest.h>

#include <random>

#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"

namespace radiosa {

namespace {
Scene furnace(double rho, double e) {
    // A closed inward sphere: its form factors are exact (see SphereInteriorIsAreaRatio).
    return parse_scene(
        "surfaces:\n  - name: shell\n    type: sphere\n    center: [0, 0, 0]\n    radius: 1\n"
        "    facing: inward\n    patches: [8, 4]\n    reflectance: [" +
            std::to_string(rho) + ", " + std::to_string(rho) + ", " + std::to_string(rho) +
            "]\n    emission: [" + std::to_string(e) + ", " + std::to_string(2 * e) + ", 0]\n",
        "furnace.yaml");
}
}  // namespace

TEST(Solver, FurnaceRadiosityIsEmissionOverOneMinusRho) {
    for (double rho : {0.0, 0.5, 0.9}) {
        const Scene s = furnace(rho, 1.0);
        const SceneGeometry geo(s);
        // p = 8 makes the furnace's form factors exact to rounding (see SphereInteriorIsAreaRatio).
        const FormFactors ff = compute_form_factors(geo, FormFactorOptions::gauss(8, true));
        const Materials m = patch_materials(s);
        for (SolverMethod method : {SolverMethod::LU, SolverMethod::GaussJordan}) {
            const RadiositySolver solver(ff.F, m.rho, method);
            const std::vector<Rgb> B = solver.solve(m.E);
            for (const Rgb& b : B) {
                EXPECT_NEAR(b.r, 1.0 / (1.0 - rho), 1e-12 / (1.0 - rho));
                EXPECT_NEAR(b.g, 2.0 / (1.0 - rho), 2e-12 / (1.0 - rho));
                EXPECT_EQ(b.b, 0.0);  // no emission in blue: no solve, exactly 0
            }
            const SolveDiagnostics d = diagnose_solution(ff.F, ff.area, m, B);
            EXPECT_LT(d.residual, 1e-14);
            EXPECT_LT(d.energy_balance_error, 1e-12);
            EXPECT_NEAR(d.emitted_power.r, 4 * kPi, 1e-12);
        }
    }
}

TEST(Solver, IdenticalChannelsShareOneFactorisation) {
    const Scene grey = furnace(0.5, 1.0);
    const SceneGeometry geo(grey);
    const FormFactors ff = compute_form_factors(geo, FormFactorOptions::gauss(2, true));
    const Materials m = patch_materials(grey);
    EXPECT_EQ(RadiositySolver(ff.F, m.rho, SolverMethod::LU).factorisations(), 1);
    std::vector<Rgb> rho = m.rho;
    rho[3].b = 0.25;  // blue differs on one patch
    EXPECT_EQ(RadiositySolver(ff.F, rho, SolverMethod::LU).factorisations(), 2);
}

TEST(Solver, SeedSceneLuAgreesWithGaussJordanAndIsLinearInEmission) {
    const Scene s = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    const SceneGeometry geo(s);
    const FormFactors ff = compute_form_factors(geo, FormFactorOptions::gauss(4, true));
    const Materials m = patch_materials(s);
    const RadiositySolver lu(ff.F, m.rho, SolverMethod::LU);
    EXPECT_EQ(lu.factorisations(), 2);  // sphere (0.5, 0.5, 1.0): red and green alike
    const std::vector<Rgb> B = lu.solve(m.E);
    const std::vector<Rgb> Bgj = RadiositySolver(ff.F, m.rho, SolverMethod::GaussJordan).solve(m.E);
    for (size_t i = 0; i < B.size(); ++i)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(B[i][c], Bgj[i][c], 1e-12);
    // Doubling the emission doubles the radiosity (substitution with the kept factors).
    std::vector<Rgb> E2 = m.E;
    for (Rgb& e : E2) e *= 2.0;
    const std::vector<Rgb> B2 = lu.solve(E2);
    for (size_t i = 0; i < B.size(); ++i) EXPECT_NEAR(B2[i].g, 2.0 * B[i].g, 1e-12);
    // The blue sphere reflects more blue than red.
    const int sphere = geo.first_patch(s.find_surface("sphere"));
    EXPECT_GT(B[sphere].b, B[sphere].r);
    EXPECT_LT(diagnose_solution(ff.F, ff.area, m, B).residual, 1e-14);
}

TEST(Solver, PatchEmissionOverridesTheSurface) {
    const Scene s = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991-c.yaml");
    const SceneGeometry geo(s);
    const Materials m = patch_materials(s);
    const int ceiling = s.find_surface("face6");
    int emitting = 0;
    for (int i = 0; i < geo.patch_count(); ++i)
        if (m.E[i] != Rgb(0.0)) {
            ++emitting;
            EXPECT_EQ(i, geo.patch_index(ceiling, 1, 1));
            EXPECT_EQ(m.E[i], Rgb(7.0));
        }
    EXPECT_EQ(emitting, 1);
}

TEST(Solver, UnknownSolverNameIsAnError) {
    EXPECT_EQ(parse_solver_method("gauss-jordan"), SolverMethod::GaussJordan);
    EXPECT_THROW(parse_solver_method("cholesky"), Error);
}

}  // namespace radiosa

namespace radiosa {

// The bound holds whatever the form-factor errors are, as long as each stays within its
// estimate: random closed systems, reflectances up to 0.999, errors drawn inside the estimates.
TEST(ErrorBound, CoversTheTrueErrorForEveryPerturbationWithinTheEstimates) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 60; ++trial) {
        const int n = 6;
        const double rho_max = trial % 3 == 0 ? 0.999 : 0.9;
        // Exact F: random rows summing to 1 (a closed scene).
        DenseMatrix exact(n);
        for (int i = 0; i < n; ++i) {
            double row = 0.0;
            for (int j = 0; j < n; ++j) row += exact(i, j) = u(rng);
            for (int j = 0; j < n; ++j) exact(i, j) /= row;
        }
        std::vector<double> est(static_cast<std::size_t>(n) * n);
        DenseMatrix computed(n);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const double e = 1e-4 * u(rng) * exact(i, j);
                est[static_cast<std::size_t>(i) * n + j] = e;
                computed(i, j) = exact(i, j) + e * (2.0 * u(rng) - 1.0);
            }
        Materials m;
        for (int i = 0; i < n; ++i) {
            m.rho.push_back(Rgb(rho_max * u(rng), rho_max, 0.5));
            m.E.push_back(Rgb(i == 0 ? 1.0 : 0.0, u(rng), 0.0));
        }
        const RadiositySolver approx(computed, m.rho, SolverMethod::LU);
        const std::vector<Rgb> B = approx.solve(m.E);
        const std::vector<Rgb> B_exact = RadiositySolver(exact, m.rho, SolverMethod::LU).solve(m.E);
        const Rgb bound = radiosity_error_bound(approx, computed, est, m, B);
        for (int c = 0; c < 3; ++c) {
            double max_b = 0.0, max_err = 0.0;
            for (int i = 0; i < n; ++i) {
                max_b = std::max(max_b, std::abs(B[i][c]));
                max_err = std::max(max_err, std::abs(B[i][c] - B_exact[i][c]));
            }
            if (max_b == 0.0) {
                EXPECT_EQ(bound[c], 0.0);
                continue;
            }
            ASSERT_TRUE(std::isfinite(bound[c])) << "trial " << trial << " channel " << c;
            EXPECT_LE(max_err / max_b, bound[c]) << "trial " << trial << " channel " << c;
            // Not vacuous: within 1000x of the truth and far below 1 here.
            EXPECT_LT(bound[c], 1000.0 * std::max(max_err / max_b, 1e-13))
                << "trial " << trial << " channel " << c;
        }
    }
}

TEST(ErrorBound, ExactFormFactorsGiveABoundAtRoundOff) {
    const Scene s = furnace(0.9, 1.0);
    const FormFactors ff = compute_form_factors(SceneGeometry(s), FormFactorOptions::adaptive(1e-6));
    const Materials m = patch_materials(s);
    const RadiositySolver solver(ff.F, m.rho, SolverMethod::LU);
    const Rgb b = radiosity_error_bound(solver, ff.F, ff.error, m, solver.solve(m.E));
    EXPECT_LT(b.r, 1e-12);
    EXPECT_LT(b.g, 1e-12);
    EXPECT_EQ(b.b, 0.0);  // dark channel
}

}  // namespace radiosa
