#pragma once
// The 1991 paper's display constraint: one palette of at most 256 colours for a whole
// sequence, computed once from every frame so colours stay stable from frame to frame.
// Two quantisers: the paper's popularity algorithm (the N most frequent colours of a 5-bit
// per channel histogram) and Heckbert's median cut (the default: it splits colour space where
// the pixels are, so rare but distinct colours such as a small lit patch keep an entry).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace radiosa {

using Colour8 = std::array<std::uint8_t, 3>;
enum class Quantiser { MedianCut, Popularity };
Quantiser parse_quantiser(const std::string& name);  // "median-cut" | "popularity"
const char* quantiser_name(Quantiser q);

// Pixel counts and colour sums per 5-bit-per-channel cell.
class ColourHistogram {
public:
    ColourHistogram();
    void add(const std::vector<std::uint8_t>& rgb);  // 8-bit RGB triples
    std::vector<Colour8> palette(int colours, Quantiser q) const;

private:
    friend struct MedianCut;
    std::vector<std::uint64_t> m_count;
    std::vector<std::array<std::uint64_t, 3>> m_sum;
};

// Nearest palette entry (Euclidean in 8-bit RGB) of every pixel.
class PaletteMapper {
public:
    explicit PaletteMapper(std::vector<Colour8> palette);
    std::vector<std::uint8_t> map(const std::vector<std::uint8_t>& rgb);
    const std::vector<Colour8>& palette() const { return m_palette; }

private:
    std::uint8_t nearest(int r, int g, int b) const;
    std::vector<Colour8> m_palette;
    std::vector<std::int16_t> m_cache;  // per exact 24-bit colour seen: its index, -1 unknown
};

// Accumulates squared error between true-colour and indexed frames; PSNR in dB (peak 255).
struct PsnrAccumulator {
    double sum_sq = 0.0;
    std::uint64_t samples = 0;
    void add(const std::vector<std::uint8_t>& rgb, const std::vector<std::uint8_t>& index,
             const std::vector<Colour8>& palette);
    double psnr_db() const;
};

}  // namespace radiosa
