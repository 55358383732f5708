#include "cache/cache_format.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>
#include <zstd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace radiosa::cache_format {

namespace {

std::string what_it_is(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
    if (S_ISSOCK(mode)) return "a socket";
    if (S_ISLNK(mode)) return "a symbolic link";
    return "not a regular file";
}

void read_method(ByteReader& in, Header& h, std::uint32_t flags) {
    const std::uint32_t method = in.u32();
    const std::uint32_t gauss_points = in.u32();
    const double tolerance = in.f64();
    if (method == kMethodFixed && gauss_points >= 1 && gauss_points <= 64)
        h.info.options = FormFactorOptions::gauss(static_cast<int>(gauss_points));
    else if (method == kMethodAdaptive && gauss_points == 0 && tolerance >= 1e-12 && tolerance <= 0.1)
        h.info.options = FormFactorOptions::adaptive(tolerance);
    else
        throw CacheFileError("implausible form-factor method " + std::to_string(method));
    h.info.options.visibility = (flags & kFlagVisibility) != 0;
    h.info.closed = (flags & kFlagClosed) != 0;
}

}  // namespace

Header read_header(ByteReader& in) {
    if (std::memcmp(in.take(sizeof kMagic), kMagic, sizeof kMagic) != 0)
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
    if (in.peek_u32() > kMaxName) throw CacheFileError("implausible scene name length");
    h.info.scene_name = in.str();
    h.info.patches = in.u64();
    h.info.surfaces = in.u64();
    const std::uint32_t element = in.u32();
    h.layout = in.u32();
    h.compression = in.u32();
    const std::uint32_t flags = in.u32();
    read_method(in, h, flags);
    h.stored = in.u64();
    h.raw = in.u64();
    h.length = in.pos();
    if (element != kElementFloat64)
        throw CacheFileError("unsupported element type " + std::to_string(element));
    if (h.layout > kLayoutCsr) throw CacheFileError("unknown matrix layout " + std::to_string(h.layout));
    if (h.compression > kCompressZstd)
        throw CacheFileError("unknown compression " + std::to_string(h.compression));
    if (flags > (kFlagErrors | kFlagVisibility | kFlagClosed))
        throw CacheFileError("unknown flags " + std::to_string(flags));
    if (h.info.patches == 0 || h.info.patches > static_cast<std::uint64_t>(kMaxDensePatches) ||
        h.info.surfaces == 0 || h.info.surfaces > h.info.patches)
        throw CacheFileError("implausible patch count " + std::to_string(h.info.patches));
    h.info.layout = h.layout == kLayoutDense ? "dense" : "csr";
    h.info.compression = h.compression == kCompressZstd ? "zstd" : "none";
    h.info.has_error_estimates = (flags & kFlagErrors) != 0;
    if (h.info.has_error_estimates != (h.info.options.method == FormFactorMethod::Adaptive))
        throw CacheFileError("error estimates do not match the method");
    return h;
}

std::uint64_t max_raw_size(std::uint64_t n, std::uint32_t layout, bool errors) {
    const std::uint64_t values = layout == kLayoutDense ? 8 * n * n : 8 * (n + 1) + 12 * n * n;
    return values + (errors ? 8 * n * n : 0);
}

std::uint64_t min_table_size(const Header& h) {
    std::uint64_t counters = 0;  // as many as FormFactorStats lists, i64 each
    FormFactorStats().for_each_counter([&](const char*, long long) { ++counters; });
    return 12 * h.info.surfaces + 20 * h.info.patches + 8 * counters;
}

std::uint64_t max_table_size(const Header& h) { return min_table_size(h) + kMaxName * h.info.surfaces; }

void check_sizes(const Header& h, std::uint64_t size) {
    const std::uint64_t n = h.info.patches;
    if (h.raw > max_raw_size(n, h.layout, h.info.has_error_estimates))
        throw CacheFileError("matrix section of " + std::to_string(h.raw) + " bytes is larger than " +
                             std::to_string(n) + " patches can need");
    if (h.compression == kCompressNone && h.stored != h.raw)
        throw CacheFileError("uncompressed matrix section sizes disagree");
    if (h.compression == kCompressZstd && h.stored > h.raw + h.raw / 64 + 1024)
        throw CacheFileError("compressed matrix section is larger than its content could need");
    const std::uint64_t body = size - h.length;  // read_header consumed h.length <= size bytes
    if (h.stored > body || min_table_size(h) + 8 > body - h.stored)
        throw CacheFileError("file is truncated (" + std::to_string(size) +
                             " bytes, the header promises more)");
    if (body - h.stored - 8 > max_table_size(h))
        throw CacheFileError("file is " + std::to_string(size) + " bytes, more than its header accounts for");
}

std::vector<std::uint8_t> Source::read_vector(std::uint64_t offset, std::size_t n) const {
    std::vector<std::uint8_t> v(n);
    read(offset, v.data(), n);
    return v;
}

FileSource::FileSource(const std::filesystem::path& path) {
    // O_NONBLOCK: opening a FIFO returns at once instead of waiting for a writer.
    m_fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (m_fd < 0) {
        if (errno == ELOOP) throw CacheFileError("is a symbolic link, not a regular file");
        throw CacheFileError(std::string("cannot be opened: ") + std::strerror(errno));
    }
    struct stat st {};
    if (::fstat(m_fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        const std::string kind = what_it_is(st.st_mode);
        ::close(m_fd);
        m_fd = -1;
        throw CacheFileError("is " + kind + ", not a regular file");
    }
    m_size = static_cast<std::uint64_t>(st.st_size);
}

FileSource::~FileSource() {
    if (m_fd >= 0) ::close(m_fd);
}

void FileSource::read(std::uint64_t offset, void* dst, std::size_t n) const {
    auto* p = static_cast<char*>(dst);
    while (n > 0) {
        const ssize_t got = ::pread(m_fd, p, n, static_cast<off_t>(offset));
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) throw CacheFileError(std::string("read failed: ") + std::strerror(errno));
        if (got == 0) throw CacheFileError("file is truncated (it shrank while being read)");
        p += got;
        offset += static_cast<std::uint64_t>(got);
        n -= static_cast<std::size_t>(got);
    }
}

void MemorySource::read(std::uint64_t offset, void* dst, std::size_t n) const {
    if (offset > m_bytes.size() || n > m_bytes.size() - offset) throw CacheFileError("file is truncated");
    if (n > 0) std::memcpy(dst, m_bytes.data() + offset, n);
}

Header read_source_header(const Source& src) {
    return parse_head(src, [](ByteReader& in) { return read_header(in); });
}

std::vector<std::uint8_t> read_checked(const Source& src) {
    std::vector<std::uint8_t> bytes = src.read_vector(0, static_cast<std::size_t>(src.size()));
    const std::size_t body = bytes.size() - 8;
    ByteReader trailer(bytes.data() + body, 8);
    if (trailer.u64() != XXH3_64bits(bytes.data(), body))
        throw CacheFileError("checksum mismatch (the file is damaged or truncated)");
    return bytes;
}

CacheKey hash_key(const std::vector<std::uint8_t>& bytes) {
    const XXH128_hash_t h = XXH3_128bits(bytes.data(), bytes.size());
    XXH128_canonical_t canon;
    XXH128_canonicalFromHash(&canon, h);
    CacheKey key;
    std::memcpy(key.bytes.data(), canon.digest, 16);
    return key;
}

std::vector<std::uint8_t> pack_section(std::vector<std::uint8_t> raw, bool* zstd) {
    std::vector<std::uint8_t> packed(ZSTD_compressBound(raw.size()));
    const std::size_t psize = ZSTD_compress(packed.data(), packed.size(), raw.data(), raw.size(), 3);
    *zstd = !ZSTD_isError(psize) && psize * 4 <= raw.size() * 3;
    if (!*zstd) return raw;
    packed.resize(psize);
    return packed;
}

void commit_file(const std::filesystem::path& path, ByteWriter& w) {
    w.u64(XXH3_64bits(w.bytes().data(), w.bytes().size()));
    check_output_path(path);
    AtomicFile file(path);
    file.write_all(w.bytes().data(), w.bytes().size());
    file.close_fd(true);
    file.commit();
}

namespace {

// Writes all of `bytes` at `offset` of fd; throws Error naming `path`.
void write_at(int fd, const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes,
              off_t offset) {
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n =
            ::pwrite(fd, bytes.data() + done, bytes.size() - done, offset + static_cast<off_t>(done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw Error(path.string() + ": write failed: " + std::strerror(n < 0 ? errno : ENOSPC));
        done += static_cast<std::size_t>(n);
    }
}

// The XXH3-64 of a file's bytes, read back in chunks.
std::uint64_t file_checksum(const std::filesystem::path& temp, const std::filesystem::path& final_path) {
    const int fd = ::open(temp.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) throw Error(final_path.string() + ": cannot read back: " + std::strerror(errno));
    std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state(XXH3_createState(), XXH3_freeState);
    XXH3_64bits_reset(state.get());
    std::vector<std::uint8_t> buf(kChunk);
    for (;;) {
        const ssize_t n = ::read(fd, buf.data(), buf.size());
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            const int saved = errno;
            ::close(fd);
            throw Error(final_path.string() + ": cannot read back: " + std::strerror(saved));
        }
        if (n == 0) break;
        XXH3_64bits_update(state.get(), buf.data(), static_cast<std::size_t>(n));
    }
    ::close(fd);
    return XXH3_64bits_digest(state.get());
}

}  // namespace

void commit_streamed(const std::filesystem::path& path, std::uint64_t raw,
                     const std::function<std::vector<std::uint8_t>(std::uint64_t stored)>& head,
                     const std::function<std::size_t(std::uint8_t* dst, std::size_t cap)>& produce) {
    check_output_path(path);
    AtomicFile file(path);
    const std::size_t head_size = head(0).size();
    if (::lseek(file.fd(), static_cast<off_t>(head_size), SEEK_SET) < 0)
        throw Error(path.string() + ": seek failed: " + std::strerror(errno));
    std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)> cctx(ZSTD_createCCtx(), ZSTD_freeCCtx);
    if (!cctx) throw Error(path.string() + ": zstd has no memory for a compression context");
    ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_compressionLevel, 3);
    ZSTD_CCtx_setPledgedSrcSize(cctx.get(), raw);
    std::vector<std::uint8_t> in(kChunk), out(ZSTD_CStreamOutSize());
    std::uint64_t fed = 0, stored = 0;
    for (bool end = false; !end;) {
        const std::size_t n = produce(in.data(), in.size());
        fed += n;
        end = n == 0;
        if (fed > raw || (end && fed != raw))
            throw std::logic_error("commit_streamed: the section was not its announced size");
        ZSTD_inBuffer ib{in.data(), n, 0};
        for (bool flushed = false; !flushed;) {
            ZSTD_outBuffer ob{out.data(), out.size(), 0};
            const std::size_t left =
                ZSTD_compressStream2(cctx.get(), &ob, &ib, end ? ZSTD_e_end : ZSTD_e_continue);
            if (ZSTD_isError(left)) throw Error(path.string() + ": zstd: " + ZSTD_getErrorName(left));
            file.write_all(out.data(), ob.pos);
            stored += ob.pos;
            flushed = end ? left == 0 : ib.pos == ib.size;
        }
    }
    const std::vector<std::uint8_t> bytes = head(stored);
    if (bytes.size() != head_size) throw std::logic_error("commit_streamed: the head changed size");
    write_at(file.fd(), path, bytes, 0);
    ByteWriter trailer;
    trailer.u64(file_checksum(file.temp_path(), path));
    file.write_all(trailer.bytes().data(), trailer.bytes().size());
    file.close_fd(true);
    file.commit();
}

std::string capped_name(const std::string& s) { return s.size() <= kMaxName ? s : s.substr(0, kMaxName); }

CacheFileError table_mismatch(const std::string& what) {
    return CacheFileError("patch table does not match the scene: " + what);
}

void write_table(ByteWriter& w, const SceneGeometry& geometry, const FormFactorStats& stats) {
    for (int k = 0; k < geometry.surface_count(); ++k) {
        w.str(capped_name(geometry.surface_name(k)));
        w.u32(static_cast<std::uint32_t>(geometry.ns(k)));
        w.u32(static_cast<std::uint32_t>(geometry.nt(k)));
    }
    for (const Patch& p : geometry.patches()) {
        w.u32(static_cast<std::uint32_t>(p.surface));
        w.u32(static_cast<std::uint32_t>(p.is));
        w.u32(static_cast<std::uint32_t>(p.it));
        w.f64(p.area);
    }
    stats.for_each_counter([&](const char*, long long v) { w.i64(v); });
}

void read_patch_table(ByteReader& in, const Header& h, const SceneGeometry& g, std::vector<double>* areas,
                      FormFactorStats* stats) {
    for (std::size_t k = 0; k < h.info.surfaces; ++k) {
        if (in.peek_u32() > kMaxName) throw CacheFileError("implausible surface name length");
        in.str();  // the surface's name: for people, not checked
        const std::uint32_t ns = in.u32(), nt = in.u32();
        if (ns != static_cast<std::uint32_t>(g.ns(static_cast<int>(k))) ||
            nt != static_cast<std::uint32_t>(g.nt(static_cast<int>(k))))
            throw table_mismatch("surface " + std::to_string(k) + " is split differently");
    }
    for (std::size_t i = 0; i < h.info.patches; ++i) {
        const std::uint32_t s = in.u32(), is = in.u32(), it = in.u32();
        const double area = (*areas)[i] = in.f64();
        const Patch& p = g.patch(static_cast<int>(i));
        if (static_cast<int>(s) != p.surface || static_cast<int>(is) != p.is ||
            static_cast<int>(it) != p.it || !(std::abs(area - p.area) <= 1e-12 * p.area))
            throw table_mismatch("patch " + std::to_string(i) + " differs");
    }
    stats->for_each_counter([&](const char*, long long& v) { v = in.i64(); });
}

void check_rows(const std::vector<double>& row_sum, const std::vector<double>& row_error,
                const CacheFileInfo& info) {
    // No estimates to hold rows to (the fixed rule), or no occlusion (rows may exceed 1).
    if (info.options.method != FormFactorMethod::Adaptive || !info.options.visibility) return;
    for (std::size_t i = 0; i < row_sum.size(); ++i) {
        const double s = row_sum[i], e = row_error[i];
        // Estimates can understate at tight tolerances (docs/accuracy.md), so both bounds take
        // a multiple of them: a matrix scaled, transposed or emptied is still far outside.
        if (!(s <= 1.0 + 16.0 * e + 1e-6))
            throw CacheFileError(
                fmt::format("row {} sums to {:.9g}, more than 1 + its error estimates", i, s));
        if (info.closed && !(std::abs(s - 1.0) <= std::max(16.0 * e, 0.01)))
            throw CacheFileError(fmt::format("row {} of a closed scene sums to {:.9g}, far from 1", i, s));
    }
}

}  // namespace radiosa::cache_format
