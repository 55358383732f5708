// `radiosa cache verify`: every check that needs no scene, streamed through in bounded memory.
// With no scene to say how large the matrix may be, a file could claim 20,000 patches and
// expand to gigabytes; so the checksum, the decompression and the value checks all run on
// chunks, and only per-row sums (O(N)) are kept.
#include <xxhash.h>
#include <zstd.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "cache/cache_file.h"
#include "cache/cache_format.h"

namespace radiosa {

using namespace cache_format;

void cache_format::check_checksum(const Source& src) {
    std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state(XXH3_createState(), XXH3_freeState);
    XXH3_64bits_reset(state.get());
    const std::uint64_t body = src.size() - 8;
    std::vector<std::uint8_t> buf(kChunk);
    for (std::uint64_t at = 0; at < body;) {
        const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, body - at));
        src.read(at, buf.data(), n);
        XXH3_64bits_update(state.get(), buf.data(), n);
        at += n;
    }
    std::uint8_t trailer[8];
    src.read(body, trailer, 8);
    ByteReader t(trailer, 8);
    if (t.u64() != XXH3_64bits_digest(state.get()))
        throw CacheFileError("checksum mismatch (the file is damaged or truncated)");
}

void cache_format::check_table(const Source& src, const Header& h, int extra_counters) {
    const std::uint64_t offset = h.length, size = src.size() - 8 - h.stored - h.length;
    const std::vector<std::uint8_t> table = src.read_vector(offset, static_cast<std::size_t>(size));
    ByteReader in(table.data(), table.size());
    std::vector<std::uint32_t> ns(h.info.surfaces), nt(h.info.surfaces);
    for (std::size_t k = 0; k < h.info.surfaces; ++k) {
        if (in.peek_u32() > kMaxName) throw CacheFileError("implausible surface name length");
        in.str();
        ns[k] = in.u32();
        nt[k] = in.u32();
    }
    for (std::size_t i = 0; i < h.info.patches; ++i) {
        const std::uint32_t s = in.u32(), is = in.u32(), it = in.u32();
        const double area = in.f64();
        if (s >= h.info.surfaces || is >= ns[s] || it >= nt[s] || !(area > 0.0) || !std::isfinite(area))
            throw CacheFileError("patch table entry " + std::to_string(i) + " is invalid");
    }
    FormFactorStats stats;
    stats.for_each_counter([&](const char*, long long& v) { v = in.i64(); });
    for (int k = 0; k < extra_counters; ++k)
        if (in.i64() < 0) throw CacheFileError("table holds a negative counter");
    if (in.remaining() != 0) throw CacheFileError("table has trailing bytes");
}

namespace {

void check_value(double f, std::uint64_t i, std::uint64_t j) {
    // 1 % above 1 at most: an entry may exceed 1 by its error estimate, checked exactly on load.
    if (!(f >= 0.0 && f <= 1.01))
        throw CacheFileError("entry (" + std::to_string(i) + "," + std::to_string(j) + ") is " +
                             std::to_string(f) + ", not a number in [0, 1]");
}

void stream_values(SectionStream& s, const Header& h, std::vector<double>* row_sum) {
    const std::uint64_t n = h.info.patches;
    if (h.layout == kLayoutDense) {
        for (std::uint64_t i = 0; i < n; ++i)
            for (std::uint64_t j = 0; j < n; ++j) {
                const double f = s.f64();
                check_value(f, i, j);
                (*row_sum)[i] += f;
            }
        return;
    }
    std::vector<std::uint64_t> start(n + 1);
    for (auto& v : start) {
        std::uint8_t b[8];
        s.read(b, 8);
        v = ByteReader(b, 8).u64();
    }
    for (std::uint64_t i = 0; i < n; ++i)
        if (start[i] > start[i + 1]) throw CacheFileError("sparse row table is not increasing");
    if (start[0] != 0 || start[n] > n * n) throw CacheFileError("sparse matrix sizes are inconsistent");
    for (std::uint64_t k = 0; k < start[n]; ++k) {
        std::uint8_t b[4];
        s.read(b, 4);
        if (ByteReader(b, 4).u32() >= n) throw CacheFileError("sparse column index out of range");
    }
    for (std::uint64_t i = 0; i < n; ++i)
        for (std::uint64_t k = start[i]; k < start[i + 1]; ++k) {
            const double f = s.f64();
            check_value(f, i, k - start[i]);
            (*row_sum)[i] += f;
        }
}

void stream_estimates(SectionStream& s, const Header& h, std::vector<double>* row_error) {
    const std::uint64_t n = h.info.patches;
    for (std::uint64_t i = 0; i < n; ++i)
        for (std::uint64_t j = 0; j < n; ++j) {
            const double e = s.f64();
            if (!(e >= 0.0 && std::isfinite(e)))
                throw CacheFileError("error estimate (" + std::to_string(i) + "," + std::to_string(j) +
                                     ") is " + std::to_string(e) + ", not a finite number >= 0");
            (*row_error)[i] += e;
        }
}

CacheFileInfo verify_source(const Source& src) {
    const Header h = read_source_header(src);
    check_sizes(h, src.size());
    check_checksum(src);
    check_table(src, h, 0);
    SectionStream s(src, h.stored, h.raw, h.compression == kCompressZstd);
    std::vector<double> row_sum(h.info.patches, 0.0), row_error(h.info.patches, 0.0);
    stream_values(s, h, &row_sum);
    if (h.info.has_error_estimates) stream_estimates(s, h, &row_error);
    s.finish();
    check_rows(row_sum, row_error, h.info);
    return h.info;
}

}  // namespace

CacheFileInfo verify_cache_bytes(std::span<const std::uint8_t> bytes) {
    try {
        return verify_source(MemorySource(bytes));
    } catch (const ByteReader::Truncated&) {
        throw CacheFileError("file is truncated (" + std::to_string(bytes.size()) + " bytes)");
    }
}

CacheFileInfo verify_cache_file(const std::filesystem::path& path) {
    const FileSource src(path);
    try {
        return verify_source(src);
    } catch (const ByteReader::Truncated&) {
        throw CacheFileError("file is truncated (" + std::to_string(src.size()) + " bytes)");
    }
}

}  // namespace radiosa
