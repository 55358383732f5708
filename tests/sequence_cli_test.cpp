// Sequences end to end: videos read back with libavformat, the report's per-frame actions,
// frames equal to the same frame rendered alone, and outputs refused before any work.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/cli.h"
#include "app/sequence_job.h"
#include "cli_run.h"
#include "encode/encode.h"
#include "encode/features.h"
#include "encode/image_io.h"
#include "encode/video_writer.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "render/camera.h"
#include "render/shading.h"
#include "scene/scene.h"
#include "schedule/sequence.h"
#include "test_scenes.h"

namespace radiosa {

namespace fs = std::filesystem;
using test::CliRun;
using test::fresh_dir;
using test::read_json;
using test::run;

namespace {
const std::string kScene = RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml";
const std::string kABC = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-abc.yaml";

fs::path write_sequence(const fs::path& dir, double fps, double duration) {
    return test::write_short_sequence(dir, fps, duration);
}
}  // namespace

TEST(SequenceCli, VideoHasTheRightFramesDurationAndRate) {
    if (!kHasVideo) GTEST_SKIP() << kNoVideoMessage;
    const fs::path d = fresh_dir("radiosa_seq_video");
    const fs::path seq = write_sequence(d, 24, 0.5);
    const CliRun r = run({"render", "--sequence", seq.string(), "-o", (d / "v.mp4").string(), "--width", "64",
                          "--height", "48", "--samples", "1", "--report", (d / "r.json").string()});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("12 frames at 24 fps"), std::string::npos) << r.out;
    const media::VideoProbe v = media::probe_video(d / "v.mp4");
    EXPECT_EQ(v.codec, "h264");
    EXPECT_EQ(v.frames, 12);
    EXPECT_EQ(v.width, 64);
    EXPECT_EQ(v.height, 48);
    EXPECT_NEAR(v.fps, 24.0, 1e-9);
    EXPECT_NEAR(v.duration_s, 0.5, 1.0 / 24);
    const auto j = read_json(d / "r.json");
    EXPECT_EQ(j["frame_count"], 12);
    EXPECT_EQ(j["frames"].size(), 12u);
    EXPECT_EQ(j["totals"]["renders"], 12);
    // No temporary file is left beside the outputs.
    EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 3);
    fs::remove_all(d);
}

TEST(SequenceCli, PaperSequenceReproducesTable3Structure) {
    const fs::path d = fresh_dir("radiosa_seq_abc");
    const CliRun r =
        run({"render", "--sequence", kABC, "-o", (d / "%d.png").string(), "--width", "64", "--height", "64",
             "--samples", "1", "--report", (d / "r.json").string(), "--cache-dir", (d / "cache").string()});
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = read_json(d / "r.json");
    const auto& f = j["frames"];
    ASSERT_EQ(f.size(), 3u);
    EXPECT_EQ(f[0]["form_factors"], "computed");
    EXPECT_EQ(f[0]["solve"], "factorised");
    EXPECT_EQ(f[0]["render"], "rendered");
    EXPECT_EQ(f[1]["form_factors"], "reused");
    EXPECT_EQ(f[1]["solve"], "reused");
    EXPECT_EQ(f[1]["render"], "rendered");
    EXPECT_EQ(f[2]["form_factors"], "reused");
    EXPECT_EQ(f[2]["solve"], "substituted");
    EXPECT_EQ(f[2]["render"], "rendered");
    // Frame A carries the factorisation (0.35 ms measured: LU and stability bounds of two
    // channels), C only a substitution (0.03 ms); a bug once dropped A's factorisation time.
    // Only that it is kept is asserted: a ratio of sub-millisecond times fails on a loaded
    // machine (it did in CI), and speed belongs in the benchmarks.
    EXPECT_GT(f[0]["solve_s"].get<double>(), 0.0);
    EXPECT_GT(f[2]["solve_s"].get<double>(), 0.0);
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(fs::exists(d / (std::to_string(k) + ".png")));
    // One reflectance set (red = green: 2 factorisations of 3) and two lightings (4 channel
    // substitutions of 6); the stability figures cover every solve.
    EXPECT_EQ(j["left_out"]["factorisations"], 2);
    EXPECT_EQ(j["left_out"]["factorisations_shared"], 1);
    EXPECT_EQ(j["left_out"]["channel_solves"], 4);
    EXPECT_EQ(j["left_out"]["channel_solves_shared"], 2);
    EXPECT_EQ(j["left_out"]["pairs_culled"], 712);
    EXPECT_GT(j["solve"]["spectral_radius"].get<double>(), 0.5);
    EXPECT_LT(j["solve"]["spectral_radius"].get<double>(), 0.9);
    EXPECT_LT(j["solve"]["residual"].get<double>(), 1e-12);
    EXPECT_LT(j["solve"]["energy_balance_error"].get<double>(), 2e-6);
    // A second run finds the matrix in the cache.
    ASSERT_EQ(run({"render", "--sequence", kABC, "-o", (d / "%d.png").string(), "--width", "64", "--height",
                   "64", "--samples", "1", "-q", "--report", (d / "r2.json").string(), "--cache-dir",
                   (d / "cache").string()})
                  .code,
              0);
    EXPECT_EQ(read_json(d / "r2.json")["frames"][0]["form_factors"], "cached");
    // Image C: the ceiling's central patch is lit, face 3 is dark.
    const Image c = media::read_image((d / "2.png").string());
    const Image a = media::read_image((d / "0.png").string());
    EXPECT_GT(c.pixel(32, 10).r, 0.99);
    EXPECT_LT(c.pixel(32, 60).r, a.pixel(32, 60).r);
    fs::remove_all(d);
}

TEST(SequenceCli, AnIterativeSolverIsWarmStartedAndGivesLUsFrames) {
    // 12 frames of a light ramp: with --solver gauss-seidel every new light state is
    // "iterated", each from the last one's radiosities, and costs fewer sweeps than the first
    // (which starts from the emission); the frames are LU's.
    const fs::path d = fresh_dir("radiosa_seq_iterated");
    const fs::path seq = write_sequence(d, 24, 0.5);
    auto render = [&](const std::string& solver, const std::string& tag) {
        return run({"render", "--sequence", seq.string(), "-o", (d / (tag + "%d.png")).string(), "--width",
                    "48", "--height", "48", "--samples", "1", "--solver", solver, "--report",
                    (d / (tag + ".json")).string(), "--cache-dir", (d / "cache").string()});
    };
    CliRun r = render("lu", "lu");
    ASSERT_EQ(r.code, 0) << r.err;
    r = render("gauss-seidel", "gs");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = read_json(d / "gs.json");
    const auto& f = j["frames"];
    ASSERT_EQ(f.size(), 12u);
    EXPECT_EQ(f[0]["solve"], "iterated");
    const int first = f[0]["sweeps"].get<int>();
    EXPECT_GT(first, 5);
    int iterated = 0;
    for (std::size_t k = 1; k < f.size(); ++k) {
        if (f[k]["solve"] == "reused") {
            EXPECT_EQ(f[k]["sweeps"], 0) << k;
            continue;
        }
        EXPECT_EQ(f[k]["solve"], "iterated") << k;
        EXPECT_LT(f[k]["sweeps"].get<int>(), first) << k;  // warm-started
        ++iterated;
    }
    EXPECT_GE(iterated, 5);
    EXPECT_EQ(read_json(d / "lu.json")["frames"][0]["solve"], "factorised");
    EXPECT_LT(j["solve"]["residual"].get<double>(), 1e-11);
    for (int k : {0, 6, 11}) {
        const Image a = media::read_image((d / ("lu" + std::to_string(k) + ".png")).string());
        const Image b = media::read_image((d / ("gs" + std::to_string(k) + ".png")).string());
        ASSERT_EQ(a.rgb.size(), b.rgb.size());
        double worst = 0.0;
        for (std::size_t i = 0; i < a.rgb.size(); ++i)
            worst = std::max(worst, static_cast<double>(std::abs(a.rgb[i] - b.rgb[i])));
        EXPECT_LE(worst, 1.0 / 255 + 1e-9) << "frame " << k;
    }
    fs::remove_all(d);
}

// A frame produced by the scheduler (substitution into a kept factorisation, shared nodes,
// encoder thread) has exactly the pixels of the same frame computed from scratch, for any
// thread count.
TEST(SequenceCli, ScheduledFrameEqualsTheFrameRenderedAlone) {
    const fs::path d = fresh_dir("radiosa_seq_alone");
    const fs::path seq_path = write_sequence(d, 10, 1.0);
    auto frames_with = [&](int threads) {
        SequenceJob job;
        job.sequence_path = seq_path.string();
        job.outputs = {(d / "f%02d.exr").string()};
        job.width = 48;
        job.height = 40;
        job.samples = 2;
        job.threads = threads;
        job.form_factors.cache.enabled = false;
        std::vector<Image> frames;
        job.on_frame = [&](int, const Image& im) { frames.push_back(im); };
        run_sequence_job(job);
        return frames;
    };
    const std::vector<Image> two = frames_with(8);  // more threads than cores
    const std::vector<Image> one = frames_with(1);
    ASSERT_EQ(two.size(), 10u);
    for (std::size_t k = 0; k < two.size(); ++k) EXPECT_EQ(two[k].rgb, one[k].rgb) << "frame " << k;

    const int k = 5;  // mid-ramp, mid-orbit
    const Scene scene = load_scene(kScene);
    const Sequence seq = load_sequence(seq_path.string(), &scene);
    const Image alone =
        test::frame_alone(scene, seq, k,
                          resolve_form_factor_options(scene.form_factors, std::nullopt, std::nullopt,
                                                      std::nullopt, std::nullopt),
                          48, 40, 2);
    EXPECT_EQ(alone.rgb, two[k].rgb);
    // And the EXR frame on disk holds the same floats.
    EXPECT_EQ(media::read_image(frame_path((d / "f%02d.exr").string(), k)).rgb, alone.rgb);
    fs::remove_all(d);
}

TEST(SequenceCli, BadOutputsAreRefusedBeforeAnyWork) {
    const fs::path d = fresh_dir("radiosa_seq_bad");
    const fs::path seq = write_sequence(d, 10, 1.0);
    CliRun r =
        run({"render", "-s", seq.string(), "-o", (d / "v.mp4").string(), "--width", "63", "--height", "48"});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(
        r.err,
        "error: " + (d / "v.mp4").string() +
            (kHasVideo
                 ? ": H.264 in yuv420p needs an even width and height, got 63x48 (use --width/--height)\n"
                 : std::string(": ") + kNoVideoMessage + "\n"));
    r = run({"render", "-s", seq.string(), "-o", (d / "frame.png").string()});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err,
              "error: " + (d / "frame.png").string() +
                  ": a sequence is written as a video (.mp4) or as numbered images with one %d or %04d in "
                  "the name, e.g. out/frames/%04d.png\n");
    r = run({"render", "-s", seq.string(), "-o", "/nonexistent-radiosa/v.mp4"});
    EXPECT_EQ(r.code, 1);
    r = run({"render", kScene, "-s", seq.string(), "-c", RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml"});
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("excludes"), std::string::npos) << r.err;
    r = run({"render", kScene});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err,
              "error: render: give --camera CAMERA.yaml for a still or --sequence SEQUENCE.yaml for an "
              "animation\n");
    EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 1);  // only seq.yaml
    fs::remove_all(d);
}

// A build without libav (-DRADIOSA_VIDEO=OFF) refuses video and palette outputs before any
// work, with the way out in the message, and says what it has in --version; a build with it
// says so too.
TEST(SequenceCli, OutputsThisBuildCannotWriteAreRefusedBeforeAnyWork) {
    CliRun r = run({"--version"});
    EXPECT_EQ(r.code, 0);
    EXPECT_NE(r.out.find(kHasVideo ? "outputs (libav): yes" : "outputs (libav): no"), std::string::npos)
        << r.out;
    if (kHasVideo) return;
    const fs::path d = fresh_dir("radiosa_seq_novideo");
    const fs::path seq = write_sequence(d, 4, 0.4);
    for (const auto& args : {std::vector<std::string>{"-o", (d / "v.mp4").string()},
                             std::vector<std::string>{"--palette", "16", "-o", (d / "p.gif").string()},
                             std::vector<std::string>{"--palette", "16", "-o", (d / "p%d.png").string()}}) {
        std::vector<std::string> a = {"render", "-s", seq.string(), "--width", "16", "--height", "16"};
        a.insert(a.end(), args.begin(), args.end());
        r = run(a);
        EXPECT_EQ(r.code, 1);
        EXPECT_NE(r.err.find(kNoVideoMessage), std::string::npos) << r.err;
    }
    EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 1);  // only seq.yaml
    fs::remove_all(d);
}

TEST(SequenceCli, PaletteSequenceWritesGifAndIndexedPngsAndReportsPsnr) {
    if (!kHasVideo) GTEST_SKIP() << kNoVideoMessage;
    const fs::path d = fresh_dir("radiosa_seq_palette");
    const fs::path seq = write_sequence(d, 10, 0.4);
    CliRun r = run({"render", "-s", seq.string(), "--palette", "16", "-o", (d / "p.gif").string(), "-o",
                    (d / "p%d.png").string(), "--width", "40", "--height", "30", "--samples", "1", "--report",
                    (d / "r.json").string()});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("PSNR vs true colour"), std::string::npos);
    const auto j = read_json(d / "r.json");
    EXPECT_EQ(j["palette"]["colours"], 16);
    EXPECT_EQ(j["palette"]["quantiser"], "median-cut");
    const double mc = j["palette"]["psnr_db"]["median-cut"], pop = j["palette"]["psnr_db"]["popularity"];
    EXPECT_GT(mc, 25.0);
    EXPECT_GT(mc, pop);  // measured on the demo: 30.4 vs 23.8 dB at 16 colours
    EXPECT_EQ(media::probe_video(d / "p.gif").frames, 4);
    for (int k = 0; k < 4; ++k)
        EXPECT_EQ(media::read_image(frame_path((d / "p%d.png").string(), k)).width, 40);
    r = run({"render", "-s", seq.string(), "--palette", "16", "-o", (d / "v.mp4").string()});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err,
              "error: " + (d / "v.mp4").string() +
                  ": with --palette, write a .gif or numbered indexed PNGs such as out/frames/%04d.png\n");
    fs::remove_all(d);
}

}  // namespace radiosa
