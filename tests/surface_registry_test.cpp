// Every registered surface type, every one of its parameters: changing it alone changes the
// form-factor cache key, so no two different scenes can share a cached matrix. A type whose
// write_key forgets a field fails here.
#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include "cache/cache_file.h"
#include "scene/scene.h"
#include "surfaces/registry.h"

namespace radiosa {
namespace {

// One surface of `type` with the given keys, in a scene of its own.
Scene one_surface(const SurfaceType& type, const std::vector<SurfaceKeyValue>& keys,
                  const std::string& patches) {
    std::string yaml = "surfaces:\n  - name: s\n    type: " + type.name + "\n    patches: " + patches +
                       "\n    reflectance: [0.5, 0.5, 0.5]\n";
    for (const auto& kv : keys) yaml += "    " + kv.key + ": " + kv.value + "\n";
    // Files the type's keys name sit beside the scene file.
    const std::string dir = testing::TempDir();
    for (const auto& f : type.example_files) std::ofstream(dir + "/" + f.key) << f.value;
    return parse_scene(yaml, dir + "/" + type.name + ".yaml");
}

std::vector<SurfaceKeyValue> with(std::vector<SurfaceKeyValue> keys, const SurfaceKeyValue& change) {
    for (auto& kv : keys)
        if (kv.key == change.key) kv.value = change.value;
    return keys;
}

TEST(SurfaceRegistry, NamesAreUniqueAndFound) {
    std::set<std::string> names;
    std::set<std::uint32_t> ids;
    for (const SurfaceType* t : surface_types()) {
        EXPECT_TRUE(names.insert(t->name).second) << t->name;
        EXPECT_TRUE(ids.insert(t->key_id).second) << t->name;
        EXPECT_EQ(find_surface_type(t->name), t);
    }
    EXPECT_EQ(find_surface_type("teapot"), nullptr);
    EXPECT_EQ(surface_type_names(), "quad, sphere, disk, cylinder, cone, torus, bezier, triangle, mesh");
}

TEST(SurfaceRegistry, EveryParameterOfEveryTypeReachesTheCacheKey) {
    const FormFactorOptions options;
    std::set<std::string> keys;
    for (const SurfaceType* t : surface_types()) {
        SCOPED_TRACE(t->name);
        ASSERT_FALSE(t->variants.empty());
        const Scene base = one_surface(*t, t->example, "[2, 2]");
        EXPECT_TRUE(keys.insert(form_factor_key(base, options).hex()).second);
        // Each of the type's own parameters, then the subdivision every type has.
        std::set<std::string> probed;
        for (const SurfaceKeyValue& v : t->variants) {
            SCOPED_TRACE(v.key + ": " + v.value);
            probed.insert(v.key);
            const Scene changed = one_surface(*t, with(t->example, v), "[2, 2]");
            EXPECT_TRUE(keys.insert(form_factor_key(changed, options).hex()).second);
        }
        for (const SurfaceKeyValue& kv : t->example)
            EXPECT_TRUE(probed.count(kv.key)) << kv.key << " is never changed";
        for (const char* patches : {"[3, 2]", "[2, 3]"})
            EXPECT_TRUE(
                keys.insert(form_factor_key(one_surface(*t, t->example, patches), options).hex()).second);
    }
}

TEST(SurfaceRegistry, EveryFormFactorOptionReachesTheCacheKey) {
    const Scene s = one_surface(*surface_types().front(), surface_types().front()->example, "[2, 2]");
    std::set<std::string> keys;
    FormFactorOptions no_visibility;
    no_visibility.visibility = false;
    FormFactorOptions one_direction;
    one_direction.one_direction = true;
    FormFactorOptions lines;
    lines.numeric_lines = true;
    for (const FormFactorOptions& o :
         {FormFactorOptions(), FormFactorOptions::adaptive(1e-7), no_visibility, FormFactorOptions::gauss(6),
          FormFactorOptions::gauss(7), one_direction, lines})
        EXPECT_TRUE(keys.insert(form_factor_key(s, o).hex()).second) << describe(o);
}

TEST(SurfaceRegistry, UnknownTypeNamesTheKnownOnes) {
    try {
        parse_scene("surfaces:\n  - {name: t, type: teapot, patches: [1, 1], reflectance: [0, 0, 0]}\n",
                    "x.yaml");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(),
                     "x.yaml:2:21: unknown surface type 'teapot' (known: quad, sphere, disk, cylinder, cone, "
                     "torus, bezier, triangle, mesh, sensor)");
    }
}

}  // namespace
}  // namespace radiosa
