// Moving surfaces: incremental form factors equal the matrix computed from scratch, bit for
// bit; they recompute only what a move can change; a sequence's frames equal stills of the
// static scene with the surfaces where the frame has them; a return to an earlier place
// recomputes nothing.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "app/sequence_job.h"
#include "cache/cache_file.h"
#include "cli_run.h"
#include "formfactor/incremental.h"
#include "geometry/scene_geometry.h"
#include "render/camera.h"
#include "render/raycast.h"
#include "render/shading.h"
#include "scene/scene.h"
#include "schedule/sequence.h"
#include "solve/solver.h"
#include "test_scenes.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

// A box of side 4 (faces 2 x 2, facing in) with a ball of radius 0.3 standing above its floor.
std::string box_with_ball(const std::string& ball_transform = "") {
    return "closed: true\nsurfaces:\n" + test::cube_faces(2.0, 0.0, 2) +
           "  - {name: ball, type: sphere, center: [0.8, 0.5, -1.6], radius: 0.3, patches: [4, 2], "
           "reflectance: [0.6, 0.3, 0.2]" +
           ball_transform + "}\n";
}

// The scene with surface k displaced by `motion` (sequence-style).
Scene moved(const Scene& base, int k, const Similarity& motion) {
    Scene s = base;
    s.surfaces[static_cast<std::size_t>(k)].shape =
        moved_shape(base.surfaces[static_cast<std::size_t>(k)], motion);
    return s;
}

Similarity roll(double angle_deg, const Vec3& axis, const Vec3& about, const Vec3& translate) {
    Similarity m;
    m.rotate = rotation_deg(axis, angle_deg);
    m.translate = about - m.rotate * about + translate;
    return m;
}

void expect_same_bits(const FormFactors& a, const FormFactors& b) {
    ASSERT_EQ(a.F.n, b.F.n);
    for (int i = 0; i < a.F.n; ++i)
        for (int j = 0; j < a.F.n; ++j) ASSERT_EQ(a.F(i, j), b.F(i, j)) << i << " " << j;
    EXPECT_EQ(a.error, b.error);
}

}  // namespace

TEST(MovingSurfaces, AnUpdateIsTheMatrixComputedFromScratchAndAStaticSceneHasItsKey) {
    const Scene base = parse_scene(box_with_ball(), "box.yaml");
    const int ball = base.find_surface("ball");
    const Similarity m = roll(37.5, Vec3(-1, 0, 0), Vec3(0.8, 0.5, -1.6), Vec3(-0.4, 1.1, 0.0));
    const Scene after = moved(base, ball, m);
    // The same place written in a scene file: the transform's bits are the motion's.
    const Scene written = parse_scene(
        box_with_ball(fmt::format(", transform: {{rotate_deg: {{axis: [-1, 0, 0], angle: 37.5}}, translate: "
                                  "[{:.17g}, {:.17g}, {:.17g}]}}",
                                  m.translate.x, m.translate.y, m.translate.z)),
        "box.yaml");
    for (const FormFactorOptions& o : {FormFactorOptions::adaptive(1e-6), FormFactorOptions::gauss(4)}) {
        EXPECT_EQ(form_factor_key(after, o), form_factor_key(written, o));
        const SceneGeometry g0(base), g1(after), gw(written);
        const FormFactors before = compute_form_factors(g0, o);
        FormFactorUpdate u;
        const FormFactors updated = update_form_factors(g0, before, g1, o, &u);
        expect_same_bits(updated, compute_form_factors(gw, o));
        // Updated in place (a state past its last frame gives its matrix up): the same bits.
        FormFactors spare = before;
        FormFactorUpdate in_place;
        expect_same_bits(update_form_factors(g0, std::move(spare), g1, o, &in_place), updated);
        // And back again: the update of the update is the first matrix.
        FormFactorUpdate back;
        expect_same_bits(update_form_factors(g1, updated, g0, o, &back), before);
        EXPECT_EQ(u.surfaces_moved, 1);
        EXPECT_FALSE(u.full);
        EXPECT_EQ(u.entries_total, 32 * 32);
        EXPECT_GT(u.pairs_unchanged, 0);  // the walls' pairs the ball cannot come between
        EXPECT_EQ(u.pairs_moved + u.pairs_shadowed + u.pairs_unchanged, 32 * 33 / 2);
    }
}

TEST(MovingSurfaces, AMotionNothingCanSeeRecomputesOnlyTheMovedSurfacesOwnEntries) {
    // A ball outside the box (whose faces face in) moves: no pair of the box can change.
    const Scene base = parse_scene("closed: false\nsurfaces:\n" + test::cube_faces(2.0, 0.0, 2) +
                                       "  - {name: ball, type: sphere, center: [6, 0, 0], radius: 0.5, "
                                       "patches: [4, 2], reflectance: [0.5, "
                                       "0.5, 0.5]}\n",
                                   "outside.yaml");
    const int ball = base.find_surface("ball");
    Similarity m;
    m.translate = Vec3(0.0, 1.5, 0.5);
    const Scene after = moved(base, ball, m);
    const SceneGeometry g0(base), g1(after);
    const FormFactorOptions o = FormFactorOptions::adaptive(1e-6);
    FormFactorUpdate u;
    const FormFactors updated = update_form_factors(g0, compute_form_factors(g0, o), g1, o, &u);
    const long long n = 32, nb = 8;
    EXPECT_EQ(u.pairs_shadowed, 0);
    EXPECT_EQ(u.pairs_moved, nb * (nb + 1) / 2 + nb * (n - nb));
    EXPECT_EQ(u.entries_recomputed, nb * nb + 2 * nb * (n - nb));
    EXPECT_EQ(u.pairs_unchanged, (n - nb) * (n - nb + 1) / 2);
    expect_same_bits(updated, compute_form_factors(g1, o));
}

TEST(MovingSurfaces, AnOccluderMovingBetweenTwoWallsRecomputesTheirEntryAndNoOther) {
    // Floor and ceiling face each other; left and right face each other far from them (each
    // behind the other pair's planes or out of their hulls); a small plate moves from beside
    // the room to between floor and ceiling. A marker facing away from everything keeps the
    // scene's extent (which the update needs unchanged, or it recomputes everything).
    const Scene base = test::scene_of(
        test::quad("floor", test::kFloor) + test::quad("ceiling", test::kCeiling) +
        test::quad("left", "[[-5, 0, 0], [-5, 0, 1], [-5, 1, 1], [-5, 1, 0]]") +
        test::quad("right", "[[-7, 0, 0], [-7, 1, 0], [-7, 1, 1], [-7, 0, 1]]") +
        test::quad("plate", "[[5.3, 0.3, 0.5], [5.3, 0.7, 0.5], [5.7, 0.7, 0.5], [5.7, 0.3, 0.5]]") +
        test::quad("marker", "[[8, 0, 0], [8, 1, 0], [8, 1, 1], [8, 0, 1]]"));
    const int plate = base.find_surface("plate");
    Similarity m;
    m.translate = Vec3(-5.0, 0.0, 0.0);
    const Scene after = moved(base, plate, m);
    const SceneGeometry g0(base), g1(after);
    const FormFactorOptions o = FormFactorOptions::adaptive(1e-9);
    const FormFactors before = compute_form_factors(g0, o);
    FormFactorUpdate u;
    const FormFactors updated = update_form_factors(g0, before, g1, o, &u);
    EXPECT_FALSE(u.full);
    EXPECT_EQ(u.pairs_moved, 6);     // the plate with each of the 6 patches, itself included
    EXPECT_EQ(u.pairs_shadowed, 1);  // floor and ceiling
    EXPECT_EQ(u.pairs_unchanged, 14);
    EXPECT_EQ(u.entries_recomputed, 2 * 5 + 1 + 2);
    EXPECT_LT(updated.F(0, 1), before.F(0, 1) - 0.01);  // the plate now hides part of the ceiling
    expect_same_bits(updated, compute_form_factors(g1, o));
}

namespace {

fs::path write_box_sequence(const fs::path& dir, const std::string& events, double duration) {
    std::ofstream(dir / "box.yaml") << box_with_ball();
    std::ofstream(dir / "seq.yaml")
        << "scene: box.yaml\nfps: 1\nduration_s: " << duration
        << "\ncamera:\n  keys:\n    - {time_s: 0, position: [0, -1.9, 0], look_at: [0.8, 0.5, "
           "-1.6], fov_deg: 70}\nevents:\n"
        << events;
    return dir / "seq.yaml";
}

SequenceJob box_job(const fs::path& dir, const fs::path& seq, std::vector<Image>* frames) {
    SequenceJob job;
    job.sequence_path = seq.string();
    job.outputs = {(dir / "f%02d.exr").string()};
    job.width = 40;
    job.height = 30;
    job.samples = 1;
    job.form_factors.cache.dir = dir / "cache";
    job.on_frame = [frames](int, const Image& im) { frames->push_back(im); };
    return job;
}

}  // namespace

TEST(MovingSurfaces, AFrameIsTheStillOfTheStaticSceneWithTheBallWhereTheFrameHasIt) {
    const fs::path d = test::fresh_dir("radiosa_moving_still");
    const fs::path seq =
        write_box_sequence(d,
                           "  - time_s: [0, 3]\n    surface: ball\n    translate: [-0.6, 1.2, 0]\n"
                           "    rotate_deg: {axis: [-1, 0, 0], angle: 80, about: [0.8, 0.5, -1.6]}\n"
                           "  - {time_s: 1, surface: f1, emission: [3, 3, 3]}\n",
                           4);
    std::vector<Image> frames;
    const SequenceReport r = run_sequence_job(box_job(d, seq, &frames));
    ASSERT_EQ(frames.size(), 4u);
    EXPECT_EQ(r.geometry_states, 4);
    EXPECT_STREQ(r.frames[2].form_factors, "updated");

    const int k = 2;  // t = 2 s: 2/3 of the roll, lit
    const Scene base = load_scene((d / "box.yaml").string());
    const Sequence s = load_sequence(seq.string(), &base);
    const double u = (2.0 - 0.0) / (3.0 - 0.0);
    const double angle = 0.0 + u * (80.0 - 0.0);
    const Similarity m = s.motion_at(static_cast<int>(base.surfaces.size()), s.frame_time(k))[6];
    std::ofstream(d / "still.yaml") << box_with_ball(
        fmt::format(", transform: {{rotate_deg: {{axis: [-1, 0, 0], angle: {:.17g}}}, translate: [{:.17g}, "
                    "{:.17g}, {:.17g}]}}",
                    angle, m.translate.x, m.translate.y, m.translate.z));
    const Image alone =
        test::frame_alone(load_scene((d / "still.yaml").string()), s, k,
                          FormFactorOptions::adaptive(kDefaultFormFactorTolerance), 40, 30, 1);
    EXPECT_EQ(alone.rgb, frames[static_cast<std::size_t>(k)].rgb);
    fs::remove_all(d);
}

TEST(MovingSurfaces, ReturningToAnEarlierPlaceRecomputesNothing) {
    const fs::path d = test::fresh_dir("radiosa_moving_return");
    const fs::path seq = write_box_sequence(d,
                                            "  - {time_s: 0, surface: f1, emission: [3, 3, 3]}\n"
                                            "  - {time_s: 1, surface: ball, translate: [-1, 0.5, 0]}\n"
                                            "  - {time_s: 2, surface: ball, translate: [0, 0, 0]}\n"
                                            "  - {time_s: 3, surface: ball, translate: [-1, 0.5, 0]}\n",
                                            4);
    std::vector<Image> frames;
    SequenceJob job = box_job(d, seq, &frames);
    job.report_path = (d / "r.json").string();
    const SequenceReport r = run_sequence_job(job);
    ASSERT_EQ(r.frames.size(), 4u);
    EXPECT_EQ(r.geometry_states, 2);
    const char* expected[] = {"computed", "updated", "reused", "reused"};
    for (int f = 0; f < 4; ++f)
        EXPECT_STREQ(r.frames[static_cast<std::size_t>(f)].form_factors, expected[f]) << f;
    EXPECT_EQ(r.frames[2].entries_recomputed, 0);
    EXPECT_EQ(r.frames[3].entries_recomputed, 0);
    EXPECT_EQ(frames[0].rgb, frames[2].rgb);
    EXPECT_EQ(frames[1].rgb, frames[3].rgb);
    EXPECT_NE(frames[0].rgb, frames[1].rgb);
    const auto j = test::read_json(d / "r.json");
    EXPECT_EQ(j["motion"]["geometry_states"], 2);
    EXPECT_EQ(j["motion"]["states_updated"], 1);
    EXPECT_EQ(j["frames"][1]["form_factors"], "updated");
    EXPECT_GT(j["frames"][1]["form_factor_update"]["pairs_unchanged"].get<long long>(), 0);
    EXPECT_EQ(j["frames"][1]["entries_total"], 32 * 32);
    fs::remove_all(d);
}

TEST(MovingSurfaces, AMotionIntoAnotherSurfaceIsRefusedWithStrict) {
    const fs::path d = test::fresh_dir("radiosa_moving_strict");
    const fs::path seq =
        write_box_sequence(d, "  - {time_s: 1, surface: ball, translate: [0, 0, -0.2]}\n", 2);
    std::vector<Image> frames;
    SequenceJob job = box_job(d, seq, &frames);
    job.form_factors.strict = true;
    try {
        run_sequence_job(job);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  seq.string() +
                      ":8:5: at t = 1.000 s the motion makes 'f0' and 'ball' intersect; "
                      "change the motion (touching is fine) or run without --strict");
    }
    fs::remove_all(d);
}

}  // namespace radiosa
