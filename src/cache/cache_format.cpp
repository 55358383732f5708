#include "cache/cache_format.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "scene/scene.h"

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
    if (h.info.patches == 0 || h.info.patches > static_cast<std::uint64_t>(kMaxPatches) ||
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
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(src.size(), kHeadRead));
    const std::vector<std::uint8_t> head = src.read_vector(0, n);
    ByteReader in(head.data(), head.size());
    try {
        return read_header(in);
    } catch (const ByteReader::Truncated&) {
        throw CacheFileError("file is truncated (" + std::to_string(src.size()) + " bytes)");
    }
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
