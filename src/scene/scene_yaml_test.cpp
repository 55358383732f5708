#include <gtest/gtest.h>

#include "formfactor/form_factor.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "surfaces/quad.h"
#include "surfaces/registry.h"

namespace radiosa {

namespace {

const char* kGood = R"(name: box
form_factors:
  gauss_points: 5
surfaces:
  - name: floor
    type: quad
    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    patches: [2, 3]
    reflectance: [0.5, 0.25, 1]
    emission: [1, 2, 3]
    patch_emission:
      - patch: [1, 2]
        emission: [7, 7, 7]
  - name: ball
    type: sphere
    center: [0, 0, 5]
    radius: 2
    facing: inward
    patches: [8, 4]
    reflectance: [0.5, 0.5, 1.0]
  - name: wall
    type: quad
    origin: [0, 0, 0]
    edge_s: [0, 0, 1]
    edge_t: [1, 0, 0]
    patches: [1, 1]
    reflectance: [0, 0, 0]
)";

// Parses `text` and returns the error message, or "" when it parses.
std::string parse_error(const std::string& text) {
    try {
        parse_scene(text, "s.yaml");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

std::string with_surface(const std::string& body) { return "surfaces:\n  - name: a\n" + body; }

const std::string kQuadBody =
    "    type: quad\n"
    "    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\n"
    "    patches: [1, 1]\n";

}  // namespace

TEST(SceneYaml, ReadsEveryField) {
    const Scene s = parse_scene(kGood, "good.yaml");
    EXPECT_EQ(s.name, "box");
    EXPECT_TRUE(s.closed);
    EXPECT_EQ(s.form_factors.gauss_points, 5);
    ASSERT_EQ(s.surfaces.size(), 3u);
    const SurfaceDesc& f = s.surfaces[0];
    EXPECT_EQ(f.type->name, "quad");
    EXPECT_EQ(f.ns, 2);
    EXPECT_EQ(f.nt, 3);
    EXPECT_EQ(f.reflectance, Rgb(0.5, 0.25, 1.0));
    EXPECT_EQ(f.emission, Rgb(1, 2, 3));
    ASSERT_EQ(f.patch_emission.size(), 1u);
    EXPECT_EQ(f.patch_emission[0].is, 1);
    EXPECT_EQ(f.patch_emission[0].it, 2);
    EXPECT_EQ(f.loc.line, 5);
    const SurfaceDesc& b = s.surfaces[1];
    EXPECT_EQ(b.type->name, "sphere");
    EXPECT_TRUE(b.shape->sees_itself());  // inward
    EXPECT_EQ(b.shape->sphere()->radius, 2.0);
    EXPECT_EQ(b.shape->sphere()->center, Vec3(0, 0, 5));
    const auto& w = dynamic_cast<const QuadSurface&>(*s.surfaces[2].shape);
    EXPECT_EQ(w.corners()[2], Vec3(1, 0, 1));  // origin + edge_s + edge_t
    EXPECT_EQ(s.patch_count(), 6 + 32 + 1);
}

// patch_emission [i, j] is patch i along s and j along t: in patch order (s fastest) index
// j * ns + i of its surface, after the patches of the surfaces before it.
TEST(SceneYaml, PatchEmissionLandsOnItsPatch) {
    const Scene s = parse_scene(
        "surfaces:\n"
        "  - {name: a, type: quad, corners: [[0,0,0],[1,0,0],[1,1,0],[0,1,0]], patches: [2, 2], reflectance: "
        "[0,0,0]}\n"
        "  - {name: b, type: quad, corners: [[0,0,1],[0,1,1],[1,1,1],[1,0,1]], patches: [3, 2], reflectance: "
        "[0,0,0],\n"
        "     emission: [1, 1, 1], patch_emission: [{patch: [2, 0], emission: [5, 5, 5]}]}\n",
        "p.yaml");
    const Materials m = patch_materials(s);
    ASSERT_EQ(m.E.size(), 10u);
    for (std::size_t i = 0; i < m.E.size(); ++i)
        EXPECT_EQ(m.E[i], i < 4 ? Rgb(0.0) : i == 4 + 2 ? Rgb(5.0) : Rgb(1.0)) << "patch " << i;
}

TEST(SceneYaml, DefaultsWhenOptionalKeysAreAbsent) {
    const Scene s = parse_scene(with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n"), "d.yaml");
    EXPECT_EQ(s.name, "d");
    EXPECT_FALSE(s.form_factors.gauss_points);  // not given: error control at the default tolerance
    EXPECT_FALSE(s.form_factors.tolerance);
    EXPECT_TRUE(s.form_factors.visibility);
    const FormFactorOptions o =
        resolve_form_factor_options(s.form_factors, std::nullopt, std::nullopt, std::nullopt, std::nullopt);
    EXPECT_EQ(o.method, FormFactorMethod::Adaptive);
    EXPECT_EQ(o.tolerance, kDefaultFormFactorTolerance);
    EXPECT_EQ(resolve_form_factor_options(s.form_factors, std::nullopt, std::nullopt, 6, std::nullopt).method,
              FormFactorMethod::Fixed);
    const FormFactorOptions t =
        resolve_form_factor_options(s.form_factors, std::nullopt, 1e-3, std::nullopt, false);
    EXPECT_EQ(t.method, FormFactorMethod::Adaptive);
    EXPECT_EQ(t.tolerance, 1e-3);
    EXPECT_FALSE(t.visibility);
    EXPECT_EQ(s.surfaces[0].emission, Rgb(0.0));
}

// method: hierarchical makes tolerance the links' tolerance; the command line's method or
// tolerance overrides the scene's, and a tolerance for one method is not carried to another.
TEST(SceneYaml, HierarchicalMethodAndItsTolerance) {
    const std::string head = "form_factors: {method: hierarchical, tolerance: 1e-4}\n";
    const Scene s = parse_scene(head + with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n"), "h.yaml");
    EXPECT_TRUE(s.form_factors.hierarchical);
    const auto resolve = [&](std::optional<std::string> m, std::optional<double> t) {
        return resolve_form_factor_options(s.form_factors, std::move(m), t, std::nullopt, std::nullopt);
    };
    const FormFactorOptions o = resolve(std::nullopt, std::nullopt);
    EXPECT_EQ(o.method, FormFactorMethod::Hierarchical);
    EXPECT_EQ(o.link_tolerance, 1e-4);
    EXPECT_EQ(o.tolerance, 1e-5);  // pairs of patches: a tenth of the links'
    EXPECT_EQ(resolve(std::nullopt, 1e-3).link_tolerance, 1e-3);
    const FormFactorOptions a = resolve("adaptive", std::nullopt);
    EXPECT_EQ(a.method, FormFactorMethod::Adaptive);
    EXPECT_EQ(a.tolerance, kDefaultFormFactorTolerance);
    const Scene d = parse_scene(with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n"), "d.yaml");
    EXPECT_EQ(
        resolve_form_factor_options(d.form_factors, "hierarchical", std::nullopt, std::nullopt, std::nullopt)
            .link_tolerance,
        kDefaultLinkTolerance);
    EXPECT_EQ(parse_error("form_factors: {method: radiant}\n" +
                          with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n")),
              "s.yaml:1:24: method must be adaptive, gauss or hierarchical, got 'radiant'");
    EXPECT_EQ(parse_error("form_factors: {method: hierarchical, gauss_points: 4}\n" +
                          with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n")),
              "s.yaml:1:52: gauss_points belongs to method: gauss, not hierarchical");
}

TEST(SceneYaml, ReceiverToleranceBelongsToTheHierarchicalMethod) {
    const std::string body = with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n");
    const Scene s =
        parse_scene("form_factors: {method: hierarchical, receiver_tolerance: 3e-6}\n" + body, "s.yaml");
    const auto resolve = [&](std::optional<std::string> method) {
        return resolve_form_factor_options(s.form_factors, method, std::nullopt, std::nullopt, std::nullopt);
    };
    EXPECT_EQ(resolve(std::nullopt).receiver_tolerance, 3e-6);
    EXPECT_EQ(resolve(std::nullopt).link_tolerance, kDefaultLinkTolerance);
    EXPECT_EQ(resolve("adaptive").receiver_tolerance, 0.0);  // the dense path has no receivers
    EXPECT_EQ(parse_error("form_factors: {receiver_tolerance: 1e-6}\n" + body),
              "s.yaml:1:36: receiver_tolerance belongs to method: hierarchical; add method: hierarchical or "
              "remove it");
    EXPECT_EQ(parse_error(
                  "form_factors: {method: hierarchical, tolerance: 1e-5, receiver_tolerance: 2e-5}\n" + body),
              "s.yaml:1:75: receiver_tolerance must not exceed tolerance (1e-5), got 2e-5");
    EXPECT_EQ(parse_error("form_factors: {method: hierarchical, receiver_tolerance: -1}\n" + body),
              "s.yaml:1:58: receiver_tolerance must be 0 (off) or in [1e-12, 0.1], got -1");
    // None given: link tolerance / 8 up to 10,000 patches, off above; 0: off.
    const Scene plain = parse_scene("form_factors: {method: hierarchical}\n" + body, "s.yaml");
    const auto automatic = [&](int patches) {
        return resolve_form_factor_options(plain.form_factors, std::nullopt, std::nullopt, std::nullopt,
                                           std::nullopt, std::nullopt, patches)
            .receiver_tolerance;
    };
    EXPECT_EQ(automatic(kAutoReceiverMaxPatches), kDefaultLinkTolerance / 8);
    EXPECT_EQ(automatic(kAutoReceiverMaxPatches + 1), 0.0);
    const Scene off =
        parse_scene("form_factors: {method: hierarchical, receiver_tolerance: 0}\n" + body, "s.yaml");
    EXPECT_EQ(resolve_form_factor_options(off.form_factors, std::nullopt, std::nullopt, std::nullopt,
                                          std::nullopt, std::nullopt, 86)
                  .receiver_tolerance,
              0.0);
    EXPECT_EQ(resolve_form_factor_options(plain.form_factors, std::nullopt, std::nullopt, std::nullopt,
                                          std::nullopt, 0.0, 86)
                  .receiver_tolerance,
              0.0);  // --ff-receiver-tolerance 0
}

TEST(SceneYaml, NumericInnerBelongsToTheAdaptiveMethod) {
    const std::string body = with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n");
    EXPECT_TRUE(
        parse_scene("form_factors: {numeric_inner: lines}\n" + body, "s.yaml").form_factors.numeric_lines);
    EXPECT_FALSE(parse_scene("form_factors: {method: adaptive, numeric_inner: rules}\n" + body, "s.yaml")
                     .form_factors.numeric_lines);
    EXPECT_FALSE(parse_scene(body, "s.yaml").form_factors.numeric_lines);  // rules by default
    EXPECT_EQ(parse_error("form_factors: {numeric_inner: strips}\n" + body),
              "s.yaml:1:31: numeric_inner must be rules or lines, got 'strips'");
    EXPECT_EQ(parse_error("form_factors: {method: hierarchical, numeric_inner: lines}\n" + body),
              "s.yaml:1:53: numeric_inner belongs to method: adaptive, not hierarchical");
    EXPECT_EQ(parse_error("form_factors: {gauss_points: 4, numeric_inner: lines}\n" + body),
              "s.yaml:1:48: numeric_inner belongs to method: adaptive, not to gauss_points");
}

TEST(SceneYaml, UnknownKeyNamesItsLine) {
    EXPECT_EQ(parse_error(with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n    colour: [1, 1, 1]\n")),
              "s.yaml:7:5: unknown key 'colour' in surface #1 (allowed: name, type, corners | origin + "
              "edge_s + edge_t, patches, reflectance, emission, patch_emission, transform, two_sided, "
              "back_reflectance, back_emission)");
}

TEST(SceneYaml, MissingFieldNamesTheSurface) {
    EXPECT_EQ(parse_error(with_surface(kQuadBody)),
              "s.yaml:2:5: surface #1 is missing the required key 'reflectance'");
    EXPECT_EQ(parse_error("name: x\n"), "s.yaml:1:1: scene is missing the required key 'surfaces'");
}

TEST(SceneYaml, WrongTypeIsReported) {
    EXPECT_EQ(parse_error(with_surface(kQuadBody + "    reflectance: 0.5\n")),
              "s.yaml:6:18: reflectance must be a list of 3 numbers [r, g, b]");
    EXPECT_EQ(parse_error(with_surface(kQuadBody + "    reflectance: [0.5, red, 0]\n")),
              "s.yaml:6:24: reflectance[1] must be a number, got 'red'");
    EXPECT_EQ(parse_error("surfaces: 3\n"), "s.yaml:1:11: surfaces must be a non-empty list of surfaces");
}

TEST(SceneYaml, NanAndInfinityAreRefused) {
    EXPECT_EQ(parse_error(with_surface(kQuadBody + "    reflectance: [.nan, 0, 0]\n")),
              "s.yaml:6:19: reflectance[0] must be a finite number, got '.nan'");
    EXPECT_EQ(
        parse_error(with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n    emission: [1e999, 0, 0]\n")),
        "s.yaml:7:16: emission[0] is out of the range of double: '1e999'");
}

TEST(SceneYaml, ReflectanceOutsideUnitIntervalIsRefused) {
    EXPECT_EQ(parse_error(with_surface(kQuadBody + "    reflectance: [0.5, 1.2, 0]\n")),
              "s.yaml:6:24: reflectance must be in [0, 1] (a surface cannot reflect more than it "
              "receives), got 1.2");
    EXPECT_NE(parse_error(with_surface(kQuadBody + "    reflectance: [-0.1, 0, 0]\n")), "");
}

TEST(SceneYaml, NegativeEmissionIsRefused) {
    EXPECT_EQ(parse_error(with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n    emission: [0, -1, 0]\n")),
              "s.yaml:7:19: emission must be >= 0, got -1");
}

TEST(SceneYaml, NegativeOrZeroRadiusIsRefused) {
    auto sphere = [](const char* radius) {
        return std::string("    type: sphere\n    center: [0, 0, 0]\n    radius: ") + radius +
               "\n    patches: [8, 4]\n    reflectance: [0, 0, 0]\n";
    };
    EXPECT_EQ(parse_error(with_surface(sphere("-1"))), "s.yaml:5:13: radius must be > 0, got -1");
    EXPECT_EQ(parse_error(with_surface(sphere("0"))), "s.yaml:5:13: radius must be > 0, got 0");
}

TEST(SceneYaml, DegenerateAndNonPlanarQuadsAreRefused) {
    const std::string collinear =
        "    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]\n    patches: [1, 1]\n"
        "    reflectance: [0, 0, 0]\n";
    EXPECT_EQ(parse_error(with_surface(collinear)),
              "s.yaml:2:5: quad 'a' is degenerate: its corners are collinear");
    const std::string bent =
        "    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0.5], [0, 1, 0]]\n    patches: [1, 1]\n"
        "    reflectance: [0, 0, 0]\n";
    EXPECT_EQ(parse_error(with_surface(bent)),
              "s.yaml:2:5: quad 'a' is not planar: corner 0 is off the plane of the others (split it "
              "into planar quads)");
    const std::string bowtie =
        "    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]\n    patches: [1, 1]\n"
        "    reflectance: [0, 0, 0]\n";
    EXPECT_NE(parse_error(with_surface(bowtie)).find("is degenerate or not convex"), std::string::npos);
}

TEST(SceneYaml, PatchCountsAreBounded) {
    std::string body = kQuadBody + "    reflectance: [0, 0, 0]\n";
    body.replace(body.find("[1, 1]"), 6, "[0, 3]");
    EXPECT_EQ(parse_error(with_surface(body)), "s.yaml:5:15: patch count must be between 1 and 4096, got 0");
    body.replace(body.find("[0, 3]"), 6, "[4000, 4000]");
    EXPECT_EQ(parse_error(with_surface(body)),
              "s.yaml:2:5: the scene has more than 1000000 patches (use fewer patches)");
}

TEST(SceneYaml, DuplicatesAreRefused) {
    EXPECT_EQ(
        parse_error(with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n    reflectance: [1, 1, 1]\n")),
        "s.yaml:7:5: key 'reflectance' appears twice in surface #1");
    const std::string two = with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n") + "  - name: a\n" +
                            kQuadBody + "    reflectance: [0, 0, 0]\n";
    EXPECT_EQ(parse_error(two), "s.yaml:7:5: surface name 'a' is used twice; names must be unique");
}

TEST(SceneYaml, PatchEmissionMustNameAnExistingPatch) {
    EXPECT_EQ(parse_error(with_surface(kQuadBody + "    reflectance: [0, 0, 0]\n    patch_emission:\n"
                                                   "      - patch: [1, 0]\n        emission: [1, 1, 1]\n")),
              "s.yaml:8:16: patch [1, 0] is outside surface 'a', which has patches [0..0, 0..0]");
}

TEST(SceneYaml, UnknownSurfaceType) {
    EXPECT_EQ(
        parse_error(
            "surfaces:\n  - name: t\n    type: klein\n    patches: [1, 1]\n    reflectance: [0, 0, 0]\n"),
        "s.yaml:3:11: unknown surface type 'klein' (known: quad, sphere, disk, cylinder, cone, torus, "
        "bezier, triangle, mesh, sensor)");
}

TEST(SceneYaml, MalformedEmptyAndBinaryFiles) {
    EXPECT_EQ(parse_error("surfaces: [\n"), "s.yaml:2:1: malformed YAML: end of sequence flow not found");
    EXPECT_EQ(parse_error(""), "s.yaml:1:1: file is empty; expected a YAML mapping");
    EXPECT_EQ(parse_error(std::string("\x7f"
                                      "ELF\0\0",
                                      6)),
              "s.yaml: file is binary, not YAML text");
}

TEST(SceneYaml, MissingFileIsReported) {
    try {
        load_scene("no/such/scene.yaml");
        FAIL();
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "no/such/scene.yaml: no such file");
    }
}

TEST(SceneYaml, ShippedScenesParse) {
    const Scene a = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    EXPECT_EQ(a.patch_count(), 86);
    EXPECT_EQ(a.surfaces[a.find_surface("face3")].emission, Rgb(1.27));
    const Scene c = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991-c.yaml");
    EXPECT_EQ(c.patch_count(), 86);
    const SurfaceDesc& ceiling = c.surfaces[c.find_surface("face6")];
    ASSERT_EQ(ceiling.patch_emission.size(), 1u);
    EXPECT_EQ(ceiling.patch_emission[0].emission, Rgb(7.0));
    EXPECT_EQ(c.surfaces[c.find_surface("face3")].emission, Rgb(0.0));
}

TEST(CameraYaml, PaperConventionPutsThetaZeroOnPlusX) {
    const CameraDesc a = parse_camera("camera:\n  distance: 6\n  theta_deg: 0\n  phi_deg: 90\n", "a.yaml");
    EXPECT_NEAR(a.eye.x, 6.0, 1e-12);
    EXPECT_NEAR(a.eye.y, 0.0, 1e-12);
    EXPECT_NEAR(a.eye.z, 0.0, 1e-12);
    const CameraDesc b = parse_camera("camera:\n  distance: 6\n  theta_deg: 180\n  phi_deg: 90\n", "b.yaml");
    EXPECT_NEAR(b.eye.x, -6.0, 1e-12);
    const CameraDesc top = parse_camera("camera:\n  distance: 2\n  theta_deg: 0\n  phi_deg: 0\n", "t.yaml");
    EXPECT_NEAR(top.eye.z, 2.0, 1e-12);
}

TEST(CameraYaml, PositionForm) {
    const CameraDesc c = parse_camera(
        "camera:\n  position: [1, 2, 3]\n  look_at: [0, 0, 1]\n  up: [0, 1, 0]\n  fov_deg: 30\n", "c.yaml");
    EXPECT_EQ(c.eye, Vec3(1, 2, 3));
    EXPECT_EQ(c.look_at, Vec3(0, 0, 1));
    EXPECT_EQ(c.up, Vec3(0, 1, 0));
    EXPECT_EQ(c.fov_deg, 30.0);
}

TEST(CameraYaml, ErrorsNameTheirLine) {
    auto err = [](const std::string& t) {
        try {
            parse_camera(t, "c.yaml");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(err("camera:\n  distance: -6\n  theta_deg: 0\n  phi_deg: 90\n"),
              "c.yaml:2:13: distance must be > 0, got -6");
    EXPECT_EQ(err("camera:\n  distance: 6\n  theta_deg: 0\n"),
              "c.yaml:2:3: camera is missing the required key 'phi_deg'");
    EXPECT_EQ(err("camera:\n  position: [0, 0, 0]\n  fov_deg: 180\n"),
              "c.yaml:3:12: fov_deg must be in (0, 180), got 180");
    EXPECT_EQ(err("camera:\n  position: [0, 0, 0]\n"), "c.yaml:2:3: camera: position and look_at coincide");
    EXPECT_EQ(err("cam:\n  position: [1, 0, 0]\n"),
              "c.yaml:1:1: camera file is missing the required key 'camera'");
}

}  // namespace radiosa

namespace radiosa {

TEST(SceneYaml, CurvedTypesAndPlacementNameTheBadValue) {
    auto one = [](const std::string& body) {
        return parse_error("surfaces:\n  - {name: a, patches: [2, 2], reflectance: [0, 0, 0], " + body +
                           "}\n");
    };
    EXPECT_EQ(one("type: disk, center: [0, 0, 0], normal: [0, 0, 0], radius: 1"),
              "s.yaml:2:95: normal must be a non-zero vector [x, y, z]");
    EXPECT_EQ(one("type: disk, center: [0, 0, 0], normal: [0, 0, 1], radius: 1, inner_radius: 1"),
              "s.yaml:2:117: disk 'a': inner_radius must be smaller than radius (1)");
    EXPECT_EQ(one("type: disk, center: [0, 0, 0], normal: [0, 0, 1], radius: 1, angles_deg: [90, 10]"),
              "s.yaml:2:129: angles_deg [from, to] needs from < to <= from + 360, got [90, 10]");
    EXPECT_EQ(one("type: cylinder, base: [0, 0, 0], axis: [0, 0, 1], radius: .nan"),
              "s.yaml:2:114: radius must be a finite number, got '.nan'");
    EXPECT_EQ(one("type: cone, base: [0, 0, 0], axis: [0, 0, 1], radius: 1, top_radius: -0.5"),
              "s.yaml:2:125: top_radius must be >= 0, got -0.5");
    EXPECT_EQ(one("type: cylinder, base: [0, 0, 0], axis: [0, 0, 1], radius: 1, facing: sideways"),
              "s.yaml:2:125: facing must be 'outward' or 'inward', got 'sideways'");
    EXPECT_EQ(one("type: sphere, center: [0, 0, 0], radius: 1, transform: {scale: -2}"),
              "s.yaml:2:119: transform scale must be a uniform scale in [1e-9, 1e9], got -2");
    EXPECT_EQ(one("type: sphere, center: [0, 0, 0], radius: 1, transform: {rotate_deg: {axis: [0, 0, 1]}}"),
              "s.yaml:2:124: rotate_deg is missing the required key 'angle'");
    EXPECT_EQ(one("type: sphere, center: [0, 0, 0], radius: 1, transform: {shear: 2}"),
              "s.yaml:2:112: unknown key 'shear' in transform (allowed: scale, rotate_deg, translate)");
    EXPECT_EQ(one("type: sphere, center: [0, 0, 0], radius: 1, back_reflectance: [0, 0, 0]"),
              "s.yaml:2:100: back_reflectance needs two_sided: true on surface 'a'");
    // A user's name cannot take the place of a two-sided surface's back.
    EXPECT_EQ(
        parse_error(
            "surfaces:\n"
            "  - {name: a, type: sphere, center: [0, 0, 0], radius: 1, patches: [1, 1], reflectance: [0, "
            "0, 0], two_sided: true}\n"
            "  - {name: a.back, type: sphere, center: [0, 0, 0], radius: 2, patches: [1, 1], "
            "reflectance: [0, 0, 0]}\n"),
        "s.yaml:3:5: surface name 'a.back' is used twice; names must be unique (a two-sided surface's "
        "back side is named <name>.back)");
}

TEST(SceneYaml, TwoSidedSurfacesBecomeTwinSurfaces) {
    const Scene s = parse_scene(
        "surfaces:\n  - {name: lamp, type: disk, center: [0, 0, 1], normal: [0, 0, -1], radius: 0.5, "
        "patches: [4, 1],"
        " reflectance: [0.5, 0.5, 0.5], emission: [3, 3, 3], two_sided: true, back_emission: [1, 0, 0]}\n",
        "lamp.yaml");
    ASSERT_EQ(s.surfaces.size(), 2u);
    EXPECT_EQ(s.surfaces[1].name, "lamp.back");
    EXPECT_EQ(s.surfaces[0].twin, 1);
    EXPECT_EQ(s.surfaces[1].twin, 0);
    EXPECT_EQ(s.surfaces[1].emission, Rgb(1, 0, 0));
    EXPECT_EQ(s.surfaces[1].reflectance, Rgb(0.5));
    EXPECT_EQ(s.patch_count(), 8);
    // The back's normal is the front's reversed.
    const Vec3 nf = s.surfaces[0].shape->normal(0.3, 0.6), nb = s.surfaces[1].shape->normal(0.3, 0.6);
    EXPECT_NEAR(glm::dot(glm::normalize(nf), glm::normalize(nb)), -1.0, 1e-15);
    EXPECT_LT(nf.z, 0.0);
}

}  // namespace radiosa
