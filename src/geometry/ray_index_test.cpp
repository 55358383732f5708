// The BVH finds exactly the hits a loop over every surface finds: the same surface, patch and
// distance, bit for bit, for rays from inside and outside a scene of every surface type, also
// when the scene and the camera lie a million units from the origin. A whole sphere's hit
// parameters come from SIMD atan2 and acos (util/angles.h) instead of glibc's: within 1e-15 of
// the loop's, in [0, 1].
#include "geometry/ray_index.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <string>

#include "../tests/test_scenes.h"
#include "geometry/scene_geometry.h"

namespace radiosa {

namespace {

// A box of side 8 (inward quads) holding `balls` small spheres on a grid, a torus, a cone, a
// two-sided disk, a tube and a curved Bezier sheet, all shifted by `offset`.
std::string crowded(int balls, double offset) {
    auto at = [&](double x, double y, double z) {
        return "[" + std::to_string(x + offset) + ", " + std::to_string(y + offset) + ", " +
               std::to_string(z + offset) + "]";
    };
    std::string s = test::cube_faces(4, offset, 2);
    const std::string m = ", reflectance: [0.5, 0.5, 0.5]}\n";
    for (int b = 0; b < balls; ++b) {
        const double x = -3 + 6.0 * (b % 10) / 9, y = -3 + 6.0 * ((b / 10) % 10) / 9,
                     z = -3 + 0.6 * (b / 100);
        s += "  - {name: ball" + std::to_string(b) + ", type: sphere, center: " + at(x, y, z) +
             ", radius: 0.2, patches: [4, 2]" + m;
    }
    s += "  - {name: ring, type: torus, center: " + at(0, 0, 2.5) +
         ", axis: [0.2, 0.3, 1], major_radius: 1, minor_radius: 0.25, patches: [8, 4]" + m;
    s += "  - {name: shade, type: cone, base: " + at(2, -2, 2) +
         ", axis: [0, 0, 0.8], radius: 0.6, top_radius: 0.1, patches: [6, 2], two_sided: true" + m;
    s += "  - {name: lamp, type: disk, center: " + at(-2, 2, 3) +
         ", normal: [0, 0, -1], radius: 0.5, patches: [4, 1], two_sided: true" + m;
    s += "  - {name: tube, type: cylinder, base: " + at(2.5, 2.5, -4) +
         ", axis: [0, 0, 8], radius: 0.4, patches: [6, 2]" + m;
    std::string cp;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            cp += (cp.empty() ? "" : ", ") +
                  at(-3 + j, -3 + i, 3.2 + 0.3 * ((i == 1 || i == 2) && (j == 1 || j == 2)));
    s += "  - {name: sheet, type: bezier, control_points: [" + cp + "], patches: [2, 2], two_sided: true" + m;
    return s;
}

// Each ray alone, and all of them as one batch (packets through Embree), find what the loop
// finds.
void expect_same_hits(const SceneGeometry& g, double offset, double far, int count) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Ray> rays;
    for (int r = 0; r < count; ++r) {
        // Half the rays start inside the box, half on a sphere of radius `far` around it.
        Vec3 o(u(rng), u(rng), u(rng));
        Vec3 d(u(rng), u(rng), u(rng));
        if (r % 2) {
            o = glm::normalize(o) * far;
            d = -o + Vec3(3 * u(rng), 3 * u(rng), 3 * u(rng));
        } else {
            o *= 3.9;
        }
        o += Vec3(offset);
        rays.push_back(Ray{o, d});
    }
    std::vector<std::optional<Hit>> batch(rays.size());
    g.intersect_front(rays.data(), rays.size(), batch.data());
    int hits = 0;
    for (int r = 0; r < count; ++r) {
        const auto b = g.intersect_front_by_loop(rays[r]);
        for (const auto& a : {g.intersect_front(rays[r]), batch[r]}) {
            ASSERT_EQ(a.has_value(), b.has_value()) << "ray " << r;
            if (!a) continue;
            ++hits;
            EXPECT_EQ(a->surface, b->surface) << "ray " << r;
            EXPECT_EQ(a->patch, b->patch) << "ray " << r;
            EXPECT_EQ(a->dist, b->dist) << "ray " << r;
            EXPECT_NEAR(a->s, b->s, 1e-15) << "ray " << r;
            EXPECT_NEAR(a->t, b->t, 1e-15) << "ray " << r;
        }
    }
    EXPECT_GT(hits, 2 * count / 4);  // the one-sided box is entered from outside only where it faces in
}

// A camera's rays, neighbours in packets as an image traces them, among a thousand balls.
TEST(RayIndex, AnImagesRaysInPacketsFindWhatTheLoopFinds) {
    const SceneGeometry g(test::scene_of(crowded(1000, 0.0)));
    std::vector<Ray> rays;
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 61; ++x)  // not a multiple of the packet: the last packet is partial
            rays.push_back(Ray{Vec3(3.9, -3.9, 3.5), Vec3(-1.0, 0.2 + 0.02 * x, -0.3 - 0.02 * y)});
    std::vector<std::optional<Hit>> batch(rays.size());
    g.intersect_front(rays.data(), rays.size(), batch.data());
    std::set<int> balls;
    for (std::size_t r = 0; r < rays.size(); ++r) {
        const auto b = g.intersect_front_by_loop(rays[r]);
        ASSERT_EQ(batch[r].has_value(), b.has_value()) << "ray " << r;
        if (!b) continue;
        EXPECT_EQ(batch[r]->surface, b->surface) << "ray " << r;
        EXPECT_EQ(batch[r]->dist, b->dist) << "ray " << r;
        EXPECT_EQ(batch[r]->patch, b->patch) << "ray " << r;
        EXPECT_NEAR(batch[r]->u, b->u, 1e-14) << "ray " << r;  // s within 1e-15, times the patches
        balls.insert(b->surface);
    }
    EXPECT_GT(balls.size(), 50u);  // the rays pass among many balls, not one wall
    // Packets of 8 (every processor) and of 16 (AVX-512: a ball tested eight lanes at a time
    // from the packet's coordinates) find the same surfaces at the same distances, bit for bit.
    std::vector<const Surface*> all;
    for (int k = 0; k < g.surface_count(); ++k) all.push_back(&g.surface(k));
    const RayIndex index(all);
    std::vector<RayIndex::Found> by8(rays.size()), by16(rays.size());
    index.nearest_front(rays.data(), rays.size(), by8.data(), 8);
    index.nearest_front(rays.data(), rays.size(), by16.data(), 16);
    for (std::size_t r = 0; r < rays.size(); ++r) {
        ASSERT_EQ(by8[r].surface, batch[r] ? batch[r]->surface : -1) << "ray " << r;
        ASSERT_EQ(by16[r].surface, by8[r].surface) << "ray " << r;
        if (by8[r].surface < 0) continue;
        EXPECT_EQ(by8[r].hit.dist, batch[r]->dist) << "ray " << r;
        EXPECT_EQ(by16[r].hit.dist, by8[r].hit.dist) << "ray " << r;
    }
}

}  // namespace

TEST(RayIndex, FindsWhatALoopOverEverySurfaceFinds) {
    const SceneGeometry g(test::scene_of(crowded(300, 0.0)));
    ASSERT_GE(g.surface_count(), SceneGeometry::kRayIndexMinSurfaces);
    expect_same_hits(g, 0.0, 20.0, 4000);
}

TEST(RayIndex, AFarSceneAndAFarCameraLoseNothing) {
    // Float has 7 digits: a million units away, only clipping the ray to the scene and taking
    // it relative to the scene's centre keeps Embree's traversal from missing boxes.
    const SceneGeometry g(test::scene_of(crowded(100, 1e6)));
    expect_same_hits(g, 1e6, 1e6, 2000);
}

TEST(RayIndex, RaysThatMissEverything) {
    const SceneGeometry g(test::scene_of(crowded(20, 0.0)));
    EXPECT_FALSE(g.intersect_front(Ray{Vec3(100, 0, 0), Vec3(1, 0, 0)}));    // pointing away
    EXPECT_FALSE(g.intersect_front(Ray{Vec3(100, 100, 0), Vec3(0, 0, 1)}));  // passing by
    EXPECT_FALSE(g.intersect_front(Ray{Vec3(0, 0, 0), Vec3(0, 0, 0)}));      // no direction
}

}  // namespace radiosa
