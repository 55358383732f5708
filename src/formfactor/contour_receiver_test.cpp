// Curved receivers by their contours against answers known in advance: a flat Bezier patch as
// Howell's parallel squares, a Bezier bump seen once from a floor and a torus's outer patches
// seen from a square, each against a 4-D product rule of Lambert's kernel
// (formfactor/contour_receiver.h; the proofs that allow it: Surface::seen_once_from,
// Surface::on_convex_hull).
#include "formfactor/contour_receiver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../tests/test_scenes.h"
#include "formfactor/analytic.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/gauss_legendre.h"

namespace radiosa {

namespace {

// F from the square centre c, half-side h, sides along the unit vectors u and v (facing u x v),
// to patch j of surface s: Lambert's kernel by a 24-point Gauss rule along each of the four
// axes, with no occlusion. For pairs nothing hides, a distance apart: the integrand is smooth.
double square_to_patch(const Surface& s, const Patch& pj, const Vec3& c, const Vec3& u, const Vec3& v,
                       double h) {
    const GaussRule gl = gauss_legendre(24);
    const Vec3 nx = glm::cross(u, v);
    const double ds = 0.5 * (pj.s1 - pj.s0), dt = 0.5 * (pj.t1 - pj.t0);
    double f = 0.0;
    for (std::size_t a = 0; a < gl.x.size(); ++a)
        for (std::size_t b = 0; b < gl.x.size(); ++b) {
            const Vec3 x = c + h * gl.x[a] * u + h * gl.x[b] * v;
            for (std::size_t k = 0; k < gl.x.size(); ++k)
                for (std::size_t l = 0; l < gl.x.size(); ++l) {
                    const double sp = pj.s0 + ds * (1 + gl.x[k]), tp = pj.t0 + dt * (1 + gl.x[l]);
                    const Vec3 r = s.point(sp, tp) - x, n = s.normal(sp, tp);
                    const double rr = glm::dot(r, r);
                    f += gl.w[a] * gl.w[b] * gl.w[k] * gl.w[l] * ds * dt * glm::dot(nx, r) * -glm::dot(n, r) /
                         (kPi * rr * rr);
                }
        }
    return f / 4.0;  // the weights of the square's two axes sum to 4, its area to 4 h^2
}

}  // namespace

TEST(CurvedSurfaces, FlatBezierPatchMatchesTheParallelSquares) {
    // A Bezier patch whose control points are an even grid is the square [0,3]^2 exactly; facing
    // a quad 3 above it they are Howell's parallel squares (C-11): 0.19982489569838737.
    std::string cp;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            cp += (cp.empty() ? "" : ", ") + std::string("[") + std::to_string(j) + ", " + std::to_string(i) +
                  ", 0]";
    const Scene scene = parse_scene(
        "closed: false\nsurfaces:\n"
        "  - {name: sheet, type: bezier, control_points: [" +
            cp +
            "], patches: [1, 1], reflectance: [0.5, 0.5, 0.5]}\n"
            "  - {name: lid, type: quad, corners: [[0, 0, 3], [0, 3, 3], [3, 3, 3], [3, 0, 3]], patches: [1, "
            "1], reflectance: [0.5, 0.5, 0.5]}\n",
        "sheet.yaml");
    const FormFactors ff =
        compute_form_factors(SceneGeometry(scene), FormFactorOptions::adaptive(1e-7, true));
    // The pair takes the contour of the sheet's boundary (seen once from the quad); only the
    // sheet's self pair (a Bezier patch may see itself) is numeric.
    EXPECT_EQ(ff.stats.semi_analytic, 1);
    EXPECT_EQ(ff.stats.numeric, 1);
    EXPECT_EQ(ff.F(0, 0), 0.0);
    EXPECT_NEAR(ff.F(0, 1), 0.19982489569838737, 1e-7);
    EXPECT_NEAR(ff.F(1, 0), 0.19982489569838737, 1e-7);
    EXPECT_LE(std::abs(ff.F(0, 1) - 0.19982489569838737), ff.error[1] + 1e-12);
}

TEST(CurvedSurfaces, ABezierSheetSeenOnceFromAPolygonTakesItsContour) {
    // A bump (edges the square [-0.5, 0.5]^2 at z = 0, the inner four control points raised 0.2),
    // two-sided and split 2 x 2, 1 above a floor [-1, 1]^2. Every ray from the floor meets it once
    // (Bezier.SeenOnce*), so each floor-to-back pair takes the contour path (its four boundary
    // cubics) and each floor-to-front pair is culled.
    const Scene scene = parse_scene(
        "closed: false\nsurfaces:\n"
        "  - {name: floor, type: quad, corners: [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1]], "
        "patches: [1, 1], reflectance: [0.5, 0.5, 0.5]}\n"
        "  - {name: sheet, type: bezier, control_points: " +
            test::bezier_bump() + ", patches: [2, 2], reflectance: [0.5, 0.5, 0.5], two_sided: true}\n",
        "bump.yaml");
    const SceneGeometry g(scene);
    ASSERT_EQ(g.patch_count(), 9);
    const FormFactorRows rows(g, FormFactorOptions::adaptive(1e-10, true));
    FormFactorStats st;
    const GaussRule gl = gauss_legendre(24);
    const Surface& back = g.surface(2);
    double sum = 0.0;
    for (int j = 1; j < 9; ++j) {
        const PairEntries e = rows.pair(0, j, &st);
        if (j < 5) {
            EXPECT_EQ(e.f_ij, 0.0);  // the floor sees only the front's back
            continue;
        }
        sum += e.f_ij;
        // Seen once, nothing hides any part of the patch; the two are a distance 1 apart.
        const double ref =
            square_to_patch(back, g.patch(j), Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(0, 1, 0), 1.0);
        EXPECT_NEAR(e.f_ij, ref, 1e-9) << "patch " << j;
        EXPECT_LE(std::abs(e.f_ij - ref), e.e_ij + 1e-13) << "patch " << j;
        EXPECT_LE(e.e_ij, 1e-9);
    }
    EXPECT_EQ(st.numeric, 0);
    EXPECT_EQ(st.semi_analytic, 4);
    EXPECT_EQ(st.pairs_culled, 4);
    // The sheet's boundary is the flat square [-0.5, 0.5]^2 at z = 0, and a surface seen once
    // subtends what its boundary bounds: the four add up to the floor's factor to that square.
    double square = 0.0;
    for (std::size_t a = 0; a < gl.x.size(); ++a)
        for (std::size_t b = 0; b < gl.x.size(); ++b)
            square += gl.w[a] * gl.w[b] *
                      analytic::point_to_parallel_rectangle(gl.x[a], gl.x[b], -0.5, 0.5, -0.5, 0.5, 1.0) /
                      4.0;
    EXPECT_NEAR(sum, square, 1e-9);
}

TEST(CurvedSurfaces, ATorusOuterPatchFacingAPolygonTakesItsContour) {
    // A ring (R 1, r 0.3) split 16 x 8 and a unit square at x = 3 facing it. A patch of the outer
    // half (cos v >= 0) lies on the ring's convex hull; where every corner of the square is in
    // front of all its tangent planes (faces_ball, exact on a torus), nothing of the ring can
    // hide it and it hides nothing of itself, so the pair takes the contour of its four circle
    // arcs. Against a 24^4-point product rule of Lambert's kernel (smooth: the square keeps 1.7
    // away from the ring).
    const Scene scene = parse_scene(
        "closed: false\nsurfaces:\n"
        "  - {name: ring, type: torus, center: [0, 0, 0], axis: [0, 0, 1], major_radius: 1,"
        " minor_radius: 0.3, patches: [16, 8], reflectance: [0.5, 0.5, 0.5]}\n"
        "  - {name: panel, type: quad, corners: [[3, -0.5, -0.5], [3, -0.5, 0.5], [3, 0.5, 0.5],"
        " [3, 0.5, -0.5]], patches: [1, 1], reflectance: [0.5, 0.5, 0.5]}\n",
        "ring.yaml");
    const SceneGeometry g(scene);
    ASSERT_EQ(g.patch_count(), 129);
    const FormFactorRows rows(g, FormFactorOptions::adaptive(1e-10, true));
    const Surface& ring = g.surface(0);
    const Patch& panel = g.patch(128);
    int facing = 0;
    for (int j = 0; j < 128; ++j) {
        const Patch& pj = g.patch(j);
        bool faces = ring.on_convex_hull(pj.s0, pj.s1, pj.t0, pj.t1);
        for (const Vec3& c : panel.corners)
            faces = faces && ring.faces_ball(pj.s0, pj.s1, pj.t0, pj.t1, BoundingSphere{c, 0.0}, false);
        if (!faces) continue;
        ++facing;
        FormFactorStats st;
        const PairEntries e = rows.pair(128, j, &st);
        EXPECT_EQ(st.semi_analytic, 1) << "patch " << j;
        EXPECT_EQ(st.numeric, 0) << "patch " << j;
        const double ref = square_to_patch(ring, pj, Vec3(3, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0), 0.5);
        EXPECT_NEAR(e.f_ij, ref, 1e-9) << "patch " << j;
        EXPECT_LE(std::abs(e.f_ij - ref), e.e_ij + 1e-12) << "patch " << j;
    }
    // The outer half's patches facing +x: two azimuth columns by the two tube rows at the
    // equator (the rows toward the top and bottom tilt their tangent planes past the square's
    // lower or upper corners).
    EXPECT_EQ(facing, 4);
}

// A cone's side bounds the nappe of its infinite cone, a convex solid: a patch is inside it when
// its largest distance from the axis is within the solid's radius at the narrow end of its
// heights. A vertical square 0.2 wide, from height 0 to 1, at distance 0.45 or 0.6 from the axis
// of a cone narrowing from radius 1 to 0.5 (inside only at 0.45), and of one widening from 0.5
// to 1 (inside neither whole, but its upper half at 0.6 is: radius 0.75 at height 0.5).
TEST(ContourReceiver, APatchIsInsideAConesSolidWhereItsNarrowEndHoldsIt) {
    auto inside = [](double r0, double r1, double x, double z0) {
        const std::string quad = "  - {name: q, type: quad, corners: [[" + std::to_string(x) + ", -0.1, " +
                                 std::to_string(z0) + "], [" + std::to_string(x) + ", 0.1, " +
                                 std::to_string(z0) + "], [" + std::to_string(x) + ", 0.1, 1], [" +
                                 std::to_string(x) +
                                 ", -0.1, 1]], patches: [1, 1], reflectance: [0.5, 0.5, 0.5]}\n";
        const Scene scene = parse_scene(
            "closed: false\nsurfaces:\n  - {name: c, type: cone, base: [0, 0, 0], axis: [0, 0, 1], radius: " +
                std::to_string(r0) + ", top_radius: " + std::to_string(r1) +
                ", facing: inward, patches: [4, 1], reflectance: [0.5, 0.5, 0.5]}\n" + quad,
            "cone.yaml");
        const SceneGeometry g(scene);
        return inside_solid(g, g.patch(4), 0);
    };
    EXPECT_TRUE(inside(1.0, 0.5, 0.45, 0.0));
    EXPECT_FALSE(inside(1.0, 0.5, 0.6, 0.0));
    EXPECT_FALSE(inside(0.5, 1.0, 0.45 + 0.15, 0.0));
    EXPECT_TRUE(inside(0.5, 1.0, 0.6, 0.5));
    EXPECT_FALSE(inside(0.5, 1.0, 0.8, 0.5));
}

}  // namespace radiosa
