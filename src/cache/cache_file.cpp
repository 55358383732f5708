#include "cache/cache_file.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <xxhash.h>
#include <zstd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "surfaces/registry.h"
#include "util/atomic_file.h"
#include "util/bytes.h"
#include "util/error.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'R', 'A', 'D', 'F', 'F', '\r', '\n', '\x1a'};
constexpr std::uint32_t kElementFloat64 = 1;
enum : std::uint32_t { kLayoutDense = 0, kLayoutCsr = 1 };
enum : std::uint32_t { kCompressNone = 0, kCompressZstd = 1 };
constexpr std::uint32_t kFlagErrors = 1;

std::uint64_t checksum(const std::uint8_t* data, std::size_t n) { return XXH3_64bits(data, n); }

std::string hex_bytes(const std::uint8_t* p, std::size_t n) {
    static const char* digits = "0123456789abcdef";
    std::string s;
    for (std::size_t i = 0; i < n; ++i) {
        s += digits[p[i] >> 4];
        s += digits[p[i] & 15];
    }
    return s;
}

// Everything in the file before the matrix section.
struct Header {
    CacheFileInfo info;
    std::uint32_t element = 0, layout = 0, compression = 0, flags = 0;
    std::uint64_t stored = 0, raw = 0;
};

Header read_header(ByteReader& in) {
    const std::uint8_t* magic = in.take(sizeof kMagic);
    if (std::memcmp(magic, kMagic, sizeof kMagic) != 0)
        throw CacheFileError("not a radiosa form-factor cache file (wrong magic bytes)");
    Header h;
    h.info.format_version = in.u32();
    if (h.info.format_version != kCacheFormatVersion)
        throw CacheFileError("file format version " + std::to_string(h.info.format_version) +
                             ", this build reads " + std::to_string(kCacheFormatVersion));
    h.info.algorithm_version = in.u32();
    if (h.info.algorithm_version != kFormFactorAlgorithmVersion)
        throw CacheFileError("computed by form-factor algorithm version " +
                             std::to_string(h.info.algorithm_version) + ", this build is version " +
                             std::to_string(kFormFactorAlgorithmVersion));
    std::memcpy(h.info.key.bytes.data(), in.take(16), 16);
    h.info.scene_name = in.str();
    h.info.patches = in.u64();
    h.info.surfaces = in.u64();
    h.element = in.u32();
    h.layout = in.u32();
    h.compression = in.u32();
    h.flags = in.u32();
    h.stored = in.u64();
    h.raw = in.u64();
    if (h.element != kElementFloat64)
        throw CacheFileError("unsupported element type " + std::to_string(h.element));
    if (h.layout > kLayoutCsr) throw CacheFileError("unknown matrix layout " + std::to_string(h.layout));
    if (h.compression > kCompressZstd)
        throw CacheFileError("unknown compression " + std::to_string(h.compression));
    if (h.info.patches > static_cast<std::uint64_t>(kMaxPatches) || h.info.surfaces > h.info.patches)
        throw CacheFileError("implausible patch count " + std::to_string(h.info.patches));
    h.info.layout = h.layout == kLayoutDense ? "dense" : "csr";
    h.info.compression = h.compression == kCompressZstd ? "zstd" : "none";
    h.info.has_error_estimates = (h.flags & kFlagErrors) != 0;
    return h;
}

std::vector<std::uint8_t> read_all(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw CacheFileError("cannot be opened");
    in.seekg(0, std::ios::end);
    const auto size = static_cast<std::size_t>(in.tellg());
    in.seekg(0);
    std::vector<std::uint8_t> bytes(size);
    if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size)))
        throw CacheFileError("read failed");
    return bytes;
}

void write_bytes(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
    check_output_path(path);
    AtomicFile file(path);
    std::FILE* f = std::fopen(file.temp_path().c_str(), "wb");
    if (!f) throw Error(path.string() + ": cannot create temporary file: " + std::strerror(errno));
    const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size() && std::fflush(f) == 0 &&
                    ::fsync(::fileno(f)) == 0;
    const int saved = errno;
    if (std::fclose(f) != 0 || !ok)
        throw Error(path.string() + ": write failed: " + std::strerror(ok ? errno : saved));
    file.commit();
}

}  // namespace

std::string CacheKey::hex() const { return hex_bytes(bytes.data(), bytes.size()); }

CacheKey form_factor_key(const Scene& scene, const FormFactorOptions& options) {
    ByteWriter w;
    w.str("radiosa form factors");
    w.u32(kFormFactorAlgorithmVersion);
    w.u32(kElementFloat64);
    // The method: error-controlled with its tolerance (and order 0), or the fixed rule with
    // its order (and tolerance 0).
    const bool adaptive = options.method == FormFactorMethod::Adaptive;
    w.f64(adaptive ? options.tolerance : 0.0);
    w.u32(static_cast<std::uint32_t>(adaptive ? 0 : options.gauss_points));
    w.u32(options.visibility ? 1 : 0);
    w.u64(scene.surfaces.size());
    for (const SurfaceDesc& s : scene.surfaces) {
        w.u32(s.type->key_id);
        s.shape->write_key(w);
        w.u32(static_cast<std::uint32_t>(s.ns));
        w.u32(static_cast<std::uint32_t>(s.nt));
    }
    const XXH128_hash_t h = XXH3_128bits(w.bytes().data(), w.bytes().size());
    XXH128_canonical_t canon;
    XXH128_canonicalFromHash(&canon, h);
    CacheKey key;
    std::memcpy(key.bytes.data(), canon.digest, 16);
    return key;
}

void write_cache_file(const fs::path& path, const CacheKey& key, const std::string& scene_name,
                      const SceneGeometry& geometry, const FormFactors& ff) {
    const std::size_t n = static_cast<std::size_t>(ff.F.n);
    std::size_t nnz = 0;
    for (double v : ff.F.data) nnz += v != 0.0;
    const bool csr = 8 * (n + 1) + 12 * nnz < 8 * n * n;
    const bool errors = !ff.error.empty();

    ByteWriter m;  // the matrix section
    if (csr) {
        std::uint64_t start = 0;
        m.u64(0);
        for (std::size_t i = 0; i < n; ++i) {
            for (std::size_t j = 0; j < n; ++j) start += ff.F.data[i * n + j] != 0.0;
            m.u64(start);
        }
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = 0; j < n; ++j)
                if (ff.F.data[i * n + j] != 0.0) m.u32(static_cast<std::uint32_t>(j));
        for (double v : ff.F.data)
            if (v != 0.0) m.f64(v);
    } else {
        m.f64_array(ff.F.data.data(), ff.F.data.size());
    }
    if (errors) m.f64_array(ff.error.data(), ff.error.size());
    const std::uint64_t raw = m.bytes().size();

    std::vector<std::uint8_t> packed(ZSTD_compressBound(raw));
    const std::size_t psize = ZSTD_compress(packed.data(), packed.size(), m.bytes().data(), raw, 3);
    const bool zstd = !ZSTD_isError(psize) && psize * 4 <= raw * 3;
    if (zstd) packed.resize(psize);
    const std::vector<std::uint8_t>& section = zstd ? packed : m.bytes();

    ByteWriter w;
    w.raw(kMagic, sizeof kMagic);
    w.u32(kCacheFormatVersion);
    w.u32(kFormFactorAlgorithmVersion);
    w.raw(key.bytes.data(), 16);
    w.str(scene_name);
    w.u64(n);
    w.u64(static_cast<std::uint64_t>(geometry.surface_count()));
    w.u32(kElementFloat64);
    w.u32(csr ? kLayoutCsr : kLayoutDense);
    w.u32(zstd ? kCompressZstd : kCompressNone);
    w.u32(errors ? kFlagErrors : 0);
    w.u64(section.size());
    w.u64(raw);
    for (int k = 0; k < geometry.surface_count(); ++k) {
        w.str(geometry.surface_name(k));
        w.u32(static_cast<std::uint32_t>(geometry.ns(k)));
        w.u32(static_cast<std::uint32_t>(geometry.nt(k)));
    }
    for (const Patch& p : geometry.patches()) {
        w.u32(static_cast<std::uint32_t>(p.surface));
        w.u32(static_cast<std::uint32_t>(p.is));
        w.u32(static_cast<std::uint32_t>(p.it));
        w.f64(p.area);
    }
    const bool adaptive = ff.options.method == FormFactorMethod::Adaptive;
    w.u32(static_cast<std::uint32_t>(adaptive ? 0 : ff.options.gauss_points));
    w.f64(adaptive ? ff.options.tolerance : 0.0);
    ff.stats.for_each_counter([&](const char*, long long v) { w.i64(v); });
    w.raw(section.data(), section.size());
    w.u64(checksum(w.bytes().data(), w.bytes().size()));
    write_bytes(path, w.bytes());
}

CacheFileInfo read_cache_info(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw CacheFileError("cannot be opened");
    std::vector<std::uint8_t> head(4096);
    in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
    ByteReader r(head.data(), static_cast<std::size_t>(in.gcount()));
    try {
        return read_header(r).info;
    } catch (const ByteReader::Truncated&) {
        throw CacheFileError("file is truncated");
    }
}

namespace {

CacheFileError table_mismatch(const std::string& what) {
    return CacheFileError("patch table does not match the scene: " + what);
}

// The per-surface subdivision; with `geometry`, it must be the scene's.
void read_surface_table(ByteReader& in, const Header& h, const SceneGeometry* geometry,
                        std::vector<std::uint32_t>* ns, std::vector<std::uint32_t>* nt) {
    ns->resize(h.info.surfaces);
    nt->resize(h.info.surfaces);
    for (std::size_t k = 0; k < h.info.surfaces; ++k) {
        in.str();  // the surface's name: for `cache list`, not checked
        (*ns)[k] = in.u32();
        (*nt)[k] = in.u32();
    }
    if (!geometry) return;
    const std::size_t n = h.info.patches;
    if (static_cast<std::size_t>(geometry->patch_count()) != n)
        throw table_mismatch(std::to_string(n) + " patches, the scene has " +
                             std::to_string(geometry->patch_count()));
    if (static_cast<std::size_t>(geometry->surface_count()) != h.info.surfaces)
        throw table_mismatch(std::to_string(h.info.surfaces) + " surfaces, the scene has " +
                             std::to_string(geometry->surface_count()));
    for (std::size_t k = 0; k < h.info.surfaces; ++k)
        if ((*ns)[k] != static_cast<std::uint32_t>(geometry->ns(static_cast<int>(k))) ||
            (*nt)[k] != static_cast<std::uint32_t>(geometry->nt(static_cast<int>(k))))
            throw table_mismatch("surface " + std::to_string(k) + " is split differently");
}

// Each patch's surface, indices and area; with `geometry`, they must be the scene's.
void read_patch_table(ByteReader& in, const Header& h, const SceneGeometry* geometry, FormFactors* ff) {
    std::vector<std::uint32_t> ns, nt;
    read_surface_table(in, h, geometry, &ns, &nt);
    for (std::size_t i = 0; i < h.info.patches; ++i) {
        const std::uint32_t s = in.u32(), is = in.u32(), it = in.u32();
        const double area = ff->area[i] = in.f64();
        if (s >= h.info.surfaces || is >= ns[s] || it >= nt[s] || !(area > 0.0) || !std::isfinite(area))
            throw CacheFileError("patch table entry " + std::to_string(i) + " is invalid");
        if (!geometry) continue;
        const Patch& p = geometry->patch(static_cast<int>(i));
        if (static_cast<int>(s) != p.surface || static_cast<int>(is) != p.is ||
            static_cast<int>(it) != p.it || std::abs(area - p.area) > 1e-12 * p.area)
            throw table_mismatch("patch " + std::to_string(i) + " differs");
    }
}

// The matrix section, decompressed when it is compressed.
std::vector<std::uint8_t> unpack_section(ByteReader& in, const Header& h, std::size_t n) {
    const std::uint8_t* sec = in.take(h.stored);
    if (h.compression != kCompressZstd) return {sec, sec + h.stored};
    if (h.raw > 16 * n * n + 8 * (n + 1) + 64) throw CacheFileError("implausible uncompressed size");
    std::vector<std::uint8_t> unpacked(h.raw);
    const std::size_t got = ZSTD_decompress(unpacked.data(), unpacked.size(), sec, h.stored);
    if (ZSTD_isError(got) || got != h.raw) throw CacheFileError("compressed matrix does not decompress");
    return unpacked;
}

void read_csr(ByteReader& m, std::size_t n, DenseMatrix* F) {
    std::vector<std::uint64_t> start(n + 1);
    for (auto& v : start) v = m.u64();
    const std::uint64_t nnz = start[n];
    for (std::size_t i = 0; i < n; ++i)
        if (start[i] > start[i + 1]) throw CacheFileError("sparse row table is not increasing");
    if (start[0] != 0 || nnz > n * n || m.remaining() < 12 * nnz)
        throw CacheFileError("sparse matrix sizes are inconsistent");
    std::vector<std::uint32_t> col(nnz);
    for (auto& c : col) c = m.u32();
    for (std::size_t i = 0; i < n; ++i)
        for (std::uint64_t k = start[i]; k < start[i + 1]; ++k) {
            if (col[k] >= n) throw CacheFileError("sparse column index out of range");
            (*F)(static_cast<int>(i), static_cast<int>(col[k])) = m.f64();
        }
}

void read_matrix(ByteReader& in, const Header& h, FormFactors* ff) {
    const std::size_t n = h.info.patches;
    const std::vector<std::uint8_t> section = unpack_section(in, h, n);
    ByteReader m(section.data(), section.size());
    if (h.layout == kLayoutDense)
        m.f64_array(ff->F.data.data(), n * n);
    else
        read_csr(m, n, &ff->F);
    if (h.info.has_error_estimates) {
        ff->error.resize(n * n);
        m.f64_array(ff->error.data(), n * n);
    }
    if (m.remaining() != 0) throw CacheFileError("matrix section has trailing bytes");
    for (std::size_t k = 0; k < n * n; ++k)
        if (!(ff->F.data[k] >= 0.0) || !std::isfinite(ff->F.data[k]))
            throw CacheFileError("entry (" + std::to_string(k / n) + "," + std::to_string(k % n) +
                                 ") is negative or not finite");
}

}  // namespace

FormFactors read_cache_file(const fs::path& path, const std::optional<CacheKey>& expected_key,
                            const SceneGeometry* geometry, CacheFileInfo* info_out) {
    const std::vector<std::uint8_t> bytes = read_all(path);
    try {
        ByteReader in(bytes.data(), bytes.size());
        const Header h = read_header(in);
        if (bytes.size() < in.pos() + 8) throw ByteReader::Truncated();
        const std::size_t body = bytes.size() - 8;
        ByteReader trailer(bytes.data() + body, 8);
        if (trailer.u64() != checksum(bytes.data(), body))
            throw CacheFileError("checksum mismatch (the file is damaged or truncated)");
        if (expected_key && h.info.key != *expected_key)
            throw CacheFileError("holds key " + h.info.key.hex() + ", not this scene's " +
                                 expected_key->hex() + " (a file from another scene or settings)");
        if (info_out) *info_out = h.info;

        FormFactors ff;
        ff.F = DenseMatrix(static_cast<int>(h.info.patches));
        ff.area.resize(h.info.patches);
        read_patch_table(in, h, geometry, &ff);
        const int gauss_points = static_cast<int>(in.u32());
        const double tolerance = in.f64();
        ff.options = gauss_points > 0 ? FormFactorOptions::gauss(gauss_points)
                                      : FormFactorOptions::adaptive(tolerance);
        ff.stats.for_each_counter([&](const char*, long long& v) { v = in.i64(); });
        if (h.stored != in.remaining() - 8)
            throw CacheFileError("matrix section is " + std::to_string(in.remaining() - 8) +
                                 " bytes, header says " + std::to_string(h.stored));
        read_matrix(in, h, &ff);
        return ff;
    } catch (const ByteReader::Truncated&) {
        throw CacheFileError("file is truncated (" + std::to_string(bytes.size()) + " bytes)");
    }
}

// ---- policy ----

fs::path default_cache_dir() {
    const char* env = std::getenv("RADIOSA_CACHE_DIR");
    if (env && *env) return fs::path(env);
    return fs::path("out") / "cache";
}

const char* cache_status_name(CacheStatus s) {
    switch (s) {
        case CacheStatus::Off:
            return "off";
        case CacheStatus::Hit:
            return "hit";
        case CacheStatus::Miss:
            return "miss";
        case CacheStatus::Rebuilt:
            return "rebuilt";
    }
    return "?";
}

namespace {

// An exclusive advisory lock on "<key>.lock" for as long as it lives, so that concurrent runs
// of one scene compute its matrix once: the others wait, then load the file. The lock file is
// removed on release. Correctness never depends on the lock: files appear only by atomic
// rename and are fully checked on load, so when the lock cannot be had (unwritable directory,
// or the rare race with the removal) concurrent runs merely compute twice.
class KeyLock {
public:
    explicit KeyLock(fs::path path) : m_path(std::move(path)) {
        m_fd = ::open(m_path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
        if (m_fd >= 0 && ::flock(m_fd, LOCK_EX) != 0) {
            ::close(m_fd);
            m_fd = -1;
        }
    }
    ~KeyLock() {
        if (m_fd < 0) return;
        ::unlink(m_path.c_str());
        ::close(m_fd);  // closing releases the lock
    }
    KeyLock(const KeyLock&) = delete;
    KeyLock& operator=(const KeyLock&) = delete;

private:
    fs::path m_path;
    int m_fd = -1;
};

}  // namespace

namespace {

// One run's use of the cache for one matrix: what it loaded, computed and wrote, and why.
class CacheRun {
public:
    CacheRun(const Scene& scene, const SceneGeometry& geometry, const FormFactorOptions& options,
             const WarningSink& warn)
        : m_scene(scene), m_geometry(geometry), m_options(options), m_warn(warn) {}

    CacheOutcome o;

    FormFactors compute() {
        const Stopwatch clock;
        FormFactors ff = compute_form_factors(m_geometry, m_options);
        o.compute_s = clock.seconds();
        return ff;
    }
    // The matrix when the file exists and is sound; records why not otherwise.
    std::optional<FormFactors> try_load(const fs::path& path, const CacheKey& key) {
        const Stopwatch clock;
        std::error_code ec;
        if (!fs::exists(path, ec)) return std::nullopt;
        try {
            FormFactors ff = read_cache_file(path, key, &m_geometry);
            o.load_s += clock.seconds();
            return ff;
        } catch (const CacheFileError& e) {
            o.load_s += clock.seconds();
            o.reason = e.what();
            return std::nullopt;
        }
    }
    // Computes the matrix and writes its file; an unwritable cache is a warning, not an error.
    FormFactors compute_and_store(const fs::path& path, const CacheKey& key) {
        o.status = o.reason.empty() ? CacheStatus::Miss : CacheStatus::Rebuilt;
        FormFactors ff = compute();
        const Stopwatch clock;
        try {
            write_cache_file(path, key, m_scene.name, m_geometry, ff);
            o.written = true;
        } catch (const Error& e) {
            m_warn(std::string("cannot write the form-factor cache: ") + e.what() +
                   "; the run goes on without it");
            if (o.reason.empty()) o.reason = std::string("not written: ") + e.what();
        }
        o.write_s = clock.seconds();
        return ff;
    }
    // Computes without storing: the cache directory cannot be made.
    FormFactors compute_unstored(const fs::path& dir, const std::error_code& ec) {
        o.status = o.reason.empty() ? CacheStatus::Miss : CacheStatus::Rebuilt;
        const std::string why = "cannot create cache directory " + dir.string() + ": " +
                                (ec ? ec.message() : std::string("not a directory"));
        m_warn(why + "; form factors are computed but not cached");
        if (o.reason.empty()) o.reason = why;
        return compute();
    }

private:
    const Scene& m_scene;
    const SceneGeometry& m_geometry;
    const FormFactorOptions& m_options;
    const WarningSink& m_warn;
};

FormFactors obtain(CacheRun& run, const Scene& scene, const FormFactorOptions& options,
                   const CacheSettings& settings, const WarningSink& warn) {
    if (!settings.enabled) return run.compute();
    if (!options.culling) {
        // A timing diagnostic: it must be computed to be timed, and in error-controlled mode
        // (no closed form without the proofs) its matrix is less accurate: never stored.
        run.o.reason = "--no-culling";
        return run.compute();
    }
    const fs::path dir = settings.dir.empty() ? default_cache_dir() : settings.dir;
    const CacheKey key = form_factor_key(scene, options);
    const fs::path path = dir / (key.hex() + ".rff");
    run.o.key = key.hex();
    run.o.file = path.string();

    if (auto ff = run.try_load(path, key)) {
        run.o.status = CacheStatus::Hit;
        return std::move(*ff);
    }
    if (!run.o.reason.empty()) warn("cache file " + path.string() + ": " + run.o.reason + "; recomputing it");
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir, ec)) return run.compute_unstored(dir, ec);

    const Stopwatch waited;
    const KeyLock lock(dir / (key.hex() + ".lock"));
    run.o.wait_s = waited.seconds();
    // Another process may have computed it while this one waited for the lock.
    const std::string first_reason = run.o.reason;
    if (auto ff = run.try_load(path, key)) {
        run.o.status = CacheStatus::Hit;
        run.o.reason.clear();
        return std::move(*ff);
    }
    if (run.o.reason.empty()) run.o.reason = first_reason;
    return run.compute_and_store(path, key);
}

}  // namespace

FormFactors obtain_form_factors(const Scene& scene, const SceneGeometry& geometry,
                                const FormFactorOptions& options, const CacheSettings& settings,
                                const WarningSink& warn, CacheOutcome* outcome) {
    CacheRun run(scene, geometry, options, warn);
    FormFactors ff = obtain(run, scene, options, settings, warn);
    if (outcome) *outcome = run.o;
    return ff;
}

}  // namespace radiosa
