#include "cache/cache_file.h"

#include <zstd.h>

#include <cmath>
#include <cstring>

#include "cache/cache_format.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "surfaces/registry.h"
#include "util/atomic_file.h"
#include "util/bytes.h"
#include "util/error.h"

namespace radiosa {

namespace fs = std::filesystem;
using namespace cache_format;

namespace {

std::string hex_bytes(const std::uint8_t* p, std::size_t n) {
    static const char* digits = "0123456789abcdef";
    std::string s;
    for (std::size_t i = 0; i < n; ++i) {
        s += digits[p[i] >> 4];
        s += digits[p[i] & 15];
    }
    return s;
}

// The matrix section: CSR or dense, whichever is smaller, then the estimates.
std::vector<std::uint8_t> matrix_section(const FormFactors& ff, bool* csr) {
    const std::size_t n = static_cast<std::size_t>(ff.F.n);
    std::size_t nnz = 0;
    for (double v : ff.F.data) nnz += v != 0.0;
    *csr = 8 * (n + 1) + 12 * nnz < 8 * n * n;
    ByteWriter m;
    if (*csr) {
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
    if (!ff.error.empty()) m.f64_array(ff.error.data(), ff.error.size());
    return std::move(m.bytes());
}

void write_header(ByteWriter& w, const CacheKey& key, const std::string& scene_name,
                  const SceneGeometry& geometry, const FormFactors& ff) {
    w.raw(kMagic, sizeof kMagic);
    w.u32(kCacheFormatVersion);
    w.u32(kFormFactorAlgorithmVersion);
    w.raw(key.bytes.data(), 16);
    w.str(capped_name(scene_name));
    w.u64(static_cast<std::uint64_t>(ff.F.n));
    w.u64(static_cast<std::uint64_t>(geometry.surface_count()));
    w.u32(kElementFloat64);
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
    if (options.one_direction) w.str("one direction");        // absent: the keys of earlier builds
    if (options.numeric_lines) w.str("numeric inner lines");  // likewise
    w.u64(scene.surfaces.size());
    for (const SurfaceDesc& s : scene.surfaces) {
        w.u32(s.type->key_id);
        s.shape->write_key(w);
        w.u32(static_cast<std::uint32_t>(s.ns));
        w.u32(static_cast<std::uint32_t>(s.nt));
    }
    return hash_key(w.bytes());
}

void write_cache_file(const fs::path& path, const CacheKey& key, const std::string& scene_name, bool closed,
                      const SceneGeometry& geometry, const FormFactors& ff) {
    bool csr = false;
    std::vector<std::uint8_t> raw = matrix_section(ff, &csr);
    const std::uint64_t raw_size = raw.size();
    bool zstd = false;
    const std::vector<std::uint8_t> section = pack_section(std::move(raw), &zstd);

    const bool adaptive = ff.options.method == FormFactorMethod::Adaptive;
    ByteWriter w;
    write_header(w, key, scene_name, geometry, ff);
    w.u32(csr ? kLayoutCsr : kLayoutDense);
    w.u32(zstd ? kCompressZstd : kCompressNone);
    w.u32((ff.error.empty() ? 0 : kFlagErrors) | (ff.options.visibility ? kFlagVisibility : 0) |
          (closed ? kFlagClosed : 0));
    w.u32(adaptive ? kMethodAdaptive : kMethodFixed);
    w.u32(static_cast<std::uint32_t>(adaptive ? 0 : ff.options.gauss_points));
    w.f64(adaptive ? ff.options.tolerance : 0.0);
    w.u64(section.size());
    w.u64(raw_size);
    write_table(w, geometry, ff.stats);
    w.raw(section.data(), section.size());
    commit_file(path, w);
}

CacheFileInfo read_cache_info(const fs::path& path) {
    const FileSource src(path);
    const Header h = read_source_header(src);
    check_sizes(h, src.size());
    return h.info;
}

namespace {

// The header against the scene and the request: before anything else is read or allocated.
void check_expectation(const Header& h, const CacheExpectation& expect) {
    const CacheFileInfo& info = h.info;
    if (info.key != expect.key)
        throw CacheFileError("holds key " + info.key.hex() + ", not this scene's " + expect.key.hex() +
                             " (a file from another scene or settings)");
    const SceneGeometry& g = *expect.geometry;
    if (info.patches != static_cast<std::uint64_t>(g.patch_count()))
        throw table_mismatch(std::to_string(info.patches) + " patches, the scene has " +
                             std::to_string(g.patch_count()));
    if (info.surfaces != static_cast<std::uint64_t>(g.surface_count()))
        throw table_mismatch(std::to_string(info.surfaces) + " surfaces, the scene has " +
                             std::to_string(g.surface_count()));
    const FormFactorOptions& o = info.options;
    const FormFactorOptions& want = expect.options;
    const bool adaptive = want.method == FormFactorMethod::Adaptive;
    if (o.method != want.method || o.visibility != want.visibility ||
        (adaptive ? o.tolerance != want.tolerance : o.gauss_points != want.gauss_points))
        throw CacheFileError("was computed " + describe(o) + ", visibility " + (o.visibility ? "on" : "off") +
                             "; this run asks for " + describe(want) + ", visibility " +
                             (want.visibility ? "on" : "off"));
    if (info.closed != expect.closed)
        throw CacheFileError(std::string("says the scene is ") + (info.closed ? "closed" : "open") +
                             "; this scene is " + (expect.closed ? "closed" : "open"));
}

// The matrix section, decompressed into a buffer the header's (already bounded) size fixes.
std::vector<std::uint8_t> unpack_section(ByteReader& in, const Header& h) {
    const std::uint8_t* sec = in.take(h.stored);
    if (h.compression != kCompressZstd) return {sec, sec + h.stored};
    const unsigned long long content = ZSTD_getFrameContentSize(sec, h.stored);
    if (content != h.raw) throw CacheFileError("compressed matrix does not say it holds the header's size");
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
    const std::vector<std::uint8_t> section = unpack_section(in, h);
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
}

FormFactors read_source(const Source& src, const CacheExpectation& expect, CacheFileInfo* info_out) {
    const Header h = read_source_header(src);
    check_expectation(h, expect);
    check_sizes(h, src.size());
    // Every size is now bounded by the file's and by the scene's matrix: read it all.
    const std::vector<std::uint8_t> bytes = read_checked(src);
    ByteReader in(bytes.data(), bytes.size() - 8);
    in.take(h.length);
    FormFactors ff;
    ff.options = h.info.options;
    ff.F = DenseMatrix(static_cast<int>(h.info.patches));
    ff.area.resize(h.info.patches);
    read_patch_table(in, h, *expect.geometry, &ff.area, &ff.stats);
    if (in.remaining() != h.stored)
        throw CacheFileError("matrix section is " + std::to_string(in.remaining()) + " bytes, header says " +
                             std::to_string(h.stored));
    read_matrix(in, h, &ff);
    check_cache_matrix(ff, h.info.options, h.info.closed);
    if (info_out) *info_out = h.info;
    return ff;
}

}  // namespace

FormFactors read_cache_bytes(std::span<const std::uint8_t> bytes, const CacheExpectation& expect,
                             CacheFileInfo* info) {
    try {
        return read_source(MemorySource(bytes), expect, info);
    } catch (const ByteReader::Truncated&) {
        throw CacheFileError("file is truncated (" + std::to_string(bytes.size()) + " bytes)");
    }
}

FormFactors read_cache_file(const fs::path& path, const CacheExpectation& expect, CacheFileInfo* info) {
    const FileSource src(path);
    try {
        return read_source(src, expect, info);
    } catch (const ByteReader::Truncated&) {
        throw CacheFileError("file is truncated (" + std::to_string(src.size()) + " bytes)");
    }
}

}  // namespace radiosa
