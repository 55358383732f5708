#pragma once
// Inside the cache stage: the file format's constants, its header, and where its bytes come
// from (a regular file opened safely, or memory for the fuzzer). Layout in cache_file.h.
#include <zstd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cache/cache_file.h"
#include "util/bytes.h"

namespace radiosa::cache_format {

inline constexpr char kMagic[8] = {'R', 'A', 'D', 'F', 'F', '\r', '\n', '\x1a'};
inline constexpr std::uint32_t kElementFloat64 = 1;
enum : std::uint32_t { kLayoutDense = 0, kLayoutCsr = 1 };
enum : std::uint32_t { kCompressNone = 0, kCompressZstd = 1 };
inline constexpr std::uint32_t kFlagErrors = 1, kFlagVisibility = 2, kFlagClosed = 4;
inline constexpr std::uint32_t kMethodFixed = 0, kMethodAdaptive = 1;
inline constexpr std::uint32_t kMaxName = 4096;  // bytes of a scene or surface name
inline constexpr std::size_t kHeadRead = 8192;   // the header lies within this many bytes
inline constexpr std::size_t kChunk = 1 << 20;   // bytes per read when streaming a section

// Everything in the file before the table.
struct Header {
    CacheFileInfo info;
    std::uint32_t layout = 0, compression = 0;
    std::uint64_t stored = 0, raw = 0;
    std::size_t length = 0;  // bytes of the header itself
};

// Parses and range-checks the header (magic first). Throws CacheFileError.
Header read_header(ByteReader& in);

// The largest uncompressed matrix section N patches can have in this layout.
std::uint64_t max_raw_size(std::uint64_t n, std::uint32_t layout, bool errors);
// The smallest and largest table (surface and patch entries, counters).
std::uint64_t min_table_size(const Header& h);
std::uint64_t max_table_size(const Header& h);
// Checks the header's sizes against each other and against the file's `size`, so that nothing
// read later can exceed the file or the matrix N patches need. Throws CacheFileError.
void check_sizes(const Header& h, std::uint64_t size);

// Where a cache file's bytes come from.
class Source {
public:
    virtual ~Source() = default;
    virtual std::uint64_t size() const = 0;
    // Exactly n bytes at offset, or CacheFileError.
    virtual void read(std::uint64_t offset, void* dst, std::size_t n) const = 0;
    std::vector<std::uint8_t> read_vector(std::uint64_t offset, std::size_t n) const;
};

// A regular file, opened without following links or waiting on FIFOs: anything else (a
// directory, FIFO, device, socket or symbolic link) is a CacheFileError saying what it is.
class FileSource final : public Source {
public:
    explicit FileSource(const std::filesystem::path& path);
    ~FileSource() override;
    FileSource(const FileSource&) = delete;
    FileSource& operator=(const FileSource&) = delete;
    std::uint64_t size() const override { return m_size; }
    void read(std::uint64_t offset, void* dst, std::size_t n) const override;

private:
    int m_fd = -1;
    std::uint64_t m_size = 0;
};

class MemorySource final : public Source {
public:
    explicit MemorySource(std::span<const std::uint8_t> bytes) : m_bytes(bytes) {}
    std::uint64_t size() const override { return m_bytes.size(); }
    void read(std::uint64_t offset, void* dst, std::size_t n) const override;

private:
    std::span<const std::uint8_t> m_bytes;
};

// The header of a source: reads at most kHeadRead bytes, checks the magic before anything else.
// Its sizes are checked by check_sizes, after the caller has compared what it can.
Header read_source_header(const Source& src);

// A file's last section (before the checksum) as a byte stream, decompressed chunk by chunk when
// it is compressed; never yields more than its uncompressed size `raw`. `what` names it in errors.
class SectionStream {
public:
    SectionStream(const Source& src, std::uint64_t stored, std::uint64_t raw, bool zstd,
                  std::string what = "matrix")
        : m_src(src),
          m_at(src.size() - 8 - stored),
          m_left(stored),
          m_raw_left(raw),
          m_zstd(zstd),
          m_what(std::move(what)),
          m_in(kChunk),
          m_out(kChunk) {
        if (m_zstd) m_ds.reset(ZSTD_createDStream());
    }
    // Exactly n bytes, or CacheFileError.
    void read(void* dst, std::size_t n) {
        if (n > m_raw_left) throw CacheFileError(m_what + " section is shorter than its content");
        m_raw_left -= n;
        auto* p = static_cast<std::uint8_t*>(dst);
        while (n > 0) {
            if (m_out_pos == m_out_len) refill();
            const std::size_t k = std::min(n, m_out_len - m_out_pos);
            std::memcpy(p, m_out.data() + m_out_pos, k);
            m_out_pos += k;
            p += k;
            n -= k;
        }
    }
    std::uint32_t u32() {
        std::uint8_t b[4];
        read(b, 4);
        return ByteReader(b, 4).u32();
    }
    double f64() {
        std::uint8_t b[8];
        read(b, 8);
        return ByteReader(b, 8).f64();
    }
    // Everything consumed: no bytes left over in the file or the decompressor.
    void finish() {
        if (m_raw_left != 0 || m_out_pos != m_out_len)
            throw CacheFileError(m_what + " section has trailing bytes");
        if (m_zstd) drain();
        if (m_left != 0 || m_in_pos != m_in_len) throw CacheFileError(m_what + " section has trailing bytes");
    }

private:
    void read_input() {
        m_in_len = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, m_left));
        if (m_in_len == 0) throw CacheFileError("compressed " + m_what + " ends early");
        m_src.read(m_at, m_in.data(), m_in_len);
        m_at += m_in_len;
        m_left -= m_in_len;
        m_in_pos = 0;
    }
    // The end of the zstd frame: it must hold nothing beyond the header's size.
    void drain() {
        while (!m_frame_done) {
            if (m_in_pos == m_in_len && m_left > 0) read_input();
            ZSTD_inBuffer in{m_in.data(), m_in_len, m_in_pos};
            ZSTD_outBuffer out{m_out.data(), m_out.size(), 0};
            const std::size_t r = ZSTD_decompressStream(m_ds.get(), &out, &in);
            if (ZSTD_isError(r)) throw CacheFileError("compressed " + m_what + " does not decompress");
            m_in_pos = in.pos;
            if (out.pos != 0)
                throw CacheFileError("compressed " + m_what + " holds more than its header says");
            m_frame_done = r == 0;
            if (!m_frame_done && m_in_pos == m_in_len && m_left == 0)
                throw CacheFileError("compressed " + m_what + " ends early");
        }
    }
    void refill() {
        m_out_pos = 0;
        if (!m_zstd) {
            m_out_len = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, m_left));
            if (m_out_len == 0) throw CacheFileError(m_what + " section is truncated");
            m_src.read(m_at, m_out.data(), m_out_len);
            m_at += m_out_len;
            m_left -= m_out_len;
            return;
        }
        for (m_out_len = 0; m_out_len == 0;) {
            if (m_frame_done)
                throw CacheFileError("compressed " + m_what + " is shorter than its header says");
            if (m_in_pos == m_in_len) read_input();
            ZSTD_inBuffer in{m_in.data(), m_in_len, m_in_pos};
            ZSTD_outBuffer out{m_out.data(), m_out.size(), 0};
            const std::size_t r = ZSTD_decompressStream(m_ds.get(), &out, &in);
            if (ZSTD_isError(r)) throw CacheFileError("compressed " + m_what + " does not decompress");
            m_in_pos = in.pos;
            m_out_len = out.pos;
            m_frame_done = r == 0;
        }
    }

    struct FreeDStream {
        void operator()(ZSTD_DStream* d) const { ZSTD_freeDStream(d); }
    };
    const Source& m_src;
    std::uint64_t m_at, m_left, m_raw_left;
    bool m_zstd;
    std::string m_what;
    std::unique_ptr<ZSTD_DStream, FreeDStream> m_ds;
    std::vector<std::uint8_t> m_in, m_out;
    std::size_t m_in_pos = 0, m_in_len = 0, m_out_pos = 0, m_out_len = 0;
    bool m_frame_done = false;
};

// The whole source, its XXH3-64 trailer checked against every preceding byte (call it once the
// header has bounded the size). Throws CacheFileError.
std::vector<std::uint8_t> read_checked(const Source& src);

// The key of canonical bytes: their XXH3-128 in canonical (big-endian) order.
CacheKey hash_key(const std::vector<std::uint8_t>& bytes);

// A section as stored: zstd-compressed when that saves at least a quarter of its bytes (*zstd
// says whether it is), else `raw` itself.
std::vector<std::uint8_t> pack_section(std::vector<std::uint8_t> raw, bool* zstd);
// Appends the XXH3-64 checksum of everything written and writes the file atomically (exclusive
// temporary, fsync, rename). Throws Error when it cannot be written.
void commit_file(const std::filesystem::path& path, ByteWriter& w);
// Writes a file whose last section is zstd-compressed as it is produced, holding a chunk of it
// in memory rather than all of it (a large scene's links are gigabytes): `head(stored)` gives
// the bytes before the section (header and table) for the section's stored size, and must give
// as many bytes for any size; `produce(dst, cap)` fills up to cap bytes of the uncompressed
// section and returns how many, 0 at its end, `raw` bytes in all. Then the XXH3-64 checksum of
// everything before it, read back; atomic like commit_file. Throws Error when it cannot be
// written.
void commit_streamed(const std::filesystem::path& path, std::uint64_t raw,
                     const std::function<std::vector<std::uint8_t>(std::uint64_t stored)>& head,
                     const std::function<std::size_t(std::uint8_t* dst, std::size_t cap)>& produce);
// The first kHeadRead bytes of a source, parsed by `parse` (a ByteReader running out is a
// truncated file).
template <class F>
auto parse_head(const Source& src, F&& parse) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(src.size(), kHeadRead));
    const std::vector<std::uint8_t> head = src.read_vector(0, n);
    ByteReader in(head.data(), head.size());
    try {
        return parse(in);
    } catch (const ByteReader::Truncated&) {
        throw CacheFileError("file is truncated (" + std::to_string(src.size()) + " bytes)");
    }
}

// A name as stored (at most kMaxName bytes), and the error for a table that differs from the scene.
std::string capped_name(const std::string& s);
CacheFileError table_mismatch(const std::string& what);

// The XXH3-64 trailer against every preceding byte, streamed. Throws CacheFileError.
void check_checksum(const Source& src);
// The table between the header and the last section, without a scene: surface splits, patch
// entries in range, the FormFactorStats counters and `extra_counters` more (i64, >= 0).
void check_table(const Source& src, const Header& h, int extra_counters);
// The table, written, and read against a scene: each patch's surface, indices and area.
void write_table(ByteWriter& w, const SceneGeometry& geometry, const FormFactorStats& stats);
void read_patch_table(ByteReader& in, const Header& h, const SceneGeometry& g, std::vector<double>* areas,
                      FormFactorStats* stats);

// Row checks shared by loads and `cache verify`: every row sum within 1 + its estimates, and
// for a closed scene's error-controlled matrix, closure within (a multiple of) the estimates.
void check_rows(const std::vector<double>& row_sum, const std::vector<double>& row_error,
                const CacheFileInfo& info);

}  // namespace radiosa::cache_format
