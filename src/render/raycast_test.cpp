#include "render/raycast.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>

#include "encode/encode.h"
#include "encode/image_io.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace radiosa {

namespace {
Scene lone_sphere() {
    return parse_scene(
        "closed: false\nsurfaces:\n  - name: ball\n    type: sphere\n    center: [0, 0, 0]\n"
        "    radius: 1\n    patches: [8, 4]\n    reflectance: [0.5, 0.5, 1]\n",
        "ball.yaml");
}
}  // namespace

TEST(Raycast, SphereSilhouetteCoversTheAnalyticArea) {
    // Seen from distance D on axis, a sphere of radius R projects to a disc of radius
    // f tan(asin(R / D)) pixels, f the focal length in pixels.
    const Scene s = lone_sphere();
    const SceneGeometry geo(s);
    CameraDesc cd;
    cd.eye = Vec3(6, 0, 0);
    cd.fov_deg = 50;
    // Square and wide images alike: the disc stays round (the field of view is vertical).
    for (const RenderOptions opt : {RenderOptions{200, 200, 4}, RenderOptions{300, 150, 4}}) {
        const PinholeCamera cam(cd, opt.width, opt.height);
        const double r = cam.focal_pixels() * std::tan(std::asin(1.0 / 6.0));
        const double expected = kPi * r * r;
        EXPECT_NEAR(surface_coverage(geo, 0, cam, opt), expected, 0.003 * expected) << opt.width;
    }
}

TEST(Raycast, DiskAndCylinderSilhouettesCoverTheAnalyticArea) {
    // A disk of radius R facing the eye at distance D projects to a disc of radius f R / D; a
    // two-sided one shows the same disc from behind. A vertical tube far taller than the view
    // projects to a band between the tangent lines, 2 f tan(asin(R / D)) pixels wide.
    const Scene s = parse_scene(
        "closed: false\nsurfaces:\n"
        "  - {name: plate, type: disk, center: [0, 0, 0], normal: [1, 0, 0], radius: 1, patches: [8, 2],\n"
        "     reflectance: [0.5, 0.5, 0.5], two_sided: true}\n"
        "  - {name: tube, type: cylinder, base: [-20, 0, -500], axis: [0, 0, 1000], radius: 1.5, patches: "
        "[8, 1],\n"
        "     reflectance: [0.5, 0.5, 0.5]}\n",
        "shapes.yaml");
    const SceneGeometry geo(s);
    ASSERT_EQ(geo.surface_count(), 3);
    const RenderOptions opt{160, 120, 4};
    for (const double side : {1.0, -1.0}) {
        CameraDesc cd;
        cd.eye = Vec3(6 * side, 0, 0);
        cd.fov_deg = 50;
        const PinholeCamera cam(cd, opt.width, opt.height);
        const double r = cam.focal_pixels() / 6.0;
        EXPECT_NEAR(surface_coverage(geo, side > 0 ? 0 : 1, cam, opt), kPi * r * r, 0.01 * kPi * r * r)
            << side;
    }
    CameraDesc cd;
    cd.eye = Vec3(-10, 0, 0);
    cd.look_at = Vec3(-20, 0, 0);
    cd.fov_deg = 50;
    const PinholeCamera cam(cd, opt.width, opt.height);
    const double width = 2 * cam.focal_pixels() * std::tan(std::asin(1.5 / 10.0));
    EXPECT_NEAR(surface_coverage(geo, 2, cam, opt), width * opt.height, 0.01 * width * opt.height);
}

TEST(Raycast, TorusSilhouetteCoversTheAnalyticAnnulus) {
    // Seen along its axis from distance D, a ring torus projects to an annulus: in a plane through
    // the axis the tube is a circle of radius r about (R, 0), and the lines from the eye tangent to
    // it leave the axis at atan(R / D) +- asin(r / hypot(R, D)).
    const Scene s = parse_scene(
        "closed: false\nsurfaces:\n"
        "  - {name: ring, type: torus, center: [0, 0, 0], axis: [1, 0, 0], major_radius: 1, minor_radius: "
        "0.25,\n"
        "     patches: [8, 4], reflectance: [0.5, 0.5, 0.5]}\n",
        "ring.yaml");
    const SceneGeometry geo(s);
    const RenderOptions opt{160, 120, 4};
    CameraDesc cd;
    cd.eye = Vec3(6, 0, 0);
    cd.fov_deg = 50;
    const PinholeCamera cam(cd, opt.width, opt.height);
    const double mid = std::atan(1.0 / 6.0), half = std::asin(0.25 / std::hypot(1.0, 6.0));
    const double f = cam.focal_pixels(), out = f * std::tan(mid + half), in = f * std::tan(mid - half);
    const double area = kPi * (out * out - in * in);
    EXPECT_NEAR(surface_coverage(geo, 0, cam, opt), area, 0.01 * area);
}

// Sub-pixel rays sit at the centres of their cells: a sphere in the middle of the view renders
// left-right and top-bottom symmetric, with one ray per pixel and with four.
TEST(Raycast, SamplesAtCellCentresKeepASymmetricViewSymmetric) {
    const Scene s = lone_sphere();
    const SceneGeometry geo(s);
    const std::vector<Rgb> B(geo.patch_count(), Rgb(1.0)), E(geo.patch_count(), Rgb(0.0));
    const NodeRadiosity nodes(geo, B, E);
    CameraDesc cd;
    cd.eye = Vec3(6, 0, 0);
    for (int samples : {1, 2}) {
        const RenderOptions opt{41, 41, samples};
        const Image img = render_image(geo, nodes, PinholeCamera(cd, opt.width, opt.height), opt);
        int asymmetric = 0;
        for (int y = 0; y < opt.height; ++y)
            for (int x = 0; x < opt.width; ++x)
                asymmetric += std::abs(img.pixel(x, y).r - img.pixel(opt.width - 1 - x, y).r) > 1e-6 ||
                              std::abs(img.pixel(x, y).r - img.pixel(x, opt.height - 1 - y).r) > 1e-6;
        EXPECT_EQ(asymmetric, 0) << samples << " samples";
    }
}

TEST(Raycast, ARowsRaysAreEachPixelsRayBitForBit) {
    // render_image traces rows a few pixels at a time from PinholeCamera::row_rays (its
    // arithmetic in arrays, for SIMD lanes): each must be ray() of its sample, bit for bit, so
    // that images do not change with it.
    CameraDesc cd;
    cd.eye = Vec3(3.7, -1.3, 0.9);
    cd.look_at = Vec3(-0.2, 0.4, -0.1);
    cd.fov_deg = 63.0;
    const PinholeCamera cam(cd, 641, 357);
    for (int n : {1, 2, 3, 8}) {
        const int pixels = PinholeCamera::kRowRays / (n * n);
        for (int y : {0, 178, 356})
            for (int x0 : {0, 333, 641 - pixels}) {
                Ray rays[PinholeCamera::kRowRays];
                cam.row_rays(y, x0, x0 + pixels, n, rays);
                int r = 0;
                for (int x = x0; x < x0 + pixels; ++x)
                    for (int sy = 0; sy < n; ++sy)
                        for (int sx = 0; sx < n; ++sx, ++r) {
                            const Ray one = cam.ray(x + (sx + 0.5) / n, y + (sy + 0.5) / n);
                            ASSERT_EQ(rays[r].origin, one.origin);
                            for (int c = 0; c < 3; ++c)
                                ASSERT_EQ(rays[r].dir[c], one.dir[c])
                                    << n << " " << x << " " << y << " " << r;
                        }
            }
    }
}

TEST(Shading, NodesAverageAroundSeamAndPoles) {
    const Scene s = lone_sphere();
    const SceneGeometry geo(s);
    std::vector<Rgb> B(geo.patch_count()), E(geo.patch_count(), Rgb(0.0));
    for (int i = 0; i < geo.patch_count(); ++i) B[i] = Rgb(double(i));
    const NodeRadiosity nodes(geo, B, E);
    // South pole: mean of the 8 patches of row 0 (indices 0..7) = 3.5, for every a.
    for (int a = 0; a <= 8; ++a) EXPECT_DOUBLE_EQ(nodes.node(0, a, 0).r, 3.5);
    // North pole: mean of row 3 (24..31) = 27.5.
    EXPECT_DOUBLE_EQ(nodes.node(0, 4, 4).r, 27.5);
    // Seam: node a = 0 and a = 8 are one point, averaging patches 7, 0, 15, 8.
    EXPECT_DOUBLE_EQ(nodes.node(0, 0, 1).r, (7 + 0 + 15 + 8) / 4.0);
    EXPECT_DOUBLE_EQ(nodes.node(0, 8, 1).r, nodes.node(0, 0, 1).r);
}

TEST(Shading, UniformRadiosityShadesUniformlyAndEmissionStaysOnItsPatch) {
    const Scene s = parse_scene(
        "surfaces:\n  - name: f\n    type: quad\n    corners: [[0, 0, 0], [3, 0, 0], "
        "[3, 3, 0], [0, 3, 0]]\n    patches: [3, 3]\n    reflectance: [0.5, 0.5, 0.5]\n",
        "f.yaml");
    const SceneGeometry geo(s);
    std::vector<Rgb> B(9, Rgb(0.25)), E(9, Rgb(0.0));
    B[4] += Rgb(7.0);
    E[4] = Rgb(7.0);  // the centre patch emits 7 on top of the uniform reflected 0.25
    const NodeRadiosity nodes(geo, B, E);
    for (double x : {0.2, 1.1, 1.5, 2.9})
        for (double y : {0.4, 1.9, 2.2}) {
            const Hit h = geo.locate(0, x / 3, y / 3, 1.0);
            const bool centre = x > 1 && x < 2 && y > 1 && y < 2;
            EXPECT_NEAR(nodes.shade(h).g, centre ? 7.25 : 0.25, 1e-14) << x << "," << y;
        }
}

TEST(Raycast, ImageDoesNotDependOnThreadCount) {
    const Scene s = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml");
    const SceneGeometry geo(s);
    std::vector<Rgb> B(geo.patch_count());
    for (int i = 0; i < geo.patch_count(); ++i) B[i] = Rgb(0.01 * i, 0.5, 1.0 - 0.01 * i);
    const NodeRadiosity nodes(geo, B, std::vector<Rgb>(geo.patch_count(), Rgb(0.0)));
    CameraDesc cd;
    const PinholeCamera cam(cd, 64, 48);
    const RenderOptions opt{64, 48, 2};
    const Image many = render_image(geo, nodes, cam, opt);
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_EQ(render_image(geo, nodes, cam, opt).rgb, many.rgb);
}

TEST(ImageIo, PngIsSrgbAndExrIsLinear) {
    Image img;
    img.width = 4;
    img.height = 2;
    img.rgb.assign(24, 0.5f);
    img.rgb[0] = 1.0f;
    img.rgb[1] = 7.0f;  // overexposed: clamps to white
    img.rgb[2] = 0.0f;
    const auto dir = std::filesystem::temp_directory_path() / "radiosa_image_io_test";
    std::filesystem::create_directories(dir);
    write_image(img, (dir / "a.png").string(), 0.0);
    write_image(img, (dir / "a.exr").string(), 0.0);
    const Image png = media::read_image((dir / "a.png").string());
    ASSERT_EQ(png.width, 4);
    ASSERT_EQ(png.height, 2);
    EXPECT_FLOAT_EQ(png.rgb[0], 1.0f);
    EXPECT_FLOAT_EQ(png.rgb[1], 1.0f);
    EXPECT_FLOAT_EQ(png.rgb[2], 0.0f);
    EXPECT_NEAR(png.rgb[3], 188.0 / 255.0, 1e-6);  // sRGB(0.5) = 0.7354 -> 188
    const Image exr = media::read_image((dir / "a.exr").string());
    EXPECT_EQ(exr.rgb, img.rgb);
    EXPECT_EQ(encode_srgb8(0.0031308 / 2), std::lround(255 * 12.92 * 0.0031308 / 2));
    std::filesystem::remove_all(dir);
}

TEST(ImageIo, MissingDirectoryFailsAndLeavesNoFile) {
    Image img;
    img.width = img.height = 1;
    img.rgb.assign(3, 0.0f);
    EXPECT_THROW(write_image(img, "/nonexistent-radiosa-dir/a.png", 0.0), Error);
    EXPECT_FALSE(std::filesystem::exists("/nonexistent-radiosa-dir"));
}

}  // namespace radiosa
