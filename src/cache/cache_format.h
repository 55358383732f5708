#pragma once
// Inside the cache stage: the file format's constants, its header, and where its bytes come
// from (a regular file opened safely, or memory for the fuzzer). Layout in cache_file.h.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
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

// Row checks shared by loads and `cache verify`: every row sum within 1 + its estimates, and
// for a closed scene's error-controlled matrix, closure within (a multiple of) the estimates.
void check_rows(const std::vector<double>& row_sum, const std::vector<double>& row_error,
                const CacheFileInfo& info);

}  // namespace radiosa::cache_format
