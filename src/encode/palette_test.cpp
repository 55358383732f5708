// Palette quantisers, the mapper, PSNR, and indexed outputs read back.
#include "encode/palette.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "encode/encode.h"
#include "encode/features.h"
#include "encode/image_io.h"
#include "encode/video_writer.h"

namespace radiosa {

namespace {
// A horizontal ramp of 256 greys plus a few saturated pixels (a small "lit patch").
std::vector<std::uint8_t> test_frame(int w, int h) {
    std::vector<std::uint8_t> rgb;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool spot = x < 4 && y < 4;
            const std::uint8_t v = static_cast<std::uint8_t>(x * 255 / (w - 1));
            rgb.insert(rgb.end(), {spot ? std::uint8_t(255) : v, spot ? std::uint8_t(40) : v,
                                   spot ? std::uint8_t(0) : v});
        }
    return rgb;
}
}  // namespace

TEST(Palette, FewColoursAreKeptExactly) {
    std::vector<std::uint8_t> rgb;
    for (int k = 0; k < 100; ++k) rgb.insert(rgb.end(), {8, 16, 24, 200, 100, 0, 0, 0, 248});
    ColourHistogram h;
    h.add(rgb);
    for (Quantiser q : {Quantiser::MedianCut, Quantiser::Popularity}) {
        PaletteMapper m(h.palette(256, q));
        EXPECT_EQ(m.palette().size(), 3u);
        PsnrAccumulator p;
        p.add(rgb, m.map(rgb), m.palette());
        EXPECT_EQ(p.sum_sq, 0.0);
        EXPECT_EQ(p.psnr_db(), 99.0);
    }
}

// A palette entry is its pixels' mean rounded to nearest: 10 and 13 in one histogram cell give
// 12 (11.5 rounded), not 11.
TEST(Palette, EntriesAreRoundedMeans) {
    ColourHistogram h;
    h.add({10, 10, 10, 13, 13, 13});
    for (Quantiser q : {Quantiser::MedianCut, Quantiser::Popularity}) {
        const std::vector<Colour8> p = h.palette(4, q);
        ASSERT_EQ(p.size(), 1u);
        EXPECT_EQ(p[0], (Colour8{12, 12, 12}));
    }
}

TEST(Palette, MedianCutKeepsRareColoursThatPopularityDrops) {
    const auto rgb = test_frame(256, 64);
    ColourHistogram h;
    h.add(rgb);
    PsnrAccumulator pm, pp;
    PaletteMapper mc(h.palette(16, Quantiser::MedianCut)), pop(h.palette(16, Quantiser::Popularity));
    const auto im = mc.map(rgb), ip = pop.map(rgb);
    pm.add(rgb, im, mc.palette());
    pp.add(rgb, ip, pop.palette());
    EXPECT_EQ(mc.palette().size(), 16u);
    EXPECT_EQ(pop.palette().size(), 16u);
    // The orange spot: median cut gives it its own entry, popularity maps it to a grey.
    const Colour8 spot_mc = mc.palette()[im[0]], spot_pop = pop.palette()[ip[0]];
    EXPECT_GT(spot_mc[0] - spot_mc[2], 150);
    EXPECT_LT(std::abs(spot_pop[0] - spot_pop[2]), 20);
    EXPECT_GT(pm.psnr_db(), pp.psnr_db());
    EXPECT_GT(pm.psnr_db(), 25.0);
}

TEST(Palette, IndexedPngAndGifDecode) {
    if (!kHasVideo) GTEST_SKIP() << kNoVideoMessage;
    namespace fs = std::filesystem;
    const fs::path d = fs::temp_directory_path() / "radiosa_palette_out";
    fs::remove_all(d);
    fs::create_directories(d);
    const auto rgb = test_frame(32, 16);
    ColourHistogram h;
    h.add(rgb);
    PaletteMapper m(h.palette(16, Quantiser::MedianCut));
    const auto ix = m.map(rgb);
    write_indexed_png((d / "f.png").string(), 32, 16, ix, m.palette());
    const Image back = media::read_image((d / "f.png").string());
    ASSERT_EQ(back.width, 32);
    for (int i = 0; i < 32 * 16; ++i)
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(back.rgb[3 * i + k] * 255.0, m.palette()[ix[i]][k], 0.01);
    write_gif((d / "a.gif").string(), 32, 16, 10, m.palette(), std::vector<std::vector<std::uint8_t>>(5, ix));
    const media::VideoProbe p = media::probe_video(d / "a.gif");
    EXPECT_EQ(p.codec, "gif");
    EXPECT_EQ(p.frames, 5);
    EXPECT_EQ(p.width, 32);
    EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 2);
    fs::remove_all(d);
}

}  // namespace radiosa
