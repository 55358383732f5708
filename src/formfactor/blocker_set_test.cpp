// The occlusion guard answers exactly as the surfaces' own tests do: random segments that miss,
// graze, cross or end inside spheres (whole, placed, partial) and quads.
#include "formfactor/blocker_set.h"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace radiosa {

namespace {

// Points near a sphere of centre c and radius R: on it, just off it, or well away.
Vec3 near_sphere(std::mt19937_64& rng, const Vec3& c, double R) {
    std::normal_distribution<double> n(0.0, 1.0);
    std::uniform_int_distribution<int> kind(0, 3);
    Vec3 u(n(rng), n(rng), n(rng));
    u /= glm::length(u);
    const double off[4] = {0.0, 1e-7, -1e-7, 0.5 + std::abs(n(rng))};
    return c + R * (1.0 + off[kind(rng)]) * u;
}

}  // namespace

TEST(BlockerSet, AnswersAsTheSurfacesDo) {
    const Scene scene = parse_scene(R"(closed: false
surfaces:
  - {name: ball, type: sphere, center: [0.3, -0.2, 0.1], radius: 0.7, patches: [4, 2], reflectance: [0.5, 0.5, 0.5]}
  - {name: moved, type: sphere, center: [0, 0, 0], radius: 0.01, patches: [4, 2], reflectance: [0.5, 0.5, 0.5],
     transform: {scale: 40, rotate_deg: {axis: [1, 2, 3], angle: 37}, translate: [3, 0, 0]}}
  - {name: cap, type: sphere, center: [0, 3, 0], radius: 0.5, polar_deg: [0, 70], patches: [4, 2],
     reflectance: [0.5, 0.5, 0.5]}
  - {name: wall, type: quad, corners: [[-1, -1, 2], [1, -1, 2], [1, 1, 2], [-1, 1, 2]], patches: [1, 1],
     reflectance: [0.5, 0.5, 0.5]}
)",
                                    "guard.yaml");
    const SceneGeometry g(scene);
    std::mt19937_64 rng(7);
    const Vec3 centres[3] = {{0.3, -0.2, 0.1}, {3, 0, 0}, {0, 3, 0}};
    const double radii[3] = {0.7, 0.4, 0.5};
    long long hits = 0, total = 0;
    for (int k = 0; k < g.surface_count(); ++k) {
        const BlockerSet guard(g, {k});
        for (int trial = 0; trial < 20000; ++trial) {
            const int a = trial % 3, b = (trial / 3) % 3;
            const Vec3 x = near_sphere(rng, centres[a], radii[a]);
            const Vec3 y = near_sphere(rng, centres[b], radii[b]);
            const Vec3 e = y - x;
            long long tests = 0;
            const bool expected = g.surface(k).blocks(Ray{x, e}, 1e-9, 1.0 - 1e-9);
            ASSERT_EQ(guard.blocked(x, e, 1e-9, 1.0 - 1e-9, &tests), expected)
                << "surface " << k << " trial " << trial;
            EXPECT_EQ(tests, 1);
            hits += expected ? 1 : 0;
            ++total;
        }
    }
    // The segments exercise both answers for every kind of surface.
    EXPECT_GT(hits, total / 20);
    EXPECT_LT(hits, total - total / 20);
}

TEST(BlockerSet, CountsEveryBlockerAskedAndStopsAtTheFirstHit) {
    const Scene scene = parse_scene(R"(closed: false
surfaces:
  - {name: a, type: sphere, center: [0, 0, 0], radius: 1, patches: [4, 2], reflectance: [0.5, 0.5, 0.5]}
  - {name: b, type: sphere, center: [0, 0, 5], radius: 1, patches: [4, 2], reflectance: [0.5, 0.5, 0.5]}
)",
                                    "count.yaml");
    const SceneGeometry g(scene);
    const BlockerSet guard(g, {0, 1});
    long long tests = 0;
    EXPECT_TRUE(guard.blocked(Vec3(-3, 0, 0), Vec3(6, 0, 0), 1e-9, 1.0 - 1e-9, &tests));
    EXPECT_EQ(tests, 1);
    tests = 0;
    EXPECT_TRUE(guard.blocked(Vec3(-3, 0, 5), Vec3(6, 0, 0), 1e-9, 1.0 - 1e-9, &tests));
    EXPECT_EQ(tests, 2);
    tests = 0;
    EXPECT_FALSE(guard.blocked(Vec3(-3, 3, 0), Vec3(6, 0, 0), 1e-9, 1.0 - 1e-9, &tests));
    EXPECT_EQ(tests, 2);
    // A segment ending on the sphere is not blocked by it at its end.
    tests = 0;
    EXPECT_FALSE(guard.blocked(Vec3(-3, 0, 0), Vec3(2, 0, 0), 1e-9, 1.0 - 1e-9, &tests));
    EXPECT_TRUE(BlockerSet(g, {}).empty());
}

// A crowd of 125 balls on one pair's list: from points among them toward a
// ball of receiving points, the blockers near_list keeps answer every segment as the whole
// list does, with the same count of blockers asked, and keep far fewer than all.
TEST(BlockerSet, ANearListAnswersAsTheWholeListDoes) {
    std::string yaml = "closed: false\nsurfaces:\n";
    for (int i = 0; i < 125; ++i)
        yaml += "  - {name: b" + std::to_string(i) + ", type: sphere, center: [" + std::to_string(i % 5) +
                ", " + std::to_string(i / 5 % 5) + ", " + std::to_string(i / 25) +
                "], radius: 0.3, patches: [4, 2], reflectance: [0.5, 0.5, 0.5]}\n";
    const Scene scene = parse_scene(yaml, "crowd.yaml");
    const SceneGeometry g(scene);
    std::vector<int> all(125);
    for (int i = 0; i < 125; ++i) all[static_cast<std::size_t>(i)] = i;
    const BlockerSet guard(g, all);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-0.5, 4.5), d(-0.25, 0.25);
    std::vector<int> near;
    long long blocked = 0, kept = 0, segments = 0;
    for (int trial = 0; trial < 400; ++trial) {
        const Vec3 x(u(rng), u(rng), u(rng)), centre(u(rng), u(rng), u(rng));
        const double radius = 0.45;  // holds centre + (d, d, d), |d| <= 0.25
        guard.near_list(x, centre, radius, &near);
        kept += static_cast<long long>(near.size());
        for (int k = 0; k < 20; ++k) {
            const Vec3 y = centre + Vec3(d(rng), d(rng), d(rng));
            long long whole = 0, among = 0;
            const bool expected = guard.blocked(x, y - x, 1e-9, 1.0 - 1e-9, &whole);
            ASSERT_EQ(guard.blocked_among(x, y - x, 1e-9, 1.0 - 1e-9, &among, near), expected) << trial;
            EXPECT_EQ(among, whole) << trial;
            blocked += expected ? 1 : 0;
            ++segments;
        }
    }
    EXPECT_GT(blocked, segments / 10);
    EXPECT_LT(blocked, segments - segments / 10);
    EXPECT_LT(kept, 400LL * 125 / 4);
}

}  // namespace radiosa
