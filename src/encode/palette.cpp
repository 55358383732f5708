#include "encode/palette.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

#include "util/error.h"

namespace radiosa {

namespace {

constexpr int kBits = 5, kSide = 1 << kBits, kCells = kSide * kSide * kSide;
int cell_of(int r, int g, int b) { return ((r >> 3) << 10) | ((g >> 3) << 5) | (b >> 3); }

}  // namespace

Quantiser parse_quantiser(const std::string& name) {
    if (name == "popularity") return Quantiser::Popularity;
    if (name == "median-cut") return Quantiser::MedianCut;
    throw Error("unknown quantiser '" + name + "' (use median-cut or popularity)");
}
const char* quantiser_name(Quantiser q) { return q == Quantiser::Popularity ? "popularity" : "median-cut"; }

ColourHistogram::ColourHistogram() : m_count(kCells, 0), m_sum(kCells, {0, 0, 0}) {}

void ColourHistogram::add(const std::vector<std::uint8_t>& rgb) {
    for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) {
        const int c = cell_of(rgb[i], rgb[i + 1], rgb[i + 2]);
        ++m_count[c];
        for (int k = 0; k < 3; ++k) m_sum[c][k] += rgb[i + k];
    }
}

struct MedianCut {
    // A box of occupied cells.
    struct Box {
        std::vector<int> cells;
        std::uint64_t pixels = 0;
        int axis = 0;
        int extent = 0;
    };
    static void measure(Box& b) {
        int lo[3] = {kSide, kSide, kSide}, hi[3] = {-1, -1, -1};
        b.pixels = 0;
        for (int c : b.cells) {
            const int v[3] = {c >> 10, (c >> 5) & 31, c & 31};
            for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
        }
        b.extent = -1;
        for (int k = 0; k < 3; ++k)
            if (hi[k] - lo[k] > b.extent) b.extent = hi[k] - lo[k], b.axis = k;
    }
};

std::vector<Colour8> ColourHistogram::palette(int colours, Quantiser q) const {
    auto mean = [&](const std::vector<int>& cells) {
        std::array<std::uint64_t, 3> s{0, 0, 0};
        std::uint64_t n = 0;
        for (int c : cells) {
            n += m_count[c];
            for (int k = 0; k < 3; ++k) s[k] += m_sum[c][k];
        }
        Colour8 out{};
        for (int k = 0; k < 3; ++k)
            out[k] = static_cast<std::uint8_t>((s[k] + n / 2) / std::max<std::uint64_t>(n, 1));
        return out;
    };
    std::vector<int> occupied;
    for (int c = 0; c < kCells; ++c)
        if (m_count[c]) occupied.push_back(c);
    std::vector<Colour8> pal;
    if (q == Quantiser::Popularity) {
        std::stable_sort(occupied.begin(), occupied.end(),
                         [&](int a, int b) { return m_count[a] > m_count[b]; });
        for (int k = 0; k < std::min<int>(colours, static_cast<int>(occupied.size())); ++k)
            pal.push_back(mean({occupied[k]}));
        return pal;
    }
    std::vector<MedianCut::Box> boxes(1);
    boxes[0].cells = occupied;
    MedianCut::measure(boxes[0]);
    while (static_cast<int>(boxes.size()) < colours) {
        // Split the box with the most pixels times its longest side (population alone never
        // splits off a rare colour that shares a box with many pixels of a narrow range).
        int best = -1;
        auto priority = [&](const MedianCut::Box& b) { return static_cast<double>(b.pixels) * b.extent; };
        for (int i = 0; i < static_cast<int>(boxes.size()); ++i)
            if (boxes[i].extent > 0 && (best < 0 || priority(boxes[i]) > priority(boxes[best]))) best = i;
        if (best < 0) break;
        MedianCut::Box& b = boxes[best];
        const int shift = b.axis == 0 ? 10 : b.axis == 1 ? 5 : 0;
        std::sort(b.cells.begin(), b.cells.end(),
                  [&](int x, int y) { return ((x >> shift) & 31) < ((y >> shift) & 31); });
        // Cut at the median pixel, never leaving a side empty and never between equal coordinates.
        std::uint64_t acc = 0;
        std::size_t cut = 1;
        for (std::size_t i = 0; i + 1 < b.cells.size(); ++i) {
            acc += m_count[b.cells[i]];
            cut = i + 1;
            if (acc * 2 >= b.pixels) break;
        }
        while (cut < b.cells.size() && ((b.cells[cut] >> shift) & 31) == ((b.cells[cut - 1] >> shift) & 31))
            ++cut;
        if (cut == b.cells.size()) {
            cut = 1;
            while (cut < b.cells.size() && ((b.cells[cut] >> shift) & 31) == ((b.cells[0] >> shift) & 31))
                ++cut;
        }
        MedianCut::Box upper;
        upper.cells.assign(b.cells.begin() + static_cast<long>(cut), b.cells.end());
        b.cells.resize(cut);
        MedianCut::measure(b);
        MedianCut::measure(upper);
        b.pixels = std::accumulate(b.cells.begin(), b.cells.end(), std::uint64_t{0},
                                   [&](std::uint64_t s, int c) { return s + m_count[c]; });
        upper.pixels = std::accumulate(upper.cells.begin(), upper.cells.end(), std::uint64_t{0},
                                       [&](std::uint64_t s, int c) { return s + m_count[c]; });
        boxes.push_back(std::move(upper));
    }
    for (const auto& b : boxes) pal.push_back(mean(b.cells));
    return pal;
}

PaletteMapper::PaletteMapper(std::vector<Colour8> palette)
    : m_palette(std::move(palette)), m_cache(std::size_t{1} << 24, -1) {
    if (m_palette.empty()) m_palette.push_back({0, 0, 0});
}

std::uint8_t PaletteMapper::nearest(int r, int g, int b) const {
    int best = 0, best_d = 1 << 30;
    for (int k = 0; k < static_cast<int>(m_palette.size()); ++k) {
        const int dr = r - m_palette[k][0], dg = g - m_palette[k][1], db = b - m_palette[k][2];
        const int d = dr * dr + dg * dg + db * db;
        if (d < best_d) best_d = d, best = k;
    }
    return static_cast<std::uint8_t>(best);
}

std::vector<std::uint8_t> PaletteMapper::map(const std::vector<std::uint8_t>& rgb) {
    std::vector<std::uint8_t> out(rgb.size() / 3);
    for (std::size_t i = 0; i < out.size(); ++i) {
        const int r = rgb[3 * i], g = rgb[3 * i + 1], b = rgb[3 * i + 2];
        std::int16_t& slot = m_cache[(static_cast<std::size_t>(r) << 16) | (g << 8) | b];
        if (slot < 0) slot = nearest(r, g, b);
        out[i] = static_cast<std::uint8_t>(slot);
    }
    return out;
}

void PsnrAccumulator::add(const std::vector<std::uint8_t>& rgb, const std::vector<std::uint8_t>& index,
                          const std::vector<Colour8>& palette) {
    for (std::size_t i = 0; i < index.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            const double d = double(rgb[3 * i + k]) - palette[index[i]][k];
            sum_sq += d * d;
        }
    samples += 3 * index.size();
}

double PsnrAccumulator::psnr_db() const {
    if (samples == 0) return 0.0;
    const double mse = sum_sq / samples;
    return mse > 0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : 99.0;  // identical: reported as 99 dB
}

}  // namespace radiosa
