// The hierarchical links' cache file: an exact round trip through obtain_hierarchy, the key,
// and damaged or crafted files (valid checksums included) refused on load and by `cache verify`.
#include "cache/link_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "../tests/cli_run.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "surfaces/quad.h"
#include "util/error.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

const std::string kSeed = RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml";

// The seed scene (closed, 86 patches: every link joins two patches) and its links, built once.
class LinkFile : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        s_scene = new Scene(load_scene(kSeed));
        s_geometry = new SceneGeometry(*s_scene);
        s_links = new Hierarchy(build_hierarchy(*s_geometry, hierarchy_options(kOptions), kOptions));
    }
    static void TearDownTestSuite() {
        delete s_links;
        delete s_geometry;
        delete s_scene;
    }
    static const Scene& scene() { return *s_scene; }
    static const SceneGeometry& geometry() { return *s_geometry; }
    static const Hierarchy& links() { return *s_links; }
    static CacheExpectation expect() {
        return {hierarchy_key(scene(), kOptions), &geometry(), kOptions, scene().closed};
    }
    // A file holding `h` under the seed scene's key: well formed, its checksum valid.
    static fs::path write(const Hierarchy& h, const std::string& name) {
        const fs::path p = test::fresh_dir("radiosa_link_file_" + name) / "links.rhl";
        write_link_file(p, expect().key, scene().name, scene().closed, geometry(), kOptions, h);
        return p;
    }
    static std::string load_error(const fs::path& p) {
        try {
            read_link_file(p, expect());
        } catch (const CacheFileError& e) {
            return e.what();
        }
        return "";
    }
    static std::string verify_error(const fs::path& p) {
        try {
            verify_link_file(p);
        } catch (const CacheFileError& e) {
            return e.what();
        }
        return "";
    }
    static inline const FormFactorOptions kOptions = FormFactorOptions::hierarchical(kDefaultLinkTolerance);

private:
    static inline Scene* s_scene = nullptr;
    static inline SceneGeometry* s_geometry = nullptr;
    static inline Hierarchy* s_links = nullptr;
};

bool same_links(const Hierarchy& a, const Hierarchy& b) {
    if (a.links.size() != b.links.size() || a.first_link != b.first_link ||
        a.pair_links.size() != b.pair_links.size() || a.first_pair_link != b.first_pair_link)
        return false;
    for (std::size_t k = 0; k < a.links.size(); ++k) {
        const Link &x = a.links[k], &y = b.links[k];
        if (x.receiver != y.receiver || x.source != y.source || x.f != y.f || x.error != y.error ||
            x.gs != y.gs || x.gt != y.gt || x.cs != y.cs || x.ct != y.ct)
            return false;
    }
    for (std::size_t k = 0; k < a.pair_links.size(); ++k) {
        const PairLink &x = a.pair_links[k], &y = b.pair_links[k];
        if (x.receiver != y.receiver || x.source != y.source || x.f != y.f || x.error != y.error)
            return false;
    }
    return true;
}

}  // namespace

// A miss builds and writes; the next run loads the same links bit for bit, the same nodes,
// and the same irradiance; `cache verify` passes the file.
TEST_F(LinkFile, RoundTripThroughTheCacheIsExact) {
    CacheSettings cs;
    cs.dir = test::fresh_dir("radiosa_link_file_cache");
    std::vector<std::string> warnings;
    const WarningSink warn = [&](const std::string& w) { warnings.push_back(w); };
    CacheOutcome first, second;
    const Hierarchy a = obtain_hierarchy(scene(), geometry(), kOptions, cs, warn, &first);
    const Hierarchy b = obtain_hierarchy(scene(), geometry(), kOptions, cs, warn, &second);
    EXPECT_EQ(first.status, CacheStatus::Miss);
    EXPECT_TRUE(first.written);
    EXPECT_EQ(second.status, CacheStatus::Hit);
    EXPECT_TRUE(warnings.empty());
    EXPECT_EQ(fs::path(second.file).extension(), ".rhl");
    EXPECT_TRUE(same_links(a, b));
    EXPECT_TRUE(same_links(a, links()));  // deterministic: equal to a separate build
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    for (std::size_t i = 0; i < a.nodes.size(); ++i) {
        EXPECT_EQ(a.nodes[i].area, b.nodes[i].area);
        EXPECT_EQ(a.nodes[i].cu, b.nodes[i].cu);
    }
    EXPECT_EQ(a.stats.node_pairs, b.stats.node_pairs);
    EXPECT_EQ(a.leaf_stats.pairs, b.leaf_stats.pairs);
    std::vector<double> B(static_cast<std::size_t>(geometry().patch_count()));
    for (std::size_t i = 0; i < B.size(); ++i) B[i] = 1.0 + std::sin(double(i));
    EXPECT_EQ(a.irradiance(B), b.irradiance(B));
    const CacheFileInfo info = verify_link_file(second.file);
    EXPECT_EQ(info.links, static_cast<std::uint64_t>(a.link_count()));
    EXPECT_EQ(info.nodes, a.nodes.size());
    EXPECT_EQ(info.patches, 86u);
}

// The key follows the geometry and every setting the links depend on, and never equals the
// matrix's key.
TEST_F(LinkFile, KeyFollowsGeometryAndSettings) {
    const CacheKey k = hierarchy_key(scene(), kOptions);
    EXPECT_EQ(k, hierarchy_key(load_scene(kSeed), kOptions));
    EXPECT_NE(k, hierarchy_key(scene(), FormFactorOptions::hierarchical(1e-4)));
    FormFactorOptions pair = kOptions;
    pair.tolerance *= 0.5;
    EXPECT_NE(k, hierarchy_key(scene(), pair));
    EXPECT_NE(k, hierarchy_key(scene(), FormFactorOptions::hierarchical(kDefaultLinkTolerance, false)));
    EXPECT_NE(k, form_factor_key(scene(), FormFactorOptions::adaptive(kOptions.tolerance)));
    Scene moved = scene();
    auto c = dynamic_cast<const QuadSurface&>(*moved.surfaces[0].shape).corners();
    c[0] += Vec3(1e-9, 0.0, 0.0);
    moved.surfaces[0].shape = std::make_shared<QuadSurface>(c[0], c[1], c[2], c[3]);
    EXPECT_NE(k, hierarchy_key(moved, kOptions));
}

// Damage and foreign files: a flipped byte, a truncation, another key, another tolerance.
TEST_F(LinkFile, DamagedOrForeignFilesAreRefused) {
    const fs::path p = write(links(), "damaged");
    EXPECT_EQ(load_error(p), "");
    const std::vector<std::uint8_t> good = test::read_bytes(p);
    std::vector<std::uint8_t> bytes = good;
    bytes[bytes.size() / 2] ^= 0x40;
    EXPECT_NE(std::string([&] {
                  try {
                      read_link_bytes(bytes, expect());
                  } catch (const CacheFileError& e) {
                      return std::string(e.what());
                  }
                  return std::string();
              }())
                  .find("checksum"),
              std::string::npos);
    EXPECT_THROW(verify_link_bytes(bytes), CacheFileError);
    const std::vector<std::uint8_t> cut(good.begin(), good.begin() + static_cast<long>(good.size() / 3));
    EXPECT_THROW(read_link_bytes(cut, expect()), CacheFileError);
    EXPECT_THROW(verify_link_bytes(cut), CacheFileError);
    CacheExpectation other = expect();
    other.options = FormFactorOptions::hierarchical(1e-4);
    EXPECT_THROW(read_link_bytes(good, other), CacheFileError);
    other = expect();
    other.key.bytes[0] ^= 1;
    EXPECT_THROW(read_link_bytes(good, other), CacheFileError);
    // Bytes without the magic are not a link file.
    EXPECT_THROW(verify_link_bytes(std::vector<std::uint8_t>(good.size(), 0)), CacheFileError);
}

// A header claiming a billion links is refused before anything is allocated: its section
// sizes no longer agree with the count.
TEST_F(LinkFile, ImpossibleCountsAreRefusedBeforeAllocating) {
    std::vector<std::uint8_t> bytes = test::read_bytes(write(links(), "counts"));
    // magic, two versions, the key, the scene name, patches, surfaces, nodes: then the link count.
    const std::size_t at = 8 + 4 + 4 + 16 + 4 + scene().name.size() + 8 + 8 + 8;
    ASSERT_EQ(bytes[at] + 256u * bytes[at + 1] + 65536u * bytes[at + 2],
              static_cast<std::uint64_t>(links().link_count()));
    bytes[at + 3] = 0x40;  // + 2^30
    EXPECT_THROW(read_link_bytes(bytes, expect()), CacheFileError);
    EXPECT_THROW(verify_link_bytes(bytes), CacheFileError);
}

// Crafted links with a valid checksum: each is refused on load naming what is wrong, and the
// ones that need no scene also by `cache verify`.
TEST_F(LinkFile, CraftedLinksAreRefused) {
    const auto crafted = [&](const std::string& name, auto&& change) {
        Hierarchy h = links();
        change(h);
        return write(h, name);
    };
    // The seed scene's links all join two patches.
    ASSERT_TRUE(links().links.empty());
    fs::path p = crafted("order", [](Hierarchy& h) { std::swap(h.pair_links[3], h.pair_links[4]); });
    EXPECT_NE(load_error(p).find("out of order"), std::string::npos) << load_error(p);
    EXPECT_NE(verify_error(p).find("out of order"), std::string::npos);
    p = crafted("range", [](Hierarchy& h) { h.pair_links.back().source = static_cast<int>(h.nodes.size()); });
    EXPECT_NE(load_error(p).find("out of range"), std::string::npos) << load_error(p);
    EXPECT_NE(verify_error(p).find("out of range"), std::string::npos);
    p = crafted("nan",
                [](Hierarchy& h) { h.pair_links[7].error = std::numeric_limits<double>::quiet_NaN(); });
    EXPECT_NE(load_error(p).find("estimate"), std::string::npos) << load_error(p);
    EXPECT_NE(verify_error(p).find("estimate"), std::string::npos);
    // A link with slopes between two patches (written in its place among the others).
    const auto with_slope = [](float gs) {
        return [gs](Hierarchy& h) {
            const PairLink l = h.pair_links[9];
            h.pair_links.erase(h.pair_links.begin() + 9);
            h.links.push_back(Link{l.receiver, l.source, l.f, l.error, gs, 0.0f, 0.0f, 0.0f});
        };
    };
    p = crafted("slope", with_slope(std::numeric_limits<float>::infinity()));
    EXPECT_NE(load_error(p).find("slope"), std::string::npos) << load_error(p);
    p = crafted("pair-slope", with_slope(0.25f));
    EXPECT_NE(load_error(p).find("joins two patches but has slopes"), std::string::npos) << load_error(p);
    // Well formed, but the rows no longer close: scaled, or half the links dropped.
    p = crafted("scaled", [](Hierarchy& h) {
        for (PairLink& l : h.pair_links) l.f *= 0.9;
    });
    EXPECT_NE(load_error(p).find("far from 1"), std::string::npos) << load_error(p);
    EXPECT_EQ(verify_error(p), "");  // rows need the nodes, which need the scene
    p = crafted("dropped", [](Hierarchy& h) { h.pair_links.resize(h.pair_links.size() / 2); });
    EXPECT_NE(load_error(p).find("far from 1"), std::string::npos) << load_error(p);
}

// Through the cache: a damaged file is reported once and rebuilt, and the rebuilt file loads.
TEST_F(LinkFile, DamagedCacheFileIsRebuilt) {
    CacheSettings cs;
    cs.dir = test::fresh_dir("radiosa_link_file_rebuild");
    const WarningSink quiet = [](const std::string&) {};
    CacheOutcome o;
    obtain_hierarchy(scene(), geometry(), kOptions, cs, quiet, &o);
    std::vector<std::uint8_t> bytes = test::read_bytes(o.file);
    bytes[bytes.size() - 20] ^= 1;
    std::ofstream(o.file, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    std::vector<std::string> warnings;
    const Hierarchy h = obtain_hierarchy(
        scene(), geometry(), kOptions, cs, [&](const std::string& w) { warnings.push_back(w); }, &o);
    EXPECT_EQ(o.status, CacheStatus::Rebuilt);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("checksum mismatch"), std::string::npos) << warnings[0];
    EXPECT_TRUE(same_links(h, links()));
    EXPECT_NO_THROW(read_link_file(o.file, expect()));
}

}  // namespace radiosa
