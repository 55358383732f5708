// Sequence files, camera interpolation and the scheduler's plans.
#include "schedule/sequence.h"

#include <gtest/gtest.h>

#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "schedule/scheduler.h"

namespace radiosa {

namespace {

const std::string kSeed = RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml";

const char* kOrbitKeys = R"(camera:
  interpolation: constant-speed
  keys:
    - time_s: 0
      distance: 6
      theta_deg: 0
      phi_deg: 90
    - time_s: 1
      distance: 6
      theta_deg: 90
      phi_deg: 90
)";

Sequence seq(const std::string& body, const Scene* scene) { return parse_sequence(body, "s.yaml", scene); }

std::string error_of(const std::string& body, const Scene* scene) {
    try {
        seq(body, scene);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST(Sequence, FrameCountAndDefaults) {
    const Scene scene = load_scene(kSeed);
    Sequence s = seq(std::string("fps: 10\n") + kOrbitKeys, &scene);
    EXPECT_EQ(s.frames, 11);  // up to and including the last key
    s = seq(std::string("fps: 10\nduration_s: 1\n") + kOrbitKeys, &scene);
    EXPECT_EQ(s.frames, 10);
    EXPECT_DOUBLE_EQ(s.frame_time(5), 0.5);
    EXPECT_EQ(s.interpolation, CameraInterpolation::ConstantSpeed);
    EXPECT_EQ(s.scene_path, "");
    s = seq(std::string("scene: ../scenes/x.yaml\nfps: 1\nimage: {width: 64, samples: 2}\n") + kOrbitKeys,
            &scene);
    EXPECT_EQ(
        parse_sequence(std::string("scene: ../scenes/x.yaml\nfps: 1\n") + kOrbitKeys, "cams/s.yaml", &scene)
            .scene_path,
        "scenes/x.yaml");
    EXPECT_EQ(s.width, 64);
    EXPECT_FALSE(s.height.has_value());
    EXPECT_EQ(s.samples, 2);
}

TEST(Sequence, ConstantSpeedOrbitAndSplineThroughKeys) {
    const Scene scene = load_scene(kSeed);
    const Sequence s = seq(std::string("fps: 10\n") + kOrbitKeys, &scene);
    // Halfway in time is halfway in angle, on the circle of radius 6.
    const CameraDesc mid = s.camera_at(0.5);
    EXPECT_NEAR(mid.eye.x, 6 * std::cos(kPi / 4), 1e-12);
    EXPECT_NEAR(mid.eye.y, 6 * std::sin(kPi / 4), 1e-12);
    EXPECT_NEAR(mid.eye.z, 0.0, 1e-12);
    // Before the first key and after the last the camera rests there.
    EXPECT_NEAR(s.camera_at(-1).eye.x, 6.0, 1e-12);
    EXPECT_NEAR(s.camera_at(5).eye.y, 6.0, 1e-12);

    // A spline through three keys passes through each one, and differs from the polyline between.
    const Sequence sp = seq(R"(fps: 10
camera:
  keys:
    - {time_s: 0, position: [5, 0, 0]}
    - {time_s: 1, position: [0, 5, 0]}
    - {time_s: 3, position: [-5, 0, 1]}
)",
                            &scene);
    EXPECT_NEAR(glm::length(sp.camera_at(1.0).eye - Vec3(0, 5, 0)), 0.0, 1e-12);
    EXPECT_NEAR(glm::length(sp.camera_at(3.0).eye - Vec3(-5, 0, 1)), 0.0, 1e-12);
    const Vec3 half = sp.camera_at(2.0).eye;
    EXPECT_GT(glm::length(half - Vec3(-2.5, 2.5, 0.5)), 0.1);
    // Catmull-Rom tangent at the middle key: (p2 - p0) / (t2 - t0), so the motion is smooth there.
    const double h = 1e-6;
    const Vec3 v_before = (sp.camera_at(1.0).eye - sp.camera_at(1.0 - h).eye) / h;
    const Vec3 v_after = (sp.camera_at(1.0 + h).eye - sp.camera_at(1.0).eye) / h;
    EXPECT_NEAR(glm::length(v_before - v_after), 0.0, 1e-3);
    EXPECT_NEAR(v_after.x, -10.0 / 3.0, 1e-3);
}

TEST(Sequence, HoldsAndCuts) {
    const Scene scene = load_scene(kSeed);
    const Sequence s = seq(R"(fps: 4
camera:
  keys:
    - {time_s: 0, position: [5, 0, 0], hold_s: 1}
    - {time_s: 2, position: [0, 5, 0]}
    - {time_s: 3, position: [0, 0, 5], up: [1, 0, 0], cut: true}
)",
                           &scene);
    EXPECT_EQ(s.camera_at(0.0).eye, Vec3(5, 0, 0));
    EXPECT_EQ(s.camera_at(0.75).eye, Vec3(5, 0, 0));  // holding
    EXPECT_NE(s.camera_at(1.5).eye, Vec3(5, 0, 0));   // moving
    EXPECT_EQ(s.camera_at(2.9).eye, Vec3(0, 5, 0));   // waits for the cut
    EXPECT_EQ(s.camera_at(3.0).eye, Vec3(0, 0, 5));   // and jumps
}

TEST(Sequence, EventsSetAndRamp) {
    const Scene scene = load_scene(kSeed);
    const SceneGeometry g(scene);
    const Materials base = patch_materials(scene);
    const Sequence s = seq(std::string("fps: 10\n") + kOrbitKeys + R"(events:
  - {time_s: [1, 3], surface: face3, emission: [0, 0, 0]}
  - {time_s: [1, 3], surface: face6, patch: [1, 1], emission: [7, 7, 7]}
  - {time_s: 2, surface: sphere, reflectance: [1, 0.5, 0.25]}
)",
                           &scene);
    const int f3 = g.patch_index(2, 1, 1), f6 = g.patch_index(5, 1, 1), f6b = g.patch_index(5, 0, 0);
    const int sph = g.patch_index(6, 0, 0);
    Materials m = s.materials_at(base, g, 0.5);
    EXPECT_EQ(m.E[f3], Rgb(1.27));
    EXPECT_EQ(m.E[f6], Rgb(0.0));
    m = s.materials_at(base, g, 2.0);
    EXPECT_NEAR(m.E[f3].r, 0.635, 1e-15);
    EXPECT_NEAR(m.E[f6].g, 3.5, 1e-15);
    EXPECT_EQ(m.E[f6b], Rgb(0.0));
    EXPECT_EQ(m.rho[sph], Rgb(1, 0.5, 0.25));
    EXPECT_EQ(s.materials_at(base, g, 1.99).rho[sph], Rgb(0.5, 0.5, 1.0));
    m = s.materials_at(base, g, 3.0);
    EXPECT_EQ(m.E[f3], Rgb(0.0));
    EXPECT_EQ(m.E[f6], Rgb(7.0));
}

TEST(Sequence, BadFilesNameTheLineAndTheFix) {
    const Scene scene = load_scene(kSeed);
    EXPECT_EQ(error_of(kOrbitKeys, &scene), "s.yaml:1:1: sequence file is missing the required key 'fps'");
    EXPECT_EQ(error_of(std::string("fps: 0\n") + kOrbitKeys, &scene),
              "s.yaml:1:6: fps must be in (0, 240], got 0");
    EXPECT_EQ(error_of(std::string("fps: 300\n") + kOrbitKeys, &scene),
              "s.yaml:1:6: fps must be in (0, 240], got 300");
    const std::string head = std::string("fps: 10\n") + kOrbitKeys + "events:\n";
    EXPECT_EQ(error_of(head + "  - {time_s: 1, surface: face9, emission: [1, 1, 1]}\n", &scene),
              "s.yaml:14:26: event 1: no surface named 'face9' in " + kSeed +
                  " (it has face1, face2, face3, face4, face5, face6, sphere)");
    EXPECT_EQ(
        error_of(head + "  - {time_s: 1, surface: face6, patch: [3, 0], emission: [1, 1, 1]}\n", &scene),
        "s.yaml:14:40: event 1: surface 'face6' has patches [0..2, 0..2], not [3, 0]");
    EXPECT_EQ(error_of(head + "  - {time_s: [2, 1], surface: face6, emission: [1, 1, 1]}\n", &scene),
              "s.yaml:14:18: event 1: a ramp must end after it starts, got [2, 1]");
    EXPECT_EQ(error_of(head + "  - {time_s: 1, surface: face6, reflectance: [1, 1.5, 1]}\n", &scene),
              "s.yaml:14:50: reflectance must be in [0, 1], got 1.5");
    EXPECT_EQ(
        error_of(head + "  - {time_s: 1, surface: face6, emission: [1, 1, 1], reflectance: [1, 1, 1]}\n",
                 &scene),
        "s.yaml:14:5: event 1: give exactly one of emission, reflectance or a motion (translate and/or "
        "rotate_deg)");
    EXPECT_EQ(error_of(head + "  - {time_s: 1, surface: face6, emision: [1, 1, 1]}\n", &scene),
              "s.yaml:14:5: event 1: give exactly one of emission, reflectance or a motion (translate and/or "
              "rotate_deg)");
    EXPECT_EQ(error_of("fps: 10\ncamera:\n  keys:\n    - {time_s: 1, position: [5, 0, 0]}\n"
                       "    - {time_s: 1, position: [6, 0, 0]}\n",
                       &scene),
              "s.yaml:5:16: camera key 2: time_s 1 must be later than the previous key's time (and hold)");
    EXPECT_EQ(error_of("fps: 10\nduration_s: 100000\n" + std::string(kOrbitKeys), &scene),
              "s.yaml:1:1: the sequence has 1000000 frames; the limit is 100000 (lower fps or duration_s)");
    // Found by the fuzzer: a key time of 5.6e63 s (the frame count overflowed the integer it was
    // printed as, undefined behaviour).
    EXPECT_EQ(error_of("fps: 1\ncamera:\n  keys:\n    - {time_s: "
                       "5555555555555555555555555555555555555555555555555555555555555555, "
                       "position: [5, 0, 0]}\n",
                       &scene),
              "s.yaml:1:1: the sequence has 5.56e+63 frames; the limit is 100000 (lower fps or duration_s)");
    EXPECT_EQ(error_of("fps: 10\ncamera:\n  keys: []\n", &scene),
              "s.yaml:3:9: camera keys must be a non-empty list of {time_s, distance, theta_deg, phi_deg | "
              "position, ...}");
    // A sequence where a camera file is expected, and the other way round.
    try {
        parse_camera(std::string("fps: 10\n") + kOrbitKeys, "c.yaml");
        ADD_FAILURE();
    } catch (const Error& e) {
        EXPECT_STREQ(
            e.what(),
            "c.yaml:1:1: this is a sequence file (it has fps); pass it with --sequence, not --camera");
    }
}

// ---- the scheduler ----

namespace {
struct Planned {
    Scene scene;
    std::unique_ptr<SceneGeometry> geo;
    Plan plan;
};
Planned plan_of(const std::string& body, bool iterative = false, bool combine = false) {
    Planned p{load_scene(kSeed), nullptr, {}};
    p.geo = std::make_unique<SceneGeometry>(p.scene);
    const Sequence s = parse_sequence(body, "s.yaml", &p.scene);
    p.plan = plan_sequence(s, patch_materials(p.scene), *p.geo, iterative, combine);
    return p;
}
std::string actions(const Plan& plan) {
    std::string s;
    for (const auto& f : plan.frames)
        s += std::string(1, solve_action_name(f.solve)[0]) + render_action_name(f.render)[0] + " ";
    return s;
}
}  // namespace

TEST(Sequence, MotionEventsSetAndRampDisplacementsFromTheScenePlace) {
    const Scene scene = load_scene(kSeed);
    const SceneGeometry g(scene);
    const int n = g.surface_count(), sphere = scene.find_surface("sphere");
    const Sequence s = seq(std::string("fps: 10\n") + kOrbitKeys + R"(events:
  - time_s: [0, 2]
    surface: sphere
    translate: [0, 1, 0]
    rotate_deg: {axis: [1, 0, 0], angle: 90, about: [0, 0, 0]}
  - {time_s: 3, surface: sphere, translate: [0, 0, 0]}
)",
                           &scene);
    EXPECT_TRUE(s.has_motion());
    EXPECT_TRUE(s.motion_at(n, 0.0)[static_cast<std::size_t>(sphere)].identity());
    const Similarity half = s.motion_at(n, 1.0)[static_cast<std::size_t>(sphere)];
    // Half way: 45 degrees about x through the origin, then half the translation.
    const Vec3 p = half.apply(Vec3(0, 0, 1));
    EXPECT_NEAR(p.x, 0.0, 1e-15);
    EXPECT_NEAR(p.y, 0.5 - std::sqrt(0.5), 1e-15);
    EXPECT_NEAR(p.z, std::sqrt(0.5), 1e-15);
    for (int k = 0; k < n; ++k) {
        if (k == sphere) continue;
        EXPECT_TRUE(s.motion_at(n, 1.0)[static_cast<std::size_t>(k)].identity()) << k;
    }
    // At 3 s the translation is set back; the rotation stays (the event leaves it as it is).
    const Vec3 q = s.motion_at(n, 3.0)[static_cast<std::size_t>(sphere)].apply(Vec3(0, 0, 1));
    EXPECT_NEAR(q.y, -1.0, 1e-15);
    EXPECT_NEAR(q.z, 0.0, 1e-15);
    // Frames group by geometry state: 0.0 s is the scene's own placement, each ramp frame a new
    // state, and every frame from 2 s on shares one.
    const Plan plan = plan_sequence(s, patch_materials(scene), g);
    EXPECT_TRUE(Plan::is_identity(plan.geometries[0]));
    EXPECT_EQ(plan.frames[20].geometry, plan.frames[25].geometry);
    EXPECT_NE(plan.frames[5].geometry, plan.frames[6].geometry);
    EXPECT_EQ(plan.frames[5].solve, SolveAction::Factorised);  // a new geometry is a new system
    EXPECT_TRUE(plan.moves());
}

TEST(Sequence, BadMotionsNameTheLineAndTheFix) {
    const Scene scene = load_scene(kSeed);
    const std::string head = std::string("fps: 10\n") + kOrbitKeys + "events:\n";
    EXPECT_EQ(
        error_of(head + "  - {time_s: 1, surface: sphere, patch: [0, 0], translate: [1, 0, 0]}\n", &scene),
        "s.yaml:14:34: event 1: a motion moves a whole surface; drop patch");
    EXPECT_EQ(error_of(head + "  - {time_s: 1, surface: sphere, translate: [1, 0, 0], emission: [1, 1, 1]}\n",
                       &scene),
              "s.yaml:14:5: event 1: give exactly one of emission, reflectance or a motion (translate and/or "
              "rotate_deg)");
    EXPECT_EQ(error_of(head + "  - {time_s: 1, surface: sphere, rotate_deg: {axis: [0, 0, 0], angle: 5}}\n",
                       &scene),
              "s.yaml:14:53: event 1: rotate_deg axis must be a non-zero vector [x, y, z]");
    EXPECT_EQ(
        error_of(
            head +
                "  - {time_s: 1, surface: sphere, rotate_deg: {axis: [0, 0, 1], angle: 5, at: [0, 0, 0]}}\n",
            &scene),
        "s.yaml:14:74: unknown key 'at' in event 1: rotate_deg (allowed: axis, angle, about)");
    EXPECT_EQ(error_of(head + "  - {time_s: 1, surface: sphere, translate: [1, .nan, 0]}\n", &scene),
              "s.yaml:14:49: translate[1] must be a finite number, got '.nan'");
    EXPECT_EQ(
        error_of(head + "  - {time_s: 1, surface: sphere, rotate_deg: {axis: [0, 0, 1], angle: 5}}\n" +
                     "  - {time_s: 2, surface: sphere, rotate_deg: {axis: [0, 1, 0], angle: 9}}\n",
                 &scene),
        "s.yaml:15:5: 'sphere' already rotates about another axis or centre (event at s.yaml:14:5); give "
        "every rotation of one surface the same axis and about");
}

TEST(Scheduler, CameraOnlySequenceSolvesOnceAndRendersEveryFrame) {
    const Planned p = plan_of(std::string("fps: 4\n") + kOrbitKeys);
    EXPECT_EQ(p.plan.frames.size(), 5u);
    EXPECT_EQ(p.plan.factorisations(), 1);
    EXPECT_EQ(p.plan.substitutions(), 1);
    EXPECT_EQ(p.plan.renders(), 5);
    EXPECT_EQ(actions(p.plan), "fr rr rr rr rr ");
}

// A camera that only zooms or only rolls still moves the picture: every frame renders.
TEST(Scheduler, ZoomOnlyAndRollOnlyStretchesRender) {
    const Planned zoom = plan_of(R"(fps: 2
camera:
  keys:
    - {time_s: 0, position: [6, 0, 0], fov_deg: 50}
    - {time_s: 1, position: [6, 0, 0], fov_deg: 30}
)");
    EXPECT_EQ(actions(zoom.plan), "fr rr rr ");
    const Planned roll = plan_of(R"(fps: 2
camera:
  keys:
    - {time_s: 0, position: [6, 0, 0], up: [0, 0, 1]}
    - {time_s: 1, position: [6, 0, 0], up: [0, 1, 1]}
)");
    EXPECT_EQ(actions(roll.plan), "fr rr rr ");
    const Planned still = plan_of(R"(fps: 2
camera:
  keys:
    - {time_s: 0, position: [6, 0, 0], fov_deg: 50}
    - {time_s: 1, position: [6, 0, 0], fov_deg: 50}
)");
    EXPECT_EQ(actions(still.plan), "fr rc rc ");
}

// The seed room's light (face3) dims while a patch of face6 brightens, from 0.25 s to 1 s.
const char* const kLightRamps = R"(fps: 4
duration_s: 2
camera:
  keys:
    - {time_s: 0, distance: 6, theta_deg: 0, phi_deg: 90}
events:
  - {time_s: [0.25, 1], surface: face3, emission: [0, 0, 0]}
  - {time_s: [0.25, 1], surface: face6, patch: [1, 1], emission: [7, 7, 7]}
)";

TEST(Scheduler, LightOnlySequenceFactorisesOnceAndSubstitutes) {
    const Planned p = plan_of(kLightRamps);
    // Frames at 0, .25 (ramp start, unchanged), .5, .75, 1 (end), then the light rests.
    EXPECT_EQ(p.plan.factorisations(), 1);
    EXPECT_EQ(p.plan.substitutions(), 4);
    EXPECT_EQ(actions(p.plan), "fr rc sr sr sr rc rc rc ");
}

// Over links, a light's emission that is a combination of emissions already iterated for the
// same reflectance is `combined`: the same ramps as above, then a colour change. Frame 2 (t =
// 0.5) adds a direction, and each later ramp frame is a combination of frames 0 and 2 whose
// weights give its emission to rounding, channel by channel. Frame 2's emission is solved
// ahead, by frame 0's sweeps (`ahead`). A colour change starts a new set: its first emission
// is solved at its own frame.
TEST(Scheduler, SolvesOverLinksCombineEmissionsAlreadySolved) {
    const std::string body =
        std::string(kLightRamps) + "  - {time_s: 1.5, surface: sphere, reflectance: [1, 0.5, 0.25]}\n";
    const Planned p = plan_of(body, true, true);
    EXPECT_EQ(actions(p.plan), "ir rc ar cr cr rc ir rc ");
    ASSERT_EQ(p.plan.combinations.size(), p.plan.solutions.size());
    const int second = p.plan.frames[2].solution, colour = p.plan.frames[6].solution;
    EXPECT_EQ(p.plan.solved_with[static_cast<std::size_t>(second)], 0);
    EXPECT_EQ(p.plan.solved_together[0], (std::vector<int>{0, second}));
    EXPECT_EQ(p.plan.solved_with[static_cast<std::size_t>(colour)], colour);
    EXPECT_EQ(p.plan.solved_together[static_cast<std::size_t>(colour)], std::vector<int>{colour});
    int combined = 0;
    for (std::size_t k = 0; k < p.plan.solutions.size(); ++k) {
        const auto& terms = p.plan.combinations[k];
        if (terms.empty()) continue;
        ++combined;
        const std::vector<Rgb>& E = p.plan.solutions[k].E;
        ASSERT_EQ(terms.size(), 2u) << k;
        for (const Combination& t : terms) {
            EXPECT_LT(t.solution, static_cast<int>(k));
            EXPECT_EQ(p.plan.solution_set[static_cast<std::size_t>(t.solution)], p.plan.solution_set[k]);
            EXPECT_TRUE(p.plan.combinations[static_cast<std::size_t>(t.solution)].empty());
        }
        double worst = 0.0, top = 0.0;
        for (std::size_t i = 0; i < E.size(); ++i) {
            Rgb sum(0.0);
            for (const Combination& t : terms)
                sum += t.weight * p.plan.solutions[static_cast<std::size_t>(t.solution)].E[i];
            for (int c = 0; c < 3; ++c) {
                worst = std::max(worst, std::abs(sum[c] - E[i][c]));
                top = std::max(top, std::abs(E[i][c]));
            }
        }
        EXPECT_LE(worst, 1e-13 * top) << k;
    }
    EXPECT_EQ(combined, 2);
    // A direct solver never combines (its substitution is already cheap), nor a dense
    // iterative one (its residual target holds frame by frame).
    EXPECT_EQ(actions(plan_of(body).plan), "fr rc sr sr sr rc fr rc ");
    EXPECT_EQ(actions(plan_of(body, true).plan), "ir rc ir ir ir rc ir rc ");
}

TEST(Scheduler, NineNewLightsAreSolvedByTwoRunsOfSweeps) {
    // Each second a patch of face6 lights up, the one before it dark again: no frame's emission
    // is a combination of earlier ones, so each must be iterated: frames 0 to 7 by frame 0's
    // sweeps (kMaxSolvedAhead), frames 8 and 9 by frame 8's.
    std::string body =
        "fps: 1\nduration_s: 10\ncamera:\n  keys:\n    - {time_s: 0, distance: 6, theta_deg: 0, "
        "phi_deg: 90}\nevents:\n";
    for (int k = 0; k < 9; ++k)
        body += "  - {time_s: " + std::to_string(k + 1) + ", surface: face6, patch: [" +
                std::to_string(k % 3) + ", " + std::to_string(k / 3) + "], emission: [" +
                std::to_string(k + 1) + ", 1, 1]}\n";
    for (int k = 0; k < 8; ++k)
        body += "  - {time_s: " + std::to_string(k + 2) + ", surface: face6, patch: [" +
                std::to_string(k % 3) + ", " + std::to_string(k / 3) + "], emission: [0, 0, 0]}\n";
    const Planned p = plan_of(body, true, true);
    EXPECT_EQ(actions(p.plan), "ir ar ar ar ar ar ar ar ir ar ");
    EXPECT_EQ(p.plan.solved_together[0], (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
    EXPECT_EQ(p.plan.solved_together[8], (std::vector<int>{8, 9}));
    EXPECT_EQ(p.plan.solved_with[9], 8);
}

TEST(Scheduler, EmissionsSolvedAheadHoldAtMost256MiBMore) {
    EXPECT_EQ(solved_ahead_limit(86), kMaxSolvedAhead);
    EXPECT_EQ(solved_ahead_limit(20198), kMaxSolvedAhead);
    EXPECT_EQ(solved_ahead_limit(74898), 8);  // 7 more x 512 bytes x 74,898 patches < 256 MiB
    EXPECT_EQ(solved_ahead_limit(74899), 7);
    EXPECT_EQ(solved_ahead_limit(101070), 6);
    EXPECT_EQ(solved_ahead_limit(524288), 2);
    EXPECT_EQ(solved_ahead_limit(524289), 1);  // none ahead
    EXPECT_EQ(solved_ahead_limit(1000000), 1);
}

TEST(Scheduler, ColourChangeRefactorises) {
    const Planned p = plan_of(R"(fps: 1
duration_s: 4
camera:
  keys:
    - {time_s: 0, distance: 6, theta_deg: 0, phi_deg: 90}
events:
  - {time_s: 1, surface: sphere, reflectance: [1, 0.5, 0.25]}
  - {time_s: 2, surface: face3, emission: [2, 2, 2]}
  - {time_s: 3, surface: sphere, reflectance: [0.5, 0.5, 1]}
)");
    EXPECT_EQ(p.plan.factorisations(), 2);  // back to the first colours reuses the first factorisation
    EXPECT_EQ(actions(p.plan), "fr fr sr sr ");
    EXPECT_EQ(p.plan.frames[3].reflectance_set, 0);
}

TEST(Scheduler, PaperSequenceABC) {
    const std::string path = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-abc.yaml";
    Planned p{load_scene(sequence_scene_path(path)), nullptr, {}};
    p.geo = std::make_unique<SceneGeometry>(p.scene);
    const Sequence s = load_sequence(path, &p.scene);
    const Plan plan = plan_sequence(s, patch_materials(p.scene), *p.geo);
    EXPECT_EQ(actions(plan), "fr rr sr ");  // A: solve + render; B: render only; C: solve + render
    EXPECT_NEAR(plan.frames[1].camera.eye.x, -6.0, 1e-12);
    EXPECT_NEAR(plan.frames[2].camera.eye.x, 6.0, 1e-12);
}

// The shipped relightings of the 20,000-patch room plan as their headers say: over links, one
// iterated frame (the first), whose sweeps solve face 6's first lit frame ahead, every other
// frame combined; and with a new light each second, every later frame solved ahead.
TEST(Scheduler, ShippedRelightingOfThe20kRoomCombines) {
    const std::string path = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-20k-relight.yaml";
    Planned p{load_scene(sequence_scene_path(path)), nullptr, {}};
    EXPECT_EQ(p.scene.patch_count(), 20198);
    p.geo = std::make_unique<SceneGeometry>(p.scene);
    const Sequence s = load_sequence(path, &p.scene);
    const Plan plan = plan_sequence(s, patch_materials(p.scene), *p.geo, true, true);
    EXPECT_EQ(actions(plan), "ir cr cr cr cr ar cr cr ");
    // A new light each second: frame 0's sweeps solve all five emissions.
    const std::string lights = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-20k-new-lights.yaml";
    const Plan more =
        plan_sequence(load_sequence(lights, &p.scene), patch_materials(p.scene), *p.geo, true, true);
    EXPECT_EQ(actions(more), "ir ar ar ar ar ");
    EXPECT_EQ(more.solved_together[0], (std::vector<int>{0, 1, 2, 3, 4}));
}

}  // namespace radiosa

namespace radiosa {

TEST(Sequence, AnEventOnAnEntryOfSeveralSurfacesChangesEachFrontPart) {
    // The teapot entry makes 32 surfaces and their backs: "teapot" names the 32 fronts.
    const Scene scene = parse_scene(
        "closed: false\nsurfaces:\n  - {name: teapot, type: bezier, file: teapot.bpt, patches: 1, "
        "reflectance: [0.5, 0.5, 0.5], two_sided: true}\n",
        RADIOSA_SOURCE_DIR "/scenes/inline.yaml");
    ASSERT_EQ(scene.surfaces.size(), 64u);
    const SceneGeometry g(scene);
    const Sequence s =
        parse_sequence(std::string("fps: 10\n") + kOrbitKeys +
                           "events:\n  - {time_s: 0, surface: teapot, reflectance: [1, 0, 0]}\n",
                       "s.yaml", &scene);
    ASSERT_EQ(s.events.size(), 32u);
    const Materials m = s.materials_at(patch_materials(scene), g, 0.5);
    for (int k = 0; k < 64; ++k)
        EXPECT_EQ(m.rho[g.patch_index(k, 0, 0)], k % 2 == 0 ? Rgb(1, 0, 0) : Rgb(0.5))
            << scene.surfaces[k].name;
    // A part by its own name is one event; an unknown name is still refused.
    EXPECT_EQ(parse_sequence(std::string("fps: 10\n") + kOrbitKeys +
                                 "events:\n  - {time_s: 0, surface: teapot.7.back, reflectance: [1, 0, 0]}\n",
                             "s.yaml", &scene)
                  .events.size(),
              1u);
    EXPECT_THROW(parse_sequence(std::string("fps: 10\n") + kOrbitKeys +
                                    "events:\n  - {time_s: 0, surface: teapo, reflectance: [1, 0, 0]}\n",
                                "s.yaml", &scene),
                 Error);
}

}  // namespace radiosa
