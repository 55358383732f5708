#pragma once
// Little-endian byte encoding, independent of host byte order and locale: the canonical form
// hashed into cache keys and the layout of cache files.
#include <bit>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace radiosa {

class ByteWriter {
public:
    ByteWriter() { m_bytes.reserve(256); }
    void u8(std::uint8_t v) { m_bytes.push_back(v); }
    void u32(std::uint32_t v) { put(v, 4); }
    void u64(std::uint64_t v) { put(v, 8); }
    void i64(std::int64_t v) { put(static_cast<std::uint64_t>(v), 8); }
    // -0.0 is written as +0.0 so that equal geometry gives equal bytes.
    void f64(double v) { put(std::bit_cast<std::uint64_t>(v == 0.0 ? 0.0 : v), 8); }
    void str(std::string_view s) {
        u32(static_cast<std::uint32_t>(s.size()));
        raw(s.data(), s.size());
    }
    void raw(const void* data, std::size_t n) {
        const auto* p = static_cast<const std::uint8_t*>(data);
        m_bytes.insert(m_bytes.end(), p, p + n);
    }
    // Doubles in bulk: a plain copy on little-endian hosts.
    void f64_array(const double* v, std::size_t n) {
        if constexpr (std::endian::native == std::endian::little)
            raw(v, n * sizeof(double));
        else
            for (std::size_t i = 0; i < n; ++i) put(std::bit_cast<std::uint64_t>(v[i]), 8);
    }
    std::vector<std::uint8_t>& bytes() { return m_bytes; }

private:
    void put(std::uint64_t v, int n) {
        for (int k = 0; k < n; ++k) m_bytes.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
    }
    std::vector<std::uint8_t> m_bytes;
};

// Reading past the end throws Truncated: every length comes from the file and is checked.
class ByteReader {
public:
    struct Truncated : std::runtime_error {
        Truncated() : std::runtime_error("file is truncated") {}
    };
    ByteReader(const std::uint8_t* data, std::size_t size) : m_data(data), m_size(size) {}

    std::uint8_t u8() { return static_cast<std::uint8_t>(get(1)); }
    std::uint32_t u32() { return static_cast<std::uint32_t>(get(4)); }
    std::uint64_t u64() { return get(8); }
    // The next u32 without consuming it (a length to check before reading what it counts).
    std::uint32_t peek_u32() {
        const std::uint32_t v = u32();
        m_pos -= 4;
        return v;
    }
    std::int64_t i64() { return static_cast<std::int64_t>(get(8)); }
    double f64() { return std::bit_cast<double>(get(8)); }
    std::string str() {
        const std::uint32_t n = u32();
        const std::uint8_t* p = take(n);
        return std::string(reinterpret_cast<const char*>(p), n);
    }
    const std::uint8_t* take(std::size_t n) {
        if (n > m_size - m_pos) throw Truncated();
        const std::uint8_t* p = m_data + m_pos;
        m_pos += n;
        return p;
    }
    void f64_array(double* out, std::size_t n) {
        if (n > (m_size - m_pos) / 8) throw Truncated();
        if (n == 0) return;  // memcpy from or to a null pointer is undefined, even for 0 bytes
        if constexpr (std::endian::native == std::endian::little)
            std::memcpy(out, take(n * 8), n * 8);
        else
            for (std::size_t i = 0; i < n; ++i) out[i] = f64();
    }
    std::size_t pos() const { return m_pos; }
    std::size_t remaining() const { return m_size - m_pos; }

private:
    std::uint64_t get(int n) {
        const std::uint8_t* p = take(static_cast<std::size_t>(n));
        std::uint64_t v = 0;
        for (int k = 0; k < n; ++k) v |= static_cast<std::uint64_t>(p[k]) << (8 * k);
        return v;
    }
    const std::uint8_t* m_data;
    std::size_t m_size;
    std::size_t m_pos = 0;
};

}  // namespace radiosa
