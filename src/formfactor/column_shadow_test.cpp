// What a column spanning a pair hides, against closed forms: from a point facing a wall, the
// wedge the column casts is a centred rectangle on the wall (Howell's B-3 on the axis), and
// from a wide wall the wedge of a thin column takes sin(alpha) = r / D of the hemisphere.
#include "formfactor/column_shadow.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "../tests/closed_forms.h"
#include "formfactor/planar_receiver.h"
#include "formfactor/point_polygon.h"
#include "scene/scene.h"
#include "util/gauss_legendre.h"

namespace radiosa {

using test::element_on_rectangle_axis;

TEST(ColumnShadow, TheWedgeOnAWallIsACentredRectangle) {
    // From the origin facing +y, a wall at y = 5 (|x| <= 10, |z| <= 3, front facing -y), and a
    // column along z of radius r through (0, D): the wedge meets the wall in |x| <= 5 tan(alpha),
    // sin(alpha) = r / D, all of its height.
    const std::array<Vec3, 4> wall = {Vec3(-10, 5, -3), Vec3(10, 5, -3), Vec3(10, 5, 3), Vec3(-10, 5, 3)};
    for (const double D : {1.0, 2.5, 4.0}) {
        const double r = 0.4, alpha = std::asin(r / D);
        const RoundTube column{Vec3(0, D, -10), Vec3(0, 0, 1), 20, r};
        EXPECT_NEAR(point_to_polygon_hidden_by_column(Vec3(0.0), Vec3(0, 1, 0), wall.data(), 4, column),
                    element_on_rectangle_axis(5 * std::tan(alpha), 3, 5), 1e-14)
            << D;
    }
    // A point inside the cylinder has no wedge; one beside the column sees it hide nothing of a
    // wall on its other side.
    std::array<Vec3, 2> h;
    EXPECT_FALSE(column_wedge(Vec3(0, 1, 0), RoundTube{Vec3(0, 1.2, 0), Vec3(0, 0, 1), 1, 0.3}, &h));
    const std::array<Vec3, 4> behind = {Vec3(-10, -5, -3), Vec3(10, -5, -3), Vec3(10, -5, 3),
                                        Vec3(-10, -5, 3)};
    EXPECT_EQ(point_to_polygon_hidden_by_column(Vec3(0.0), Vec3(0, -1, 0), behind.data(), 4,
                                                RoundTube{Vec3(0, 2, -10), Vec3(0, 0, 1), 20, 0.4}),
              0.0);
}

TEST(ColumnShadow, ACloseWideWallLosesSinAlphaOfTheHemisphere) {
    // The wedge of a thin column seen from a point facing a huge wall just behind it holds sin
    // alpha of the projected hemisphere (1/pi times the integral of cos over the wedge).
    const double L = 1e6;
    const std::array<Vec3, 4> wall = {Vec3(-L, 3, -L), Vec3(L, 3, -L), Vec3(L, 3, L), Vec3(-L, 3, L)};
    const RoundTube column{Vec3(0, 2, -2 * L), Vec3(0, 0, 1), 4 * L, 0.5};
    EXPECT_NEAR(point_to_polygon_hidden_by_column(Vec3(0.0), Vec3(0, 1, 0), wall.data(), 4, column), 0.25,
                1e-5);
}

TEST(ColumnShadow, SpanningNeedsTheSlabAndAClearView) {
    const RoundTube column{Vec3(0, 0, -1), Vec3(0, 0, 1), 2, 0.3};
    const std::array<Vec3, 4> left = {Vec3(-1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, 1, 1), Vec3(-1, -1, 1)};
    const std::array<Vec3, 4> right = {Vec3(1, -1, -1), Vec3(1, -1, 1), Vec3(1, 1, 1), Vec3(1, 1, -1)};
    EXPECT_TRUE(column_spans_pair(left, right, column, 1e-9));
    // Taller than the column: a segment may pass over its top.
    std::array<Vec3, 4> tall = right;
    tall[1].z = tall[2].z = 1.5;
    EXPECT_FALSE(column_spans_pair(left, tall, column, 1e-9));
    // The floor under the column: its projection holds the circle.
    const std::array<Vec3, 4> floor = {Vec3(-1, -1, -1), Vec3(1, -1, -1), Vec3(1, 1, -1), Vec3(-1, 1, -1)};
    EXPECT_FALSE(column_spans_pair(floor, right, column, 1e-9));
    // A floor patch around the column's foot (every edge clear of the circle, the circle inside).
    const std::array<Vec3, 4> around = {Vec3(-0.5, -0.5, -1), Vec3(0.5, -0.5, -1), Vec3(0.5, 0.5, -1),
                                        Vec3(-0.5, 0.5, -1)};
    EXPECT_FALSE(column_spans_pair(around, right, column, 1e-9));
    // A receiver between the source and the column.
    const std::array<Vec3, 4> near = {Vec3(-0.5, -1, -1), Vec3(-0.5, -1, 1), Vec3(-0.5, 1, 1),
                                      Vec3(-0.5, 1, -1)};
    EXPECT_FALSE(column_spans_pair(left, near, column, 1e-9));
}

TEST(ColumnShadow, TwoWallsWithAColumnBetweenMatchAFineReference) {
    // Two facing walls 2 apart and a two-sided column from floor level to ceiling level between
    // them: the pair takes the closed-form shadow both ways; each direction within its estimate
    // of a fine piecewise Gauss reference on the same inner factor, and of the other direction.
    const Scene scene = parse_scene(
        "closed: false\nsurfaces:\n"
        "  - {name: a, type: quad, corners: [[-1, -1, -1], [-1, 1, -1], [-1, 1, 1], [-1, -1, 1]], patches: "
        "[1, 1],"
        " reflectance: [0.5, 0.5, 0.5]}\n"
        "  - {name: b, type: quad, corners: [[1, -1, -1], [1, -1, 1], [1, 1, 1], [1, 1, -1]], patches: [1, "
        "1],"
        " reflectance: [0.5, 0.5, 0.5]}\n"
        "  - {name: column, type: cylinder, base: [0.1, 0.2, -1], axis: [0, 0, 2], radius: 0.3, patches: [4, "
        "1],"
        " reflectance: [0.5, 0.5, 0.5], two_sided: true}\n",
        "walls.yaml");
    const SceneGeometry g(scene);
    const std::vector<int> blockers = {2, 3};
    const auto how = planar_receiver(g, 0, 1, blockers, true);
    ASSERT_TRUE(how && how->column);
    const GaussRule outer = gauss_legendre(4), fine = gauss_legendre(8);
    const Estimate ab = area_times_f_planar(g, 0, 1, *how, 1e-10, outer, 4096, 1e-12);
    const Estimate ba =
        area_times_f_planar(g, 1, 0, *planar_receiver(g, 1, 0, blockers, true), 1e-10, outer, 4096, 1e-12);
    // The reference: the unblocked pair (Howell's parallel squares C-11, sides 2 at distance 2)
    // minus the shadow integrated over wall a by Gauss rules on strips cut where the wedge's
    // edges pass b's corners (vertical lines on a: the shadow's only kinks), 8 x 8 strips of
    // 8 x 8 points each.
    const std::array<Vec3, 4> b = g.front_polygon(1);
    const RoundTube column = *how->column;
    std::vector<double> cuts = {-1.0, 1.0};
    for (const Vec3& v : b) {
        std::array<Vec3, 2> h;
        ASSERT_TRUE(column_wedge(v, column, &h));
        for (const Vec3& m : h) {
            const double y = v.y - m.x * (-1.0 - v.x) / m.y;
            if (y > -1.0 && y < 1.0) cuts.push_back(y);
        }
    }
    std::sort(cuts.begin(), cuts.end());
    double hidden = 0.0;
    for (std::size_t c = 0; c + 1 < cuts.size(); ++c)
        for (int i = 0; i < 8; ++i)
            for (int j = 0; j < 8; ++j)
                for (std::size_t p = 0; p < fine.x.size(); ++p)
                    for (std::size_t q = 0; q < fine.x.size(); ++q) {
                        const double hy = (cuts[c + 1] - cuts[c]) / 8, hz = 2.0 / 8;
                        const double y = cuts[c] + hy * (i + 0.5 * (fine.x[p] + 1)),
                                     z = -1 + hz * (j + 0.5 * (fine.x[q] + 1));
                        hidden += 0.25 * hy * hz * fine.w[p] * fine.w[q] *
                                  point_to_polygon_hidden_by_column(Vec3(-1, y, z), Vec3(1, 0, 0), b.data(),
                                                                    4, column);
                    }
    const double open = 4 * 0.19982489569838737;
    EXPECT_NEAR(ab.value, open - hidden, std::max(ab.error, 1e-9));
    EXPECT_NEAR(ba.value, open - hidden, std::max(ba.error, 1e-9));
    EXPECT_NEAR(ab.value, ba.value, ab.error + ba.error);
    EXPECT_GT(hidden, 0.1);
}

}  // namespace radiosa
