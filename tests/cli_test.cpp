// End to end through the command line, in-process: exit codes, messages, outputs, report.
#include "app/cli.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_run.h"
#include "encode/encode.h"
#include "encode/image_io.h"

namespace radiosa {

namespace fs = std::filesystem;
using test::CliRun;
using test::fresh_dir;
using test::read_json;
using test::run;

namespace {
const std::string kScene = RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml";
const std::string kSceneC = RADIOSA_SOURCE_DIR "/scenes/baranoski1991-c.yaml";
const std::string kCamA = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml";
const std::string kCamB = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-b.yaml";

}  // namespace

TEST(Cli, RendersImageAndReport) {
    const fs::path d = fresh_dir("radiosa_cli_render");
    const CliRun r =
        run({"render", kScene, "--camera", kCamA, "-o", (d / "a.png").string(), "-o", (d / "a.exr").string(),
             "--report", (d / "a.json").string(), "--width", "64", "--height", "48", "--samples", "2"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("closure max"), std::string::npos);
    const Image png = media::read_image((d / "a.png").string());
    EXPECT_EQ(png.width, 64);
    EXPECT_EQ(png.height, 48);
    EXPECT_EQ(media::read_image((d / "a.exr").string()).width, 64);
    std::ifstream in(d / "a.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["patches"], 86);
    EXPECT_EQ(j["form_factor_method"], "adaptive");
    EXPECT_EQ(j["form_factor_tolerance"], 1e-6);
    EXPECT_TRUE(j["gauss_points"].is_null());
    EXPECT_EQ(j["numeric_inner"], "rules");
    for (const char* k : {"form_factors_s", "solve_s", "render_s", "total_s"})
        EXPECT_GE(j["timings"][k].get<double>(), 0.0);
    EXPECT_LT(j["reciprocity_abs_error"].get<double>(), 1e-6);
    EXPECT_LT(j["reciprocity_vs_estimate"].get<double>(), 1.0);
    EXPECT_LT(j["closure_max_error"].get<double>(), 1e-6);
    EXPECT_LT(j["energy_balance_error"].get<double>(), 2.3e-6);  // measured 2.25e-7 for image A
    // Nothing but the outputs is left behind (no temporary files).
    EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 3);
    fs::remove_all(d);
}

TEST(Cli, NumericInnerLinesIsReportedAndBelongsToTheAdaptiveMethod) {
    const fs::path d = fresh_dir("radiosa_cli_lines");
    const std::string report = (d / "r.json").string();
    CliRun r = run({"formfactors", kScene, "--ff-tolerance", "1e-3", "--ff-numeric-inner", "lines",
                    "--no-cache", "--report", report, "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(read_json(report)["numeric_inner"], "lines");
    r = run(
        {"formfactors", kScene, "--ff-method", "hierarchical", "--ff-numeric-inner", "lines", "--no-cache"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(
        r.err,
        "error: --ff-numeric-inner lines belongs to the adaptive method, not hierarchical: use --ff-method "
        "adaptive, or leave it out\n");
    fs::remove_all(d);
}

TEST(Cli, PaperImagesLookRight) {
    // A: the sphere in the middle is blue; B: the lit face 3 shows behind the sphere;
    // C: the single emitting ceiling patch is white, the rest of the ceiling is not.
    const fs::path d = fresh_dir("radiosa_cli_abc");
    auto render = [&](const std::string& scene, const std::string& cam, const std::string& name) {
        const CliRun r = run({"render", scene, "--camera", cam, "-o", (d / name).string(), "--width", "128",
                              "--height", "128", "--samples", "1", "-q"});
        EXPECT_EQ(r.code, 0) << r.err;
        EXPECT_EQ(r.out, "");
        return media::read_image((d / name).string());
    };
    const Image a = render(kScene, kCamA, "a.exr");
    const Rgb sphere = a.pixel(64, 64);
    EXPECT_GT(sphere.b, 1.3 * sphere.r);
    const Image b = render(kScene, kCamB, "b.exr");
    EXPECT_GT(b.pixel(36, 64).r, 1.27);  // face 3 behind: its radiosity includes E = 1.27
    EXPECT_LT(b.pixel(64, 64).b, b.pixel(36, 64).b);
    const Image c = render(kSceneC, kCamA, "c.exr");
    EXPECT_GT(c.pixel(64, 20).r, 7.0);  // centre of the ceiling, seen through face 3
    EXPECT_LT(c.pixel(20, 20).r, 1.0);
    fs::remove_all(d);
}

TEST(Cli, BadInputGivesOneMessageAndExitCodeOne) {
    CliRun r = run({"render", "no/such.yaml", "--camera", kCamA});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err, "error: no/such.yaml: no such file\n");
    r = run({"render", kScene, "--camera", kCamA, "--widht", "3"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err, "error: The following arguments were not expected: 3 --widht (see 'radiosa --help')\n");
    r = run({"render", kScene, "--camera", kCamA, "--width", "0"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err, "error: --width: Value 0 not in range 1 to 16384 (see 'radiosa --help')\n");
    r = run({"render", kScene, "--camera", kCamA, "--solver", "magic"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err,
              "error: --solver: magic not in {lu,gauss-jordan,jacobi,gauss-seidel,southwell} (see 'radiosa "
              "--help')\n");
    const fs::path d = fresh_dir("radiosa_cli_bad");
    std::ofstream(d / "bad.yaml") << "surfaces:\n  - name: s\n    type: sphere\n    center: [0, 0, 0]\n"
                                     "    radius: -2\n    patches: [8, 4]\n    reflectance: [0, 0, 0]\n";
    r = run({"render", (d / "bad.yaml").string(), "--camera", kCamA, "-o", (d / "x.png").string()});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err, "error: " + (d / "bad.yaml").string() + ":5:13: radius must be > 0, got -2\n");
    EXPECT_FALSE(fs::exists(d / "x.png"));
    fs::remove_all(d);
}

TEST(Cli, UnwritableOutputFailsBeforeAnyWork) {
    CliRun r = run({"render", kScene, "--camera", kCamA, "-o", "/nonexistent-radiosa/a.png"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(
        r.err,
        "error: /nonexistent-radiosa/a.png: directory '/nonexistent-radiosa' does not exist (create it or "
        "choose another output path)\n");
    r = run({"render", kScene, "--camera", kCamA, "-o", "/tmp/a.unknownformat", "--report",
             "/tmp/a-unknown.json"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err,
              "error: /tmp/a.unknownformat: no image writer for '.unknownformat' (use .png or .exr)\n");
    EXPECT_FALSE(fs::exists("/tmp/a-unknown.json"));  // refused before any work
    EXPECT_FALSE(fs::exists("/tmp/a.unknownformat"));
}

TEST(Cli, HelpExitsZero) {
    const CliRun r = run({"--help"});
    EXPECT_EQ(r.code, 0);
    EXPECT_NE(r.out.find("render"), std::string::npos);
}

}  // namespace radiosa

namespace radiosa {

TEST(Cli, NoSteadyStateIsRefusedAndNearSingularWarns) {
    const fs::path d = fresh_dir("radiosa_cli_furnace");
    auto furnace = [&](const std::string& rho) {
        const fs::path p = d / ("f" + rho + ".yaml");
        std::ofstream(p) << "closed: true\nform_factors:\n  tolerance: 1e-8\nsurfaces:\n  - name: shell\n    "
                            "type: sphere\n"
                            "    center: [0, 0, 0]\n    radius: 1\n    facing: inward\n    patches: [8, 4]\n"
                            "    reflectance: ["
                         << rho << ", " << rho << ", " << rho << "]\n    emission: [1, 1, 1]\n";
        return p.string();
    };
    const std::string cam = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml";
    const std::string one = furnace("1");
    CliRun r = run({"render", one, "-c", cam, "-o", (d / "x.png").string(), "--no-cache", "--width", "8",
                    "--height", "8"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(
        r.err,
        "error: " + one +
            ": every reflectance is 1 in the red channel of a closed scene: light is never "
            "absorbed, so radiosity grows without bound and there is no steady state (make some reflectance "
            "< 1, or the scene open)\n");
    EXPECT_FALSE(fs::exists(d / "x.png"));
    const std::string near = furnace("0.9995");
    r = run({"render", near, "-c", cam, "-o", (d / "y.exr").string(), "--no-cache", "--width", "8",
             "--height", "8", "-q"});
    EXPECT_EQ(r.code, 0);
    EXPECT_EQ(r.err.rfind("warning: " + near + ": nearly singular radiosity system in the red channel", 0),
              0u)
        << r.err;
    fs::remove_all(d);
}

}  // namespace radiosa

namespace radiosa {

TEST(Cli, SceneWithoutEmissionRendersBlackWithoutASolve) {
    const fs::path d = fresh_dir("radiosa_cli_dark");
    std::ofstream(d / "dark.yaml") << "closed: false\nsurfaces:\n  - name: floor\n    type: quad\n"
                                      "    corners: [[-2, -2, -1], [2, -2, -1], [2, 2, -1], [-2, 2, -1]]\n"
                                      "    patches: [2, 2]\n    reflectance: [0.5, 0.5, 0.5]\n";
    const CliRun r =
        run({"render", (d / "dark.yaml").string(), "-c", RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml",
             "-o", (d / "d.exr").string(), "--report", (d / "r.json").string(), "--width", "16", "--height",
             "16", "--no-cache", "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = read_json(d / "r.json");
    EXPECT_EQ(j["solve"]["factorisations"], 0);
    EXPECT_EQ(j["solve"]["skipped"], "no emission: the image is black");
    EXPECT_EQ(j["left_out"]["solve_skipped"], true);
    EXPECT_EQ(j["left_out"]["factorisations_shared"], 3);
    EXPECT_EQ(j["left_out"]["channel_solves_shared"], 3);
    const Image img = media::read_image((d / "d.exr").string());
    for (float v : img.rgb) EXPECT_EQ(v, 0.0f);
    fs::remove_all(d);
}

}  // namespace radiosa

namespace radiosa {

// A sensor anywhere inside a closed box whose walls all emit E and reflect rho sees the
// furnace's radiosity E / (1 - rho) from every direction: its irradiance is that, whatever its
// place and normal, and its form factors sum to 1.
TEST(Cli, SensorInAFurnaceReadsTheRadiosity) {
    const fs::path d = fresh_dir("radiosa_cli_sensor");
    const char* faces[6] = {"[[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1]]",
                            "[[-1, -1, 1], [-1, 1, 1], [1, 1, 1], [1, -1, 1]]",
                            "[[-1, -1, -1], [-1, -1, 1], [1, -1, 1], [1, -1, -1]]",
                            "[[-1, 1, -1], [1, 1, -1], [1, 1, 1], [-1, 1, 1]]",
                            "[[-1, -1, -1], [-1, 1, -1], [-1, 1, 1], [-1, -1, 1]]",
                            "[[1, -1, -1], [1, -1, 1], [1, 1, 1], [1, 1, -1]]"};
    std::string scene = "surfaces:\n";
    for (int k = 0; k < 6; ++k)
        scene += "  - {name: f" + std::to_string(k) + ", type: quad, corners: " + faces[k] +
                 ", patches: [2, 2], reflectance: [0.5, 0.25, 0.75], emission: [1, 1, 1]}\n";
    scene += "  - {name: meter, type: sensor, position: [0.1, -0.2, 0.3], normal: [1, 1, 1]}\n";
    std::ofstream(d / "box.yaml") << scene;
    std::ofstream(d / "cam.yaml") << "camera: {distance: 0.5, theta_deg: 0, phi_deg: 90, fov_deg: 60}\n";
    const CliRun r = run({"render", (d / "box.yaml").string(), "--camera", (d / "cam.yaml").string(), "-o",
                          (d / "i.png").string(), "--report", (d / "r.json").string(), "--width", "16",
                          "--height", "16", "--samples", "1"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("sensor meter: irradiance (2, 1.33333, 4)"), std::string::npos) << r.out;
    std::ifstream in(d / "r.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    ASSERT_EQ(j["sensors"].size(), 1u);
    EXPECT_EQ(j["sensors"][0]["name"], "meter");
    EXPECT_NEAR(j["sensors"][0]["irradiance"][0].get<double>(), 2.0, 1e-6);
    EXPECT_NEAR(j["sensors"][0]["irradiance"][1].get<double>(), 4.0 / 3.0, 1e-6);
    EXPECT_NEAR(j["sensors"][0]["irradiance"][2].get<double>(), 4.0, 1e-6);
    EXPECT_EQ(j["patches"], 24);  // the sensor is no patch

    const CliRun f = run({"formfactors", (d / "box.yaml").string(), "--sensors", (d / "s.csv").string()});
    ASSERT_EQ(f.code, 0) << f.err;
    std::ifstream csv(d / "s.csv");
    std::string header, row;
    std::getline(csv, header);
    std::getline(csv, row);
    EXPECT_EQ(header.substr(0, 20), "sensor,\"f0[0,0]\",\"f0");
    EXPECT_EQ(row.substr(0, 8), "\"meter\",");
    double sum = 0.0;
    std::stringstream cells(row.substr(8));
    for (std::string c; std::getline(cells, c, ',');) sum += std::stod(c);
    EXPECT_NEAR(sum, 1.0, 1e-9);
    // In a sequence, each frame's report reads the radiosity of that frame's lights: every wall
    // doubles its emission at 1 s.
    std::string seq =
        "scene: box.yaml\nfps: 2\nduration_s: 2\nimage: {width: 8, height: 8, samples: 1}\n"
        "camera:\n  keys:\n    - {time_s: 0, distance: 0.5, theta_deg: 0, phi_deg: 90, fov_deg: 60}\n"
        "events:\n";
    for (int k = 0; k < 6; ++k)
        seq += "  - {time_s: 1, surface: f" + std::to_string(k) + ", emission: [2, 2, 2]}\n";
    std::ofstream(d / "seq.yaml") << seq;
    const CliRun q = run({"render", "--sequence", (d / "seq.yaml").string(), "-o", (d / "f%02d.png").string(),
                          "--report", (d / "q.json").string()});
    ASSERT_EQ(q.code, 0) << q.err;
    std::ifstream qin(d / "q.json");
    const nlohmann::json qj = nlohmann::json::parse(qin);
    ASSERT_EQ(qj["frames"].size(), 4u);
    for (int f = 0; f < 4; ++f) {
        const double e = f < 2 ? 1.0 : 2.0;
        ASSERT_EQ(qj["frames"][f]["sensors"].size(), 1u);
        EXPECT_NEAR(qj["frames"][f]["sensors"][0]["irradiance"][2].get<double>(), 4.0 * e, 1e-6) << f;
    }
    // A scene without sensors says so and writes nothing.
    const CliRun none = run({"formfactors", kScene, "--sensors", (d / "none.csv").string()});
    EXPECT_EQ(none.code, 1);
    EXPECT_NE(none.err.find("the scene has no sensors"), std::string::npos) << none.err;
    EXPECT_FALSE(fs::exists(d / "none.csv"));
    fs::remove_all(d);
}

}  // namespace radiosa
