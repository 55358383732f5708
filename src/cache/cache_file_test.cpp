// The form-factor cache: what the key includes and leaves out, exact round trips, and every
// kind of damaged or foreign file detected and rebuilt.
#include "cache/cache_file.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include "../tests/cli_run.h"
#include "../tests/test_scenes.h"
#include "cache/cache_format.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "surfaces/quad.h"
#include "surfaces/sphere.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

const std::string kSeed = RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml";

fs::path fresh_dir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

FormFactorOptions opts(int p = 6) { return FormFactorOptions::gauss(p); }

// The scene with one corner of surface k (a quad) moved by d.
Scene move_corner(Scene s, int k, int corner, const Vec3& d) {
    auto c = dynamic_cast<const QuadSurface&>(*s.surfaces[k].shape).corners();
    c[corner] += d;
    s.surfaces[k].shape = std::make_shared<QuadSurface>(c[0], c[1], c[2], c[3]);
    return s;
}

struct Obtained {
    FormFactors ff;
    CacheOutcome outcome;
    std::vector<std::string> warnings;
};
Obtained obtain(const Scene& scene, const fs::path& dir, int p = 6) {
    Obtained r;
    const SceneGeometry g(scene);
    CacheSettings cs;
    cs.dir = dir;
    r.ff = obtain_form_factors(
        scene, g, opts(p), cs, [&](const std::string& w) { r.warnings.push_back(w); }, &r.outcome);
    return r;
}

// Two plates facing each other: half the matrix is zero but the dense layout is still smaller.
Scene plates() {
    return test::scene_of(test::quad("floor", test::kFloor, 2, 1) +
                          test::quad("ceiling", test::kCeiling, 2, 1));
}

}  // namespace

TEST(CacheKey, IgnoresWhatDoesNotChangeTheMatrix) {
    const Scene a = load_scene(kSeed);
    const CacheKey k = form_factor_key(a, opts());
    EXPECT_EQ(k.hex().size(), 32u);
    Scene b = a;
    b.name = "renamed";
    b.surfaces[0].reflectance = Rgb(0.1, 0.2, 0.3);
    b.surfaces[2].emission = Rgb(0.0);
    b.surfaces[5].patch_emission.push_back({1, 1, Rgb(7.0), {}});
    b.surfaces[0].name = "floor";
    EXPECT_EQ(form_factor_key(b, opts()), k);
}

TEST(CacheKey, ChangesWithGeometrySubdivisionAndSettings) {
    const Scene a = load_scene(kSeed);
    std::vector<std::string> keys{form_factor_key(a, opts()).hex()};
    keys.push_back(form_factor_key(move_corner(a, 0, 2, Vec3(1e-9, 0, 0)), opts()).hex());  // a nanometre
    Scene b = a;
    b.surfaces[3].ns += 1;
    keys.push_back(form_factor_key(b, opts()).hex());
    b = a;
    const BoundingSphere ball = *b.surfaces[6].shape->sphere();
    b.surfaces[6].shape = std::make_shared<SphereSurface>(ball.center, ball.radius + 1e-12, false);
    keys.push_back(form_factor_key(b, opts()).hex());
    keys.push_back(form_factor_key(a, opts(7)).hex());
    FormFactorOptions novis = opts();
    novis.visibility = false;
    keys.push_back(form_factor_key(a, novis).hex());
    std::sort(keys.begin(), keys.end());
    EXPECT_EQ(std::unique(keys.begin(), keys.end()), keys.end());
}

TEST(CacheFile, RoundTripIsBitExactInBothLayouts) {
    const fs::path d = fresh_dir("radiosa_cache_roundtrip");
    for (const Scene& scene : {load_scene(kSeed), plates()}) {
        const SceneGeometry g(scene);
        const FormFactorOptions o = FormFactorOptions::adaptive(1e-6);
        const FormFactors ff = compute_form_factors(g, o);  // estimates travel with the matrix
        const CacheKey key = form_factor_key(scene, o);
        const fs::path file = d / (key.hex() + ".rff");
        write_cache_file(file, key, scene.name, scene.closed, g, ff);
        CacheFileInfo info;
        const FormFactors back = read_cache_file(file, {key, &g, o, scene.closed}, &info);
        EXPECT_EQ(back.F.data, ff.F.data);
        EXPECT_EQ(back.area, ff.area);
        EXPECT_EQ(back.error, ff.error);
        EXPECT_EQ(back.options.method, FormFactorMethod::Adaptive);
        EXPECT_EQ(back.options.tolerance, 1e-6);
        EXPECT_EQ(info.closed, scene.closed);
        EXPECT_EQ(back.stats.segment_tests, ff.stats.segment_tests);
        EXPECT_EQ(info.patches, static_cast<std::uint64_t>(g.patch_count()));
        EXPECT_EQ(read_cache_info(file).key, key);
        // The seed scene has many zero pairs and a symmetric box: sparse and compressed.
        EXPECT_EQ(info.layout, scene.name == "baranoski1991" ? "csr" : "dense");
    }
    fs::remove_all(d);
}

TEST(CacheObtain, HitsWhenOnlyColoursEmissionOrNameChange) {
    const fs::path d = fresh_dir("radiosa_cache_hit");
    const Scene a = load_scene(kSeed);
    const Obtained first = obtain(a, d);
    EXPECT_EQ(first.outcome.status, CacheStatus::Miss);
    EXPECT_TRUE(first.outcome.written);
    EXPECT_TRUE(fs::exists(first.outcome.file));
    Scene c = load_scene(RADIOSA_SOURCE_DIR "/scenes/baranoski1991-c.yaml");
    c.surfaces[6].reflectance = Rgb(0.9, 0.1, 0.1);
    const Obtained second = obtain(c, d);
    EXPECT_EQ(second.outcome.status, CacheStatus::Hit);
    EXPECT_TRUE(second.warnings.empty());
    EXPECT_EQ(second.ff.F.data, first.ff.F.data);
    EXPECT_EQ(second.outcome.compute_s, 0.0);
    // Geometry, subdivision or p: a different file.
    EXPECT_EQ(obtain(move_corner(a, 0, 0, Vec3(0, 0, -1e-6)), d).outcome.status, CacheStatus::Miss);
    EXPECT_EQ(obtain(a, d, 4).outcome.status, CacheStatus::Miss);
    int files = 0;
    for (const auto& e : fs::directory_iterator(d)) files += e.path().extension() == ".rff";
    EXPECT_EQ(files, 3);
    // Nothing but complete matrix files is left: no temporaries, no locks.
    EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 3);
    fs::remove_all(d);
}

// Each kind of damage is detected, reported once with its reason, recomputed, and the file
// rewritten so that the next run hits.
TEST(CacheObtain, DamagedFilesAreDetectedAndRebuilt) {
    const fs::path d = fresh_dir("radiosa_cache_damage");
    const Scene scene = load_scene(kSeed);
    const Obtained good = obtain(scene, d);
    const fs::path file = good.outcome.file;
    const std::vector<std::uint8_t> pristine = test::read_bytes(file);
    ASSERT_GT(pristine.size(), 1000u);

    // A file of another scene (or other settings) copied under this key's name.
    const Obtained other = obtain(scene, d, 3);
    const std::vector<std::uint8_t> foreign = test::read_bytes(other.outcome.file);
    // A file with this key but the patch table of another scene.
    const fs::path forged = d / "forged.rff";
    {
        const Scene p = plates();
        const SceneGeometry g(p);
        write_cache_file(forged, form_factor_key(scene, opts()), p.name, true, g,
                         compute_form_factors(g, opts()));
    }
    const std::vector<std::uint8_t> wrong_table = test::read_bytes(forged);
    fs::remove(forged);

    struct Case {
        std::string name;
        std::vector<std::uint8_t> bytes;
        std::string reason;
    };
    std::vector<Case> cases;
    auto flipped = [&](std::size_t at) {
        std::vector<std::uint8_t> b = pristine;
        b[at] ^= 0x10;
        return b;
    };
    cases.push_back({"byte flipped in the matrix", flipped(pristine.size() - 100), "checksum mismatch"});
    cases.push_back({"byte flipped in the key", flipped(20), "not this scene's"});
    cases.push_back({"byte flipped in the checksum", flipped(pristine.size() - 1), "checksum mismatch"});
    cases.push_back(
        {"truncated to half", {pristine.begin(), pristine.begin() + pristine.size() / 2}, "truncated"});
    cases.push_back({"last byte missing", {pristine.begin(), pristine.end() - 1}, "checksum"});
    cases.push_back({"truncated in the header", {pristine.begin(), pristine.begin() + 30}, "truncated"});
    cases.push_back({"empty", {}, "truncated"});
    std::vector<std::uint8_t> v2 = pristine;
    v2[8] = 99;
    cases.push_back({"future format version", v2, "file format version 99"});
    std::vector<std::uint8_t> old_alg = pristine;
    old_alg[12] = 0;
    cases.push_back({"older algorithm", old_alg, "algorithm version 0"});
    std::vector<std::uint8_t> magic = pristine;
    magic[0] = 'X';
    cases.push_back({"not a cache file", magic, "wrong magic"});
    cases.push_back({"another scene's file", foreign, "not this scene's"});
    cases.push_back({"matching key, other patch table", wrong_table, "patch table does not match"});

    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        test::write_bytes(file, c.bytes);
        const Obtained r = obtain(scene, d);
        EXPECT_EQ(r.outcome.status, CacheStatus::Rebuilt);
        EXPECT_NE(r.outcome.reason.find(c.reason), std::string::npos) << r.outcome.reason;
        ASSERT_EQ(r.warnings.size(), 1u);
        EXPECT_NE(r.warnings[0].find(file.string()), std::string::npos);
        EXPECT_EQ(r.ff.F.data, good.ff.F.data);       // never a partially used matrix
        EXPECT_EQ(test::read_bytes(file), pristine);  // rewritten, and deterministic
        EXPECT_EQ(obtain(scene, d).outcome.status, CacheStatus::Hit);
    }
    fs::remove_all(d);
}

TEST(CacheObtain, UnwritableCacheWarnsAndStillComputes) {
    const fs::path d = fresh_dir("radiosa_cache_unwritable");
    std::ofstream(d / "file") << "not a directory";
    const Scene scene = load_scene(kSeed);
    const Obtained r = obtain(scene, d / "file" / "cache");
    EXPECT_EQ(r.outcome.status, CacheStatus::Miss);
    EXPECT_FALSE(r.outcome.written);
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("not cached"), std::string::npos);
    EXPECT_EQ(r.ff.F.n, 86);
    fs::remove_all(d);
}

TEST(CacheObtain, OffComputesAndWritesNothing) {
    const fs::path d = fresh_dir("radiosa_cache_off");
    const Scene scene = load_scene(kSeed);
    const SceneGeometry g(scene);
    CacheSettings cs;
    cs.dir = d;
    cs.enabled = false;
    CacheOutcome o;
    const FormFactors ff = obtain_form_factors(
        scene, g, opts(), cs, [](const std::string&) {}, &o);
    EXPECT_EQ(o.status, CacheStatus::Off);
    EXPECT_GT(o.compute_s, 0.0);
    EXPECT_EQ(ff.F.n, 86);
    EXPECT_TRUE(fs::is_empty(d));
    fs::remove_all(d);
}

TEST(CacheObtain, DefaultDirectoryFollowsTheEnvironment) {
    const char* saved = std::getenv("RADIOSA_CACHE_DIR");
    const std::string keep = saved ? saved : "";
    ::setenv("RADIOSA_CACHE_DIR", "/some/where", 1);
    EXPECT_EQ(default_cache_dir(), fs::path("/some/where"));
    ::setenv("RADIOSA_CACHE_DIR", "", 1);
    EXPECT_EQ(default_cache_dir(), fs::path("out/cache"));
    if (saved)
        ::setenv("RADIOSA_CACHE_DIR", keep.c_str(), 1);
    else
        ::unsetenv("RADIOSA_CACHE_DIR");
}

// A section written in pieces (a large scene's links are gigabytes, never held whole): more
// than three chunks long, it reads back byte for byte through the streaming reader, with a
// valid checksum and the stored size in its head; one flipped byte fails the checksum; a
// producer that stops short is a programming error and leaves no file.
TEST(CacheFormat, StreamedSectionReadsBackAcrossChunks) {
    using namespace cache_format;
    const fs::path dir = test::fresh_dir("radiosa_streamed_section");
    const fs::path p = dir / "s.bin";
    const std::uint64_t raw = 3 * kChunk + 12345;
    const auto byte = [](std::uint64_t i) {  // compressible, and not one repeated run
        return static_cast<std::uint8_t>(i % 7 == 0 ? (i * 2654435761u) >> 13 : i / 4096);
    };
    const auto head = [](std::uint64_t stored) {
        ByteWriter w;
        w.raw("HEAD", 4);
        w.u64(stored);
        return std::move(w.bytes());
    };
    std::uint64_t next = 0;
    const auto produce = [&](std::uint8_t* dst, std::size_t cap) {
        const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(cap, raw - next));
        for (std::size_t k = 0; k < n; ++k) dst[k] = byte(next + k);
        next += n;
        return n;
    };
    commit_streamed(p, raw, head, produce);
    {
        const FileSource src(p);
        EXPECT_NO_THROW(check_checksum(src));
        const std::vector<std::uint8_t> h = src.read_vector(0, 12);
        ByteReader in(h.data() + 4, 8);
        const std::uint64_t stored = in.u64();
        EXPECT_EQ(src.size(), 12 + stored + 8);
        EXPECT_LT(stored, raw / 2);  // it was compressed
        SectionStream s(src, stored, raw, true, "test");
        std::vector<std::uint8_t> got(65536);
        std::uint64_t bad = 0;
        for (std::uint64_t at = 0; at < raw; at += got.size()) {
            const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(got.size(), raw - at));
            s.read(got.data(), n);
            for (std::size_t k = 0; k < n; ++k) bad += got[k] != byte(at + k);
        }
        EXPECT_EQ(bad, 0u);
        EXPECT_NO_THROW(s.finish());
    }
    {
        std::fstream f(p, std::ios::in | std::ios::out | std::ios::binary);
        f.seekg(20);
        const char c = static_cast<char>(f.get());
        f.seekp(20);
        f.put(static_cast<char>(c ^ 0x5a));
    }
    EXPECT_THROW(check_checksum(FileSource(p)), CacheFileError);

    const fs::path short_file = dir / "short.bin";
    next = raw - 10;  // ten bytes where raw were announced
    EXPECT_THROW(commit_streamed(short_file, raw, head, produce), std::logic_error);
    EXPECT_FALSE(fs::exists(short_file));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);  // no temporary left
}

}  // namespace radiosa
