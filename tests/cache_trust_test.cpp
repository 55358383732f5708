// A shared cache directory must not be able to hurt a run (docs/cache.md, "Trust"): crafted
// files with a valid checksum, headers that claim more than the scene needs, special files in
// place of cache files, a stuck lock holder, planted links and names with terminal escapes.
// Each case is one the probe of the cache found; every crafted file is made here.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>
#include <zstd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>

#include "cache/cache_file.h"
#include "cli_run.h"
#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/bytes.h"

namespace radiosa {

namespace fs = std::filesystem;
using test::CliRun;
using test::fresh_dir;
using test::run;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAsan = true;  // ASan reserves terabytes of address space: no ulimit -v under it
#else
constexpr bool kAsan = false;
#endif

// A valid checksum for edited bytes.
void reseal(std::vector<std::uint8_t>* b) {
    const std::uint64_t sum = XXH3_64bits(b->data(), b->size() - 8);
    for (int k = 0; k < 8; ++k) (*b)[b->size() - 8 + k] = static_cast<std::uint8_t>(sum >> (8 * k));
}
void put_u64(std::vector<std::uint8_t>* b, std::size_t at, std::uint64_t v) {
    for (int k = 0; k < 8; ++k) (*b)[at + k] = static_cast<std::uint8_t>(v >> (8 * k));
}
// Offset of the patch count: magic, versions, key, then the scene name (u32 length + bytes).
std::size_t patches_offset(const std::vector<std::uint8_t>& b) {
    return 36 + (b[32] | (b[33] << 8) | (b[34] << 16) | (static_cast<std::size_t>(b[35]) << 24));
}

struct Seed {
    Scene scene = load_scene(test::kSeedScene);
    SceneGeometry geometry{scene};
    FormFactorOptions options;  // the default: adaptive, 1e-6
    FormFactors good = compute_form_factors(geometry, options);
    CacheKey key = form_factor_key(scene, options);
};
const Seed& seed() {
    static const Seed s;
    return s;
}

struct Load {
    CacheOutcome outcome;
    std::vector<std::string> warnings;
    FormFactors ff;
};
Load load(const fs::path& dir, double lock_timeout_s = 600) {
    const Seed& s = seed();
    Load r;
    CacheSettings cs;
    cs.dir = dir;
    cs.lock_timeout_s = lock_timeout_s;
    r.ff = obtain_form_factors(
        s.scene, s.geometry, s.options, cs, [&](const std::string& w) { r.warnings.push_back(w); },
        &r.outcome);
    return r;
}

fs::path seed_file(const fs::path& dir) { return dir / (seed().key.hex() + ".rff"); }

// The seed scene's good file in `dir`, its header claiming `patches` patches (checksum valid).
void write_with_patch_count(const fs::path& dir, std::uint64_t patches) {
    const Seed& s = seed();
    write_cache_file(seed_file(dir), s.key, s.scene.name, s.scene.closed, s.geometry, s.good);
    std::vector<std::uint8_t> b = test::read_bytes(seed_file(dir));
    put_u64(&b, patches_offset(b), patches);
    reseal(&b);
    test::write_bytes(seed_file(dir), b);
}

// Runs a shell command with its virtual memory limited; returns its exit status.
int run_limited(const std::string& cmd, int megabytes) {
    const std::string line = "bash -c 'ulimit -v " + std::to_string(megabytes * 1024) + "; " + cmd + "'";
    const int status = std::system(line.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

// F x 0.5, F x 1.5, the transpose, all zeros, one entry doubled, the no-visibility matrix and
// the paper's p = 1 matrix under this key, estimates that are not numbers, every value 1e308:
// each was a silent hit; each is now one warning, rebuilt, replaced.
TEST(CacheTrust, CraftedMatricesWithAValidChecksumAreRebuilt) {
    const Seed& s = seed();
    const fs::path d = fresh_dir("radiosa_trust_crafted");
    const int n = s.good.F.n;
    auto scaled = [&](double k) {
        FormFactors f = s.good;
        for (double& v : f.F.data) v *= k;
        return f;
    };
    FormFactors transposed = s.good, zeros = s.good, doubled = s.good, huge = s.good;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) transposed.F(i, j) = s.good.F(j, i);
    for (double& v : zeros.F.data) v = 0.0;
    const auto big = std::max_element(doubled.F.data.begin(), doubled.F.data.end());
    *big *= 2.0;
    for (double& v : huge.F.data) v = 1e308;
    // One smaller entry halved: rows stay plausible, reciprocity does not.
    FormFactors halved = s.good;
    *std::find_if(halved.F.data.begin(), halved.F.data.end(),
                  [](double v) { return v > 0.005 && v < 0.02; }) *= 0.5;
    struct Case {
        const char* name;
        FormFactors ff;
        const char* reason;
    };
    std::vector<Case> cases = {{"F x 0.5", scaled(0.5), "far from 1"},
                               {"F x 1.5", scaled(1.5), "more than 1 + its error estimates"},
                               {"transpose", transposed, "sums to"},
                               {"all zeros", zeros, "far from 1"},
                               {"one entry doubled", doubled, "more than 1 + its error estimates"},
                               {"one entry halved", halved, "break reciprocity"},
                               {"every value 1e308", huge, "not a number in [0, 1]"}};
    for (double e : {std::nan(""), -1e300, static_cast<double>(INFINITY)}) {
        FormFactors f = s.good;
        f.error[5] = e;
        cases.push_back({"an estimate not a finite number >= 0", f, "not a finite number >= 0"});
    }
    FormFactors no_vis = compute_form_factors(s.geometry, FormFactorOptions::adaptive(1e-6, false));
    cases.push_back({"the no-visibility matrix", no_vis, "visibility off; this run asks for"});
    cases.push_back({"the Gauss p = 1 matrix", compute_form_factors(s.geometry, FormFactorOptions::gauss(1)),
                     "was computed Gauss p = 1"});
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        write_cache_file(seed_file(d), s.key, s.scene.name, s.scene.closed, s.geometry, c.ff);
        const Load r = load(d);
        EXPECT_EQ(r.outcome.status, CacheStatus::Rebuilt);
        EXPECT_NE(r.outcome.reason.find(c.reason), std::string::npos) << r.outcome.reason;
        ASSERT_EQ(r.warnings.size(), 1u);
        EXPECT_EQ(r.ff.F.data, s.good.F.data);
        EXPECT_EQ(load(d).outcome.status, CacheStatus::Hit);  // replaced by a good file
    }
    fs::remove_all(d);
}

// A 105-byte header used to make the reader allocate 3.2 GB: the patch count is now checked
// against the scene before anything is allocated, in a process limited to a fraction of that.
TEST(CacheTrust, HeaderClaiming20000PatchesCostsNoMoreThanTheScene) {
    const fs::path d = fresh_dir("radiosa_trust_header");
    write_with_patch_count(d, 20000);
    const Load r = load(d);
    EXPECT_EQ(r.outcome.status, CacheStatus::Rebuilt);
    EXPECT_NE(r.outcome.reason.find("20000 patches, the scene has 86"), std::string::npos)
        << r.outcome.reason;
    if (kAsan) return;
    write_with_patch_count(d, 20000);
    const std::string cmd = std::string(RADIOSA_BINARY) + " formfactors " + test::kSeedScene +
                            " -q --cache-dir " + d.string() + " 2> " + (d / "err").string();
    EXPECT_EQ(run_limited(cmd, 400), 0);  // 3.2 GB would not fit in 400 MB of address space
    std::ifstream err(d / "err");
    const std::string line{std::istreambuf_iterator<char>(err), {}};
    EXPECT_NE(line.find("20000 patches, the scene has 86; recomputing it"), std::string::npos) << line;
    fs::remove_all(d);
}

// A small zstd frame that expands to hundreds of megabytes of zeros passed `cache verify` as
// "ok" after allocating all of it: verify now streams (bounded memory) and the closure check
// of a closed scene's zero rows says BAD.
TEST(CacheTrust, CompressionBombFailsVerifyInBoundedMemory) {
    const fs::path d = fresh_dir("radiosa_trust_bomb");
    constexpr std::uint64_t n = 6000;  // 576 MB of matrix and estimates when expanded
    ByteWriter w;
    const std::uint8_t magic[8] = {'R', 'A', 'D', 'F', 'F', '\r', '\n', 0x1a};
    w.raw(magic, 8);
    w.u32(kCacheFormatVersion);
    w.u32(kFormFactorAlgorithmVersion);
    const std::uint8_t key[16] = {};
    w.raw(key, 16);
    w.str("bomb");
    w.u64(n);
    w.u64(1);
    w.u32(1);          // float64
    w.u32(0);          // dense
    w.u32(1);          // zstd
    w.u32(1 | 2 | 4);  // estimates, visibility, closed
    w.u32(1);          // adaptive
    w.u32(0);
    w.f64(1e-6);
    const std::uint64_t raw = 16 * n * n;
    // Compress raw zero bytes in chunks.
    std::vector<std::uint8_t> packed;
    {
        ZSTD_CCtx* c = ZSTD_createCCtx();
        ZSTD_CCtx_setPledgedSrcSize(c, raw);
        const std::vector<std::uint8_t> zeros(1 << 20, 0);
        std::vector<std::uint8_t> out(ZSTD_CStreamOutSize());
        for (std::uint64_t done = 0; done < raw;) {
            const std::size_t k = static_cast<std::size_t>(std::min<std::uint64_t>(zeros.size(), raw - done));
            done += k;
            ZSTD_inBuffer in{zeros.data(), k, 0};
            const ZSTD_EndDirective mode = done == raw ? ZSTD_e_end : ZSTD_e_continue;
            for (bool more = true; more;) {
                ZSTD_outBuffer o{out.data(), out.size(), 0};
                const std::size_t left = ZSTD_compressStream2(c, &o, &in, mode);
                packed.insert(packed.end(), out.data(), out.data() + o.pos);
                more = mode == ZSTD_e_end ? left != 0 : in.pos < in.size;
            }
        }
        ZSTD_freeCCtx(c);
    }
    w.u64(packed.size());
    w.u64(raw);
    w.str("s");
    w.u32(100);
    w.u32(60);
    for (std::uint32_t i = 0; i < n; ++i) {
        w.u32(0);
        w.u32(i % 100);
        w.u32(i / 100);
        w.f64(1.0);
    }
    FormFactorStats{}.for_each_counter([&](const char*, long long) { w.i64(0); });
    w.raw(packed.data(), packed.size());
    w.u64(XXH3_64bits(w.bytes().data(), w.bytes().size()));
    const fs::path file = d / "c" / "00000000000000000000000000000000.rff";
    fs::create_directories(file.parent_path());
    test::write_bytes(file, w.bytes());
    ASSERT_LT(fs::file_size(file), 1u << 20);

    const CliRun r = run({"cache", "verify", "--cache-dir", (d / "c").string()});
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.out.find("BAD  " + file.string() + ": row 0 of a closed scene sums to 0, far from 1"),
              std::string::npos)
        << r.out;
    if (!kAsan) {
        const std::string cmd =
            std::string(RADIOSA_BINARY) + " cache verify --cache-dir " + (d / "c").string() + " > /dev/null";
        EXPECT_EQ(run_limited(cmd, 300), 1);  // BAD, found in 300 MB of address space, not 576 MB
    }
    fs::remove_all(d);
}

// A FIFO, a directory and a symbolic link in place of the cache file: never waited on or
// followed; reported as not a regular file and rebuilt beside it (the FIFO and the link are
// replaced by the new file; a directory cannot be, so the run goes on uncached).
TEST(CacheTrust, SpecialFilesArePassedOverNotWaitedOn) {
    const fs::path d = fresh_dir("radiosa_trust_special");
    const fs::path target = d / "elsewhere.rff";
    std::ofstream(target) << "precious";
    struct Case {
        const char* name;
        std::function<void(const fs::path&)> make;
        const char* reason;
        bool replaced;
    };
    const std::vector<Case> cases = {
        {"FIFO", [](const fs::path& p) { ::mkfifo(p.c_str(), 0644); }, "is a FIFO, not a regular file", true},
        {"directory", [](const fs::path& p) { fs::create_directories(p / "x"); }, "is a directory", false},
        {"symbolic link", [&](const fs::path& p) { fs::create_symlink(target, p); }, "is a symbolic link",
         true}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const fs::path cache = d / c.name;
        fs::create_directories(cache);
        c.make(seed_file(cache));
        const auto start = std::chrono::steady_clock::now();
        const Load r = load(cache);
        EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
        EXPECT_EQ(r.outcome.status, CacheStatus::Rebuilt);
        EXPECT_NE(r.outcome.reason.find(c.reason), std::string::npos) << r.outcome.reason;
        EXPECT_EQ(r.ff.F.data, seed().good.F.data);
        EXPECT_EQ(fs::is_regular_file(fs::symlink_status(seed_file(cache))), c.replaced);
        // verify names what it is, and a cache path that is a file is an error.
        const CliRun v = run({"cache", "verify", "--cache-dir", cache.string()});
        EXPECT_EQ(v.code, c.replaced ? 0 : 1) << v.out;
    }
    EXPECT_EQ(test::read_bytes(target), (std::vector<std::uint8_t>{'p', 'r', 'e', 'c', 'i', 'o', 'u', 's'}));
    const CliRun f = run({"cache", "verify", "--cache-dir", target.string()});
    EXPECT_EQ(f.code, 1);
    EXPECT_EQ(f.err, "error: " + target.string() +
                         ": the cache path is not a directory (give --cache-dir a directory)\n");
    fs::remove_all(d);
}

// A lock held by a stopped process: one line after a second saying who and for how long it will
// wait, then an error at the deadline; never a silent wait.
TEST(CacheTrust, StuckLockHolderEndsInAMessageAtTheDeadline) {
    const fs::path d = fresh_dir("radiosa_trust_lock");
    const fs::path lock = d / (seed().key.hex() + ".lock");
    const int fd = ::open(lock.c_str(), O_CREAT | O_RDWR, 0644);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX), 0);
    ASSERT_EQ(::write(fd, "4242\n", 5), 5);
    const auto start = std::chrono::steady_clock::now();
    try {
        load(d, 1.5);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  lock.string() +
                      ": gave up after 2 s waiting for process 4242 computing the same "
                      "form factors (it may be stopped or hung); stop it, raise "
                      "--lock-timeout, or run with --no-cache");
    }
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
    ::close(fd);
    fs::remove_all(d);
}

// Links planted at the lock file and at an output are never followed: a dangling lock link does
// not create its target, and an output that is a link is replaced, its target untouched.
TEST(CacheTrust, PlantedLinksAreNeverFollowed) {
    const fs::path d = fresh_dir("radiosa_trust_links");
    fs::create_directories(d / "c");
    fs::create_symlink(d / "victim", d / "c" / (seed().key.hex() + ".lock"));
    const Load r = load(d / "c");
    EXPECT_EQ(r.outcome.status, CacheStatus::Miss);
    EXPECT_TRUE(r.outcome.written);
    EXPECT_FALSE(fs::exists(d / "victim"));
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("a symbolic link"), std::string::npos) << r.warnings[0];

    std::ofstream(d / "target.json") << "keep";
    fs::create_symlink(d / "target.json", d / "report.json");
    ASSERT_EQ(run({"formfactors", test::kSeedScene, "-q", "--cache-dir", (d / "c").string(), "--report",
                   (d / "report.json").string()})
                  .code,
              0);
    EXPECT_FALSE(fs::is_symlink(d / "report.json"));
    EXPECT_EQ(test::read_bytes(d / "target.json"), (std::vector<std::uint8_t>{'k', 'e', 'e', 'p'}));
    fs::remove_all(d);
}

// A scene name with escape sequences and a newline: printed escaped by `cache list` and
// `cache verify`, so it cannot recolour the terminal or forge an "ok" line.
TEST(CacheTrust, NamesFromFilesArePrintedEscaped) {
    const Seed& s = seed();
    const fs::path d = fresh_dir("radiosa_trust_names");
    write_cache_file(seed_file(d), s.key, "evil\x1b[31m\nok   forged", s.scene.closed, s.geometry, s.good);
    for (const char* cmd : {"list", "verify"}) {
        const CliRun r = run({"cache", cmd, "--cache-dir", d.string()});
        EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << cmd;
        EXPECT_EQ(r.out.find("\nok   forged"), std::string::npos) << cmd;
        EXPECT_NE(r.out.find("evil\\x1b[31m\\x0aok   forged"), std::string::npos) << r.out;
    }
    fs::remove_all(d);
}

// A header with zero patches (a null-pointer memcpy under UBSan) is refused by its count.
TEST(CacheTrust, ZeroPatchesIsRefusedByItsCount) {
    const fs::path d = fresh_dir("radiosa_trust_zero");
    write_with_patch_count(d, 0);
    const CliRun r = run({"cache", "verify", "--cache-dir", d.string()});
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.out.find("implausible patch count 0"), std::string::npos) << r.out;
    EXPECT_EQ(load(d).outcome.status, CacheStatus::Rebuilt);
    fs::remove_all(d);
}

// A sparse matrix whose column index is one past the row (N) is refused, never written into
// the next row or past the matrix: a CSR file crafted with a valid checksum.
TEST(CacheTrust, SparseColumnIndexOfNIsRefused) {
    const Scene s = parse_scene(
        "closed: false\nsurfaces:\n"
        "  - {name: floor, type: quad, corners: [[0,0,0],[1,0,0],[1,1,0],[0,1,0]], patches: [2, 2], "
        "reflectance: [0,0,0]}\n"
        "  - {name: top, type: quad, corners: [[0,0,1],[0,1,1],[1,1,1],[1,0,1]], patches: [1, 1], "
        "reflectance: [0,0,0]}\n",
        "csr.yaml");
    const SceneGeometry g(s);
    const FormFactorOptions o;
    const FormFactors ff = compute_form_factors(g, o);
    const CacheKey key = form_factor_key(s, o);
    const fs::path d = fresh_dir("radiosa_trust_csr");
    write_cache_file(d / "f.rff", key, s.name, s.closed, g, ff);
    std::vector<std::uint8_t> b = test::read_bytes(d / "f.rff");
    const std::size_t at = patches_offset(b);  // then surfaces, element, layout, compression, ...
    auto u64_at = [&](std::size_t k) {
        std::uint64_t v = 0;
        for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(b[k + i]) << (8 * i);
        return v;
    };
    ASSERT_EQ(b[at + 20], 1);  // CSR
    const std::uint64_t stored = u64_at(at + 48), raw = u64_at(at + 56);
    const std::size_t section = b.size() - 8 - stored;
    std::vector<std::uint8_t> m(raw);
    if (b[at + 24] == 1)
        ASSERT_EQ(ZSTD_decompress(m.data(), m.size(), b.data() + section, stored), raw);
    else
        std::copy(b.begin() + section, b.begin() + section + stored, m.begin());
    const std::size_t n = 5, first_column = 8 * (n + 1);
    m[first_column] = static_cast<std::uint8_t>(n);  // row 0's first column: 5, one past the row
    m[first_column + 1] = m[first_column + 2] = m[first_column + 3] = 0;
    b.resize(section);
    b[at + 24] = 0;  // stored uncompressed
    put_u64(&b, at + 48, raw);
    b.insert(b.end(), m.begin(), m.end());
    b.resize(b.size() + 8);
    reseal(&b);
    try {
        read_cache_bytes(b, {key, &g, o, s.closed});
        FAIL() << "no error";
    } catch (const CacheFileError& e) {
        EXPECT_STREQ(e.what(), "sparse column index out of range");
    }
    fs::remove_all(d);
}

// Running out of memory is a message and exit code 2, never an abort.
TEST(CacheTrust, OutOfMemoryIsAMessage) {
    if (kAsan) GTEST_SKIP() << "ulimit -v cannot be combined with AddressSanitizer";
    const fs::path d = fresh_dir("radiosa_trust_oom");
    std::ofstream(d / "big.yaml") << "closed: false\nsurfaces:\n"
                                     "  - {name: a, type: quad, corners: [[0,0,0],[1,0,0],[1,1,0],[0,1,0]], "
                                     "patches: [100, 100], reflectance: [0.5, 0.5, 0.5]}\n"
                                     "  - {name: b, type: quad, corners: [[0,0,1],[0,1,1],[1,1,1],[1,0,1]], "
                                     "patches: [100, 100], reflectance: [0.5, 0.5, 0.5]}\n";
    const std::string cmd = std::string(RADIOSA_BINARY) + " formfactors " + (d / "big.yaml").string() +
                            " --no-cache 2> " + (d / "err").string();
    EXPECT_EQ(run_limited(cmd, 1000), 2);  // the dense matrix of 20,000 patches is 3.2 GB
    std::ifstream err(d / "err");
    const std::string text{std::istreambuf_iterator<char>(err), {}};
    EXPECT_EQ(text,
              "error: out of memory (the scene needs more than this machine or its limits allow; use fewer "
              "patches)\n");
    fs::remove_all(d);
}

}  // namespace radiosa
