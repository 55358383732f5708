#include "encode/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include "encode/encode.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace radiosa::media {

namespace {
std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    return ext;
}
std::unique_ptr<OIIO::ImageOutput> create_writer(const std::string& path) {
    auto out = OIIO::ImageOutput::create(path);  // by the final name's extension
    if (!out) throw Error(path + ": no image writer for '" + lower_extension(path) + "' (use .png or .exr)");
    return out;
}
}  // namespace

void check_image_output(const std::string& path) {
    check_output_path(path);
    create_writer(path);
}

void write_image(const Image& img, const std::string& path, double exposure_stops) {
    const std::string ext = lower_extension(path);
    check_output_path(path);
    AtomicFile file(path);
    auto out = create_writer(path);
    const bool linear = ext == ".exr" || ext == ".hdr";
    OIIO::ImageSpec spec(img.width, img.height, 3, linear ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", linear ? "Linear" : "sRGB");
    spec.attribute("Software", "radiosa");
    if (!out->open(file.temp_path().string(), spec))
        throw Error(path + ": cannot open for writing: " + out->geterror());
    bool ok;
    if (linear) {
        ok = out->write_image(OIIO::TypeDesc::FLOAT, img.rgb.data());
    } else {
        const double scale = std::exp2(exposure_stops);
        std::vector<unsigned char> px(img.rgb.size());
        for (size_t i = 0; i < px.size(); ++i) px[i] = encode_srgb8(img.rgb[i] * scale);
        ok = out->write_image(OIIO::TypeDesc::UINT8, px.data());
    }
    if (!ok || !out->close()) throw Error(path + ": write failed: " + out->geterror());
    file.commit();
}

Image read_image(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw Error(path + ": cannot read image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    Image img;
    img.width = spec.width;
    img.height = spec.height;
    std::vector<float> all(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
        throw Error(path + ": cannot decode image: " + in->geterror());
    img.rgb.resize(static_cast<size_t>(spec.width) * spec.height * 3);
    for (size_t p = 0; p < static_cast<size_t>(spec.width) * spec.height; ++p)
        for (int c = 0; c < 3; ++c)
            img.rgb[3 * p + c] = all[p * spec.nchannels + std::min(c, spec.nchannels - 1)];
    return img;
}

}  // namespace radiosa::media
