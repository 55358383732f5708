// Nothing wrong goes unsaid: intersecting surfaces and entries that miss their tolerance are
// named in a warning, and --strict refuses them (exit 1, no output).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "cli_run.h"

namespace radiosa {

namespace fs = std::filesystem;
using test::CliRun;
using test::fresh_dir;
using test::read_json;
using test::run;

namespace {

const std::string kScene = RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml";
const std::string kCamA = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml";

// The seed scene with its sphere lowered through the floor (face1, z = -2).
fs::path write_cut_scene(const fs::path& d) {
    std::ifstream in(kScene);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    const std::string from = "center: [0, 0, 0]";
    text.replace(text.find(from), from.size(), "center: [0, 0, -1.5]");
    std::ofstream(d / "cut.yaml") << text;
    return d / "cut.yaml";
}

// Nested spheres, the outer one split in two, the inner one off centre: the outer patches see
// each other past a ball whose shadow is not a cap, so those entries need the numeric path,
// whose estimates stay far above 1e-6 at its refinement cap.
fs::path write_nested_scene(const fs::path& d) {
    std::ofstream(d / "nested.yaml")
        << "closed: true\nsurfaces:\n"
           "  - {name: outer, type: sphere, center: [0, 0, 0], radius: 2, "
           "facing: inward, patches: [2, 1], reflectance: [0.5, 0.5, 0.5]}\n"
           "  - {name: inner, type: sphere, center: [0.3, 0, 0], radius: 1, "
           "patches: [1, 1], reflectance: [0.5, 0.5, 0.5], emission: [1, 1, 1]}\n";
    return d / "nested.yaml";
}

}  // namespace

TEST(NeverSilent, IntersectingSurfacesAreNamedAndStrictRefusesThem) {
    const fs::path d = fresh_dir("radiosa_silent_cut");
    const fs::path scene = write_cut_scene(d);
    CliRun r = run({"render", scene.string(), "--camera", kCamA, "-o", (d / "a.png").string(), "--report",
                    (d / "a.json").string(), "--width", "32", "--gauss-points", "2"});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: surfaces intersect: 'face1' and 'sphere'. "), std::string::npos) << r.err;
    EXPECT_EQ(read_json(d / "a.json")["surface_intersections"],
              nlohmann::json::parse(R"([["face1", "sphere"]])"));
    fs::remove(d / "a.png");
    fs::remove(d / "a.json");

    r = run({"render", scene.string(), "--camera", kCamA, "-o", (d / "a.png").string(), "--report",
             (d / "a.json").string(), "--strict"});
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(
        std::regex_search(r.err, std::regex("^error: .*cut.yaml:[0-9]+:[0-9]+: surfaces intersect: 'face1' "
                                            "and 'sphere'; move them apart")))
        << r.err;
    EXPECT_FALSE(fs::exists(d / "a.png"));
    EXPECT_FALSE(fs::exists(d / "a.json"));
    // The seed scene itself intersects nothing.
    r = run({"formfactors", kScene, "--report", (d / "seed.json").string()});
    EXPECT_EQ(r.code, 0);
    EXPECT_EQ(r.err, "");
    EXPECT_TRUE(read_json(d / "seed.json")["surface_intersections"].empty());
    EXPECT_EQ(read_json(d / "seed.json")["entries_over_tolerance"], 0);
    fs::remove_all(d);
}

// The same for a curved type, whose crossing is found by sampling: the seed scene with a
// column through its floor.
TEST(NeverSilent, AColumnThroughTheFloorIsNamedAndStrictRefusesIt) {
    const fs::path d = fresh_dir("radiosa_silent_column");
    std::ifstream in(kScene);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    text +=
        "  - {name: column, type: cylinder, base: [1.2, 1.2, -2.5], axis: [0, 0, 1.5], radius: 0.2,\n"
        "     patches: [4, 1], reflectance: [0.5, 0.5, 0.5]}\n";
    std::ofstream(d / "column.yaml") << text;
    const std::string scene = (d / "column.yaml").string();
    CliRun r = run({"formfactors", scene, "--gauss-points", "2", "--report", (d / "a.json").string()});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: surfaces intersect: 'face1' and 'column'. "), std::string::npos) << r.err;
    EXPECT_EQ(read_json(d / "a.json")["surface_intersections"],
              nlohmann::json::parse(R"([["face1", "column"]])"));
    fs::remove(d / "a.json");
    r = run({"formfactors", scene, "--gauss-points", "2", "--report", (d / "a.json").string(), "--strict"});
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(std::regex_search(
        r.err, std::regex("^error: .*column.yaml:[0-9]+:[0-9]+: surfaces intersect: 'face1' and 'column'")))
        << r.err;
    EXPECT_FALSE(fs::exists(d / "a.json"));
    fs::remove_all(d);
}

TEST(NeverSilent, EntriesOverTheirToleranceAreCountedAndTheWorstIsNamed) {
    const fs::path d = fresh_dir("radiosa_silent_nested");
    const fs::path scene = write_nested_scene(d);
    CliRun r = run({"formfactors", scene.string(), "--report", (d / "n.json").string()});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: 4 form-factor entries miss the tolerance 1e-06"), std::string::npos)
        << r.err;
    EXPECT_TRUE(std::regex_search(
        r.err, std::regex(R"(the worst, F\[outer\[[01],0\] -> outer\[[01],0\]\], has the estimate)")))
        << r.err;
    const nlohmann::json j = read_json(d / "n.json");
    EXPECT_EQ(j["entries_over_tolerance"], 4);
    EXPECT_TRUE(std::regex_match(j["worst_entry_over_tolerance"]["pair"].get<std::string>(),
                                 std::regex(R"(outer\[[01],0\] -> outer\[[01],0\])")));
    EXPECT_GT(j["worst_entry_over_tolerance"]["estimate_over_target"].get<double>(), 1.0);

    r = run({"formfactors", scene.string(), "--report", (d / "strict.json").string(), "--strict"});
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("error: " + scene.string() + ": 4 form-factor entries miss the tolerance"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(d / "strict.json"));
    fs::remove_all(d);
}

}  // namespace radiosa
