// A target on the radiosity: the form-factor tolerance is tightened until the radiosity error
// bound meets it, and the scene key is validated like any other.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "scene/scene.h"
#include "util/error.h"

namespace radiosa {

namespace fs = std::filesystem;
using test::fresh_dir;
using test::read_json;
using test::run;

namespace {

// A closed box split 2 x 2 per face around a ball, every reflectance 0.9: the ball's entries
// are integrated numerically, and 1/(1 - rho) = 10 amplifies their errors.
std::string box_with_ball(const std::string& extra) {
    std::string s = "closed: true\n" + extra + "surfaces:\n";
    const char* faces[][2] = {{"floor", "[[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1]]"},
                              {"south", "[[-1, -1, -1], [-1, -1, 1], [1, -1, 1], [1, -1, -1]]"},
                              {"east", "[[1, -1, -1], [1, -1, 1], [1, 1, 1], [1, 1, -1]]"},
                              {"west", "[[-1, -1, -1], [-1, 1, -1], [-1, 1, 1], [-1, -1, 1]]"},
                              {"north", "[[-1, 1, -1], [1, 1, -1], [1, 1, 1], [-1, 1, 1]]"},
                              {"ceiling", "[[-1, -1, 1], [-1, 1, 1], [1, 1, 1], [1, -1, 1]]"}};
    for (const auto& f : faces)
        s += std::string("  - {name: ") + f[0] + ", type: quad, corners: " + f[1] +
             ", patches: [2, 2], reflectance: [0.9, 0.9, 0.9]" +
             (std::string(f[0]) == "ceiling" ? ", emission: [1, 1, 1]}\n" : "}\n");
    s += "  - {name: ball, type: sphere, center: [0, 0, 0], radius: 0.5, patches: [4, 2], "
         "reflectance: [0.9, 0.9, 0.9]}\n";
    return s;
}

}  // namespace

TEST(SolveTarget, TheFormFactorToleranceIsTightenedUntilTheBoundMeetsTheTarget) {
    const fs::path d = fresh_dir("radiosa_solve_target");
    std::ofstream(d / "box.yaml") << box_with_ball("solve: {tolerance: 1e-5}\n");
    // Without the target the default tolerance gives a bound above 1e-5 ...
    auto r = run({"formfactors", (d / "box.yaml").string(), "--solve-tolerance", "1e-3", "--report",
                  (d / "loose.json").string()});
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json loose = read_json(d / "loose.json");
    EXPECT_EQ(loose["solve_target"]["rounds"], 1);
    EXPECT_GT(loose["solve_target"]["bound"].get<double>(), 1e-5);
    EXPECT_EQ(loose["form_factor_tolerance"], 1e-6);
    // ... and the scene's target makes it tighter until the bound is below 1e-5.
    r = run({"formfactors", (d / "box.yaml").string(), "--report", (d / "t.json").string()});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("solve target 1e-05: met after"), std::string::npos) << r.out;
    const nlohmann::json j = read_json(d / "t.json");
    EXPECT_TRUE(j["solve_target"]["reached"].get<bool>());
    EXPECT_GE(j["solve_target"]["rounds"].get<int>(), 2);
    EXPECT_LE(j["solve_target"]["bound"].get<double>(), 1e-5);
    EXPECT_LT(j["form_factor_tolerance"].get<double>(), 1e-6);
    EXPECT_EQ(j["solve_target"]["form_factor_tolerance"], j["form_factor_tolerance"]);
    fs::remove_all(d);
}

TEST(SolveTarget, BadTargetsAreRefusedWithTheirPlace) {
    auto message = [](const std::string& extra) {
        try {
            parse_scene(box_with_ball(extra), "t.yaml");
        } catch (const Error& e) {
            return e.loc() ? e.loc()->to_string() + ": " + e.message() : e.message();
        }
        return std::string("accepted");
    };
    EXPECT_EQ(
        message("solve: {tolerance: 0}\n"),
        "t.yaml:2:20: solve tolerance must be in [1e-12, 0.1] (relative to the largest radiosity of each "
        "channel), got 0");
    EXPECT_EQ(message("solve: {tolerance: .nan}\n").substr(0, 12), "t.yaml:2:20:");
    EXPECT_NE(message("solve: {tol: 1e-6}\n").find("tol"), std::string::npos);
    EXPECT_NE(message("solve: {tolerance: 1e-6}\nform_factors: {gauss_points: 4}\n")
                  .find("a tolerance needs error-controlled form factors"),
              std::string::npos);
    const auto r = run({"formfactors", "x.yaml", "--solve-tolerance", "1e-6", "--gauss-points", "4"});
    EXPECT_EQ(r.code, 1);
}

}  // namespace radiosa
