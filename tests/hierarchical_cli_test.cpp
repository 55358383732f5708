// The hierarchical method end to end through the command line: a still over the links against
// the dense path's, the expanded matrix against the dense matrix, and the refusals (no steady
// state, sequences, a matrix too large to expand).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.h"
#include "encode/image_io.h"

namespace radiosa {

namespace fs = std::filesystem;
using test::CliRun;
using test::fresh_dir;
using test::read_json;
using test::run;

namespace {
const std::string kScene = RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml";
const std::string kCamA = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml";

// The doubles of a .npy file (format 1.0: magic, version, a 2-byte header length, the header).
std::vector<double> npy_values(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    const std::string b{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (b.size() < 10) return {};
    const std::size_t start = 10 + static_cast<unsigned char>(b[8]) + 256u * static_cast<unsigned char>(b[9]);
    std::vector<double> v((b.size() - start) / sizeof(double));
    std::memcpy(v.data(), b.data() + start, v.size() * sizeof(double));
    return v;
}
}  // namespace

// The seed scene over links renders what the dense path renders: at 86 patches every link joins
// two patches, integrated as the dense path integrates them, so the EXR pixels agree to the
// solves' stopping rules, and the report carries the hierarchy's keys.
TEST(HierarchicalCli, StillMatchesTheDensePath) {
    const fs::path d = fresh_dir("radiosa_hier_still");
    const auto render = [&](const std::string& tag, std::vector<std::string> extra) {
        std::vector<std::string> args = {"render",     kScene,
                                         "-c",         kCamA,
                                         "-o",         (d / (tag + ".exr")).string(),
                                         "--report",   (d / (tag + ".json")).string(),
                                         "--width",    "64",
                                         "--height",   "48",
                                         "--samples",  "1",
                                         "--no-cache", "-q"};
        args.insert(args.end(), extra.begin(), extra.end());
        const CliRun r = run(args);
        EXPECT_EQ(r.code, 0) << r.err;
    };
    render("dense", {"--radiosities", (d / "dense.csv").string()});
    render("links", {"--ff-method", "hierarchical", "--ff-tolerance", "1e-5", "--radiosities",
                     (d / "links.csv").string()});
    // Per patch: the same radiosities to the solves' stopping rules (1e-10 of the largest).
    const auto rows = [](const fs::path& p) {
        std::ifstream in(p);
        std::vector<std::vector<double>> out;
        std::string line;
        std::getline(in, line);
        EXPECT_EQ(line, "patch,area,B_r,B_g,B_b");
        while (std::getline(in, line)) {
            std::vector<double> v;
            std::stringstream ss(line.substr(line.rfind('"') + 2));
            for (std::string x; std::getline(ss, x, ',');) v.push_back(std::stod(x));
            out.push_back(v);
        }
        return out;
    };
    const auto rd = rows(d / "dense.csv"), rl = rows(d / "links.csv");
    ASSERT_EQ(rd.size(), 86u);
    ASSERT_EQ(rl.size(), 86u);
    for (std::size_t i = 0; i < rd.size(); ++i)
        for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(rl[i][k], rd[i][k], 1e-8) << i << " " << k;
    const nlohmann::json j = read_json(d / "links.json");
    EXPECT_EQ(j["form_factor_method"], "hierarchical");
    EXPECT_EQ(j["link_tolerance"], 1e-5);
    EXPECT_DOUBLE_EQ(j["form_factor_tolerance"].get<double>(), 1e-6);
    EXPECT_EQ(j["hierarchy"]["nodes"], 165);  // 6 faces of 9 patches (17 nodes) and 32 sphere patches (63)
    EXPECT_EQ(j["hierarchy"]["links"], j["hierarchy"]["leaf_links"]);
    EXPECT_GT(j["hierarchy"]["links"].get<long long>(), 4000);
    EXPECT_EQ(j["solve"]["method"], "links");
    EXPECT_LT(j["closure_max_error"].get<double>(), 1e-6);
    EXPECT_LT(j["energy_balance_error"].get<double>(), 1e-6);
    EXPECT_TRUE(j["radiosity_error_bound"].is_null());
    for (const auto& e : j["radiosity_error_estimate"]) EXPECT_LT(e.get<double>(), 1e-4);
    const Image a = media::read_image((d / "dense.exr").string());
    const Image b = media::read_image((d / "links.exr").string());
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    float top = 0.0f, diff = 0.0f;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) {
        top = std::max(top, a.rgb[i]);
        diff = std::max(diff, std::abs(a.rgb[i] - b.rgb[i]));
    }
    EXPECT_GT(top, 0.1f);
    EXPECT_LE(diff, 1e-6f * top);
    fs::remove_all(d);
}

// Expanded to a matrix, the links of the seed scene are the dense matrix: every link is a pair
// of patches integrated by the same code at the same tolerance (in either order, so to rounding).
TEST(HierarchicalCli, ExpandedMatrixIsTheDenseMatrix) {
    const fs::path d = fresh_dir("radiosa_hier_matrix");
    CliRun r = run({"formfactors", kScene, "-m", (d / "dense.npy").string(), "--no-cache", "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    r = run({"formfactors", kScene, "-m", (d / "links.npy").string(), "--ff-method", "hierarchical",
             "--ff-tolerance", "1e-5", "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<double> a = npy_values(d / "dense.npy"), b = npy_values(d / "links.npy");
    ASSERT_EQ(a.size(), 86u * 86u);
    ASSERT_EQ(b.size(), a.size());
    double diff = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) diff = std::max(diff, std::abs(a[i] - b[i]));
    EXPECT_LE(diff, 1e-12);
    fs::remove_all(d);
}

TEST(HierarchicalCli, RefusesWhatItCannotDo) {
    const fs::path d = fresh_dir("radiosa_hier_refusals");
    // No steady state: the same message as the dense path's, before any sweep.
    const fs::path furnace = d / "furnace.yaml";
    std::ofstream(furnace)
        << "closed: true\nform_factors: {method: hierarchical}\nsurfaces:\n"
           "  - {name: shell, type: sphere, center: [0, 0, 0], radius: 1, facing: inward,\n"
           "     patches: [8, 4], reflectance: [1, 1, 1], emission: [1, 1, 1]}\n";
    CliRun r = run({"render", furnace.string(), "-c", kCamA, "-o", (d / "x.png").string(), "--width", "8",
                    "--height", "8"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err, "error: " + furnace.string() +
                         ": every reflectance is 1 in the red channel of a closed scene: light is never "
                         "absorbed, so radiosity grows without bound and there is no steady state (make some "
                         "reflectance < 1, or the scene open)\n");
    EXPECT_FALSE(fs::exists(d / "x.png"));
    // Sequences need the dense path in this version.
    r = run({"render", kScene, "-s", RADIOSA_SOURCE_DIR "/cameras/baranoski1991-abc.yaml", "-o",
             (d / "x.mp4").string(), "--ff-method", "hierarchical"});
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("hierarchical form factors render stills in this version"), std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(d / "x.mp4"));
    fs::remove_all(d);
}

}  // namespace radiosa
