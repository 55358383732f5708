// The hierarchical method end to end through the command line: a still over the links against
// the dense path's, the expanded matrix against the dense matrix, and the refusals (no steady
// state, sequences, a matrix too large to expand).
#include <fmt/format.h>
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
#include <utility>
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
// The largest pixel value of image a, and the largest difference between a and b (infinite
// when their sizes differ).
std::pair<float, float> image_difference(const fs::path& a_path, const fs::path& b_path) {
    const Image a = media::read_image(a_path.string());
    const Image b = media::read_image(b_path.string());
    if (a.rgb.size() != b.rgb.size()) return {0.0f, INFINITY};
    float top = 0.0f, diff = 0.0f;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) {
        top = std::max(top, a.rgb[i]);
        diff = std::max(diff, std::abs(a.rgb[i] - b.rgb[i]));
    }
    return {top, diff};
}
}  // namespace

// The seed scene over links renders what the dense path renders: at 86 patches every link joins
// two patches, integrated as the dense path integrates them but in one direction (the other by
// reciprocity), so entries agree within their tolerance (1e-6) and radiosities within what that
// allows (measured 5e-8 of 0.34); the report carries the hierarchy's keys.
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
    // Per patch: the same radiosities within what entries within 1e-6 allow.
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
        for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(rl[i][k], rd[i][k], 1e-6) << i << " " << k;
    const nlohmann::json j = read_json(d / "links.json");
    EXPECT_EQ(j["form_factor_method"], "hierarchical");
    EXPECT_EQ(j["link_tolerance"], 1e-5);
    EXPECT_DOUBLE_EQ(j["receiver_tolerance"].get<double>(), 1e-5 / 8);  // automatic below 10,000 patches
    EXPECT_DOUBLE_EQ(j["form_factor_tolerance"].get<double>(), 1e-6);
    EXPECT_EQ(j["hierarchy"]["nodes"], 165);  // 6 faces of 9 patches (17 nodes) and 32 sphere patches (63)
    EXPECT_EQ(j["hierarchy"]["links"], j["hierarchy"]["leaf_links"]);
    EXPECT_GT(j["hierarchy"]["links"].get<long long>(), 4000);
    EXPECT_EQ(j["solve"]["method"], "links");
    EXPECT_LT(j["closure_max_error"].get<double>(), 1e-6);
    EXPECT_LT(j["energy_balance_error"].get<double>(), 1e-6);
    EXPECT_TRUE(j["radiosity_error_bound"].is_null());
    for (const auto& e : j["radiosity_error_estimate"]) EXPECT_LT(e.get<double>(), 1e-4);
    const auto [top, diff] = image_difference(d / "dense.exr", d / "links.exr");
    EXPECT_GT(top, 0.1f);
    EXPECT_LE(diff, 1e-5f * top);
    fs::remove_all(d);
}

// Expanded to a matrix, the links of the seed scene are the dense matrix: every link is a pair
// of patches integrated by the same code at the same tolerance, so every entry is within it
// (1e-6) of the dense one. The dense path integrates both directions of a pair; the links one,
// the other by reciprocity, so their matrix is reciprocal to rounding.
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
    EXPECT_LE(diff, 1e-6);
    std::ifstream table(d / "links.patches.csv");
    std::vector<double> area;
    std::string line;
    std::getline(table, line);
    EXPECT_EQ(line, "patch,surface,is,it,area");
    while (std::getline(table, line)) area.push_back(std::stod(line.substr(line.rfind(',') + 1)));
    ASSERT_EQ(area.size(), 86u);
    double asym = 0.0, dense_asym = 0.0;
    for (std::size_t i = 0; i < 86; ++i)
        for (std::size_t k = 0; k < 86; ++k) {
            const double gi = area[i] * b[i * 86 + k], gk = area[k] * b[k * 86 + i];
            asym = std::max(asym, std::abs(gi - gk) / std::max({gi, gk, 1e-300}));
            dense_asym = std::max(dense_asym, std::abs(area[i] * a[i * 86 + k] - area[k] * a[k * 86 + i]));
        }
    EXPECT_LE(asym, 1e-14);
    EXPECT_GT(dense_asym, 1e-9);  // the dense pairs' two directions differ within their tolerance
    fs::remove_all(d);
}

// The links are cached like the matrix: the next run loads them (status hit, nothing built) and
// writes the same radiosities byte for byte; `cache list`, `verify` and `clear` know the file.
TEST(HierarchicalCli, CachedLinksServeTheNextRun) {
    const fs::path d = fresh_dir("radiosa_hier_cache");
    const std::string cache = (d / "cache").string();
    const auto render = [&](const std::string& tag) {
        const CliRun r =
            run({"render", kScene, "-c", kCamA, "-o", (d / (tag + ".png")).string(), "--width", "32",
                 "--height", "24", "--ff-method", "hierarchical", "--cache-dir", cache, "--radiosities",
                 (d / (tag + ".csv")).string(), "--report", (d / (tag + ".json")).string(), "-q"});
        EXPECT_EQ(r.code, 0) << r.err;
        EXPECT_EQ(r.err, "");
        return read_json(d / (tag + ".json"));
    };
    const nlohmann::json cold = render("cold"), warm = render("warm");
    EXPECT_EQ(cold["form_factor_cache"]["status"], "miss");
    EXPECT_EQ(warm["form_factor_cache"]["status"], "hit");
    EXPECT_EQ(warm["form_factor_cache"]["compute_s"], 0.0);
    EXPECT_EQ(warm["hierarchy"]["links"], cold["hierarchy"]["links"]);
    EXPECT_EQ(warm["closure_max_error"], cold["closure_max_error"]);
    const std::string file = warm["form_factor_cache"]["file"];
    EXPECT_EQ(fs::path(file).extension(), ".rhl");
    const auto text = [](const fs::path& p) {
        std::ifstream in(p);
        return std::string{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    };
    EXPECT_EQ(text(d / "cold.csv"), text(d / "warm.csv"));
    EXPECT_GT(text(d / "cold.csv").size(), 86u * 20u);
    CliRun r = run({"cache", "list", "--cache-dir", cache});
    EXPECT_EQ(r.code, 0);
    EXPECT_NE(r.out.find("0 matrix file(s), 1 link file(s)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("links  baranoski1991"), std::string::npos) << r.out;
    r = run({"cache", "verify", "--cache-dir", cache});
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("ok   " + file), std::string::npos) << r.out;
    r = run({"cache", "clear", "--cache-dir", cache});
    EXPECT_NE(r.out.find("removed 1 file(s)"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(file));
    fs::remove_all(d);
}

// A relighting sequence over links. The seed scene's only light (face3) ramps: every frame is
// a multiple of the first frame's emission per channel, so it is `combined` from it (no sweep).
// Then face6 ramps up: its first frame is a new direction, a warm-started link solve
// (`iterated`, fewer sweeps than the cold first frame), and the frames after it combine the
// two. Every frame is the dense sequence's frame.
TEST(HierarchicalCli, RelitSequenceIsSolvedAheadOrCombinedOverLinks) {
    const fs::path d = fresh_dir("radiosa_hier_sequence");
    const fs::path seq = d / "dim.yaml";
    std::ofstream(seq)
        << "scene: " << kScene
        << "\nfps: 4\nduration_s: 2\ncamera:\n  keys:\n    - {time_s: 0, distance: 6, theta_deg: 0, "
           "phi_deg: 90, fov_deg: 50}\nevents:\n  - {time_s: [0, 1], surface: face3, emission: [1.2, "
           "1.1, 1.0]}\n  - {time_s: [1, 2], surface: face6, emission: [0.5, 0.2, 0.1]}\n";
    const auto render = [&](const std::string& tag, std::vector<std::string> extra) {
        fs::create_directories(d / tag);
        std::vector<std::string> args = {"render",
                                         "-s",
                                         seq.string(),
                                         "-o",
                                         (d / tag / "%02d.exr").string(),
                                         "--report",
                                         (d / (tag + ".json")).string(),
                                         "--width",
                                         "48",
                                         "--height",
                                         "32",
                                         "--samples",
                                         "1",
                                         "-q"};
        args.insert(args.end(), extra.begin(), extra.end());
        const CliRun r = run(args);
        EXPECT_EQ(r.code, 0) << r.err;
        return read_json(d / (tag + ".json"));
    };
    const nlohmann::json dense = render("dense", {});
    const nlohmann::json links = render("links", {"--ff-method", "hierarchical", "--ff-tolerance", "1e-5"});
    EXPECT_EQ(links["solve"]["method"], "links");
    ASSERT_EQ(links["frames"].size(), 8u);
    const long long cold = links["frames"][0]["sweeps"];
    EXPECT_GT(cold, 10);
    for (std::size_t f = 0; f < 8; ++f) {
        const nlohmann::json& fr = links["frames"][f];
        // Face6's first frame above 0 (t = 1.25 s) is not a combination of earlier ones: frame
        // 0's sweeps solve it ahead, beside frame 0's own emission.
        EXPECT_EQ(fr["solve"], f == 0 ? "iterated" : f == 5 ? "ahead" : "combined") << f;
        if (f > 0) {
            EXPECT_EQ(fr["sweeps"], 0) << f;
        }
        EXPECT_EQ(fr["entries_total"], links["hierarchy"]["links"]);
        const std::string name = fmt::format("{:02d}.exr", f);
        const auto [top, diff] = image_difference(d / "dense" / name, d / "links" / name);
        EXPECT_GT(top, 0.1f);
        EXPECT_LE(diff, 1e-6f * top) << f;
    }
    // About ten times the link tolerance: 1.01e-4 at worst (blue) since kinks in a ball's shadow
    // count in the estimates of the pairs of patches (9.5e-5 before).
    for (const auto& e : links["radiosity_error_estimate"]) EXPECT_LT(e.get<double>(), 2e-4);
    EXPECT_LT(links["solve"]["energy_balance_error"].get<double>(), 1e-6);
    EXPECT_TRUE(dense["radiosity_error_estimate"].is_null());
    fs::remove_all(d);
}

// --ff-receiver-tolerance: in the report, part of the links' cache key (links built with another
// are not served to a run with it), 0 turns the automatic one off, and refused without the
// hierarchical method.
TEST(HierarchicalCli, ReceiverToleranceIsInTheReportAndTheCacheKey) {
    const fs::path d = fresh_dir("radiosa_hier_receivers");
    const std::string cache = (d / "cache").string();
    const auto render = [&](const std::string& tag, std::vector<std::string> extra) {
        std::vector<std::string> args = {"render",      kScene,
                                         "-c",          kCamA,
                                         "-o",          (d / (tag + ".png")).string(),
                                         "--width",     "32",
                                         "--height",    "24",
                                         "--cache-dir", cache,
                                         "--report",    (d / (tag + ".json")).string(),
                                         "-q"};
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args);
    };
    CliRun r = render("plain", {"--ff-method", "hierarchical"});
    ASSERT_EQ(r.code, 0) << r.err;
    r = render("held", {"--ff-method", "hierarchical", "--ff-receiver-tolerance", "2e-6"});
    ASSERT_EQ(r.code, 0) << r.err;
    r = render("off", {"--ff-method", "hierarchical", "--ff-receiver-tolerance", "0"});
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json plain = read_json(d / "plain.json"), held = read_json(d / "held.json"),
                         off = read_json(d / "off.json");
    EXPECT_DOUBLE_EQ(plain["receiver_tolerance"].get<double>(), 2e-5 / 8);  // 86 patches: automatic
    EXPECT_EQ(held["receiver_tolerance"], 2e-6);
    EXPECT_TRUE(off["receiver_tolerance"].is_null());
    EXPECT_EQ(held["form_factor_cache"]["status"], "miss");
    EXPECT_EQ(off["form_factor_cache"]["status"], "miss");
    EXPECT_NE(held["form_factor_cache"]["file"], plain["form_factor_cache"]["file"]);
    EXPECT_NE(off["form_factor_cache"]["file"], plain["form_factor_cache"]["file"]);
    r = render("again", {"--ff-method", "hierarchical", "--ff-receiver-tolerance", "2e-6"});
    EXPECT_EQ(read_json(d / "again.json")["form_factor_cache"]["status"], "hit");
    r = render("dense", {"--ff-receiver-tolerance", "2e-6"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(
        r.err,
        "error: --ff-receiver-tolerance belongs to the hierarchical method: add --ff-method hierarchical, "
        "or remove it\n");
    EXPECT_FALSE(fs::exists(d / "dense.png"));
    r = render("negative", {"--ff-method", "hierarchical", "--ff-receiver-tolerance", "-1e-6"});
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("must be 0 (off) or in [1e-12, 0.1], got -1e-6"), std::string::npos) << r.err;
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
    // Moving surfaces need the dense path's incremental update in this version.
    const fs::path moving = d / "moving.yaml";
    std::ofstream(moving)
        << "scene: " << kScene
        << "\nfps: 2\nduration_s: 1\ncamera:\n  keys:\n    - {time_s: 0, distance: 6, theta_deg: 0, "
           "phi_deg: 90, fov_deg: 50}\nevents:\n  - {time_s: [0, 1], surface: sphere, translate: [0, "
           "0.1, 0]}\n";
    // Numbered images, so the refusal is the same in a build without video.
    r = run(
        {"render", "-s", moving.string(), "-o", (d / "f%02d.png").string(), "--ff-method", "hierarchical"});
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("hierarchical links are not updated for motion"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(d / "f00.png"));
    fs::remove_all(d);
}

}  // namespace radiosa
