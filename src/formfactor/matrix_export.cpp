#include "formfactor/matrix_export.h"

#include <fmt/format.h>

#include <cstdio>
#include <sstream>

#include "geometry/scene_geometry.h"
#include "util/atomic_file.h"
#include "util/bytes.h"
#include "util/error.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

std::string lower_extension(const fs::path& p) {
    std::string e = p.extension().string();
    for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

std::string fmt17(double v) { return fmt::format("{:.17g}", v); }

std::string patch_table_csv(const SceneGeometry& g, const FormFactors& ff, bool with_matrix) {
    std::ostringstream s;
    s << "patch,surface,is,it,area";
    const int n = ff.F.n;
    if (with_matrix)
        for (int j = 0; j < n; ++j) s << ",\"" << g.patch_label(j) << "\"";
    s << "\n";
    for (int i = 0; i < n; ++i) {
        const Patch& p = g.patch(i);
        s << i << ",\"" << g.surface_name(p.surface) << "\"," << p.is << "," << p.it << ","
          << fmt17(ff.area[i]);
        if (with_matrix)
            for (int j = 0; j < n; ++j) s << "," << fmt17(ff.F(i, j));
        s << "\n";
    }
    return s.str();
}

}  // namespace

fs::path npy_patch_table_path(const fs::path& npy) {
    fs::path p = npy;
    p.replace_extension(".patches.csv");
    return p;
}

void check_matrix_output(const fs::path& path) {
    const std::string ext = lower_extension(path);
    if (ext != ".csv" && ext != ".npy")
        throw Error(path.string() + ": unknown matrix format '" + ext + "' (use .csv or .npy)");
    check_output_path(path);
}

void write_matrix(const fs::path& path, const SceneGeometry& g, const FormFactors& ff) {
    check_matrix_output(path);
    if (lower_extension(path) == ".csv") {
        write_text_file(path, patch_table_csv(g, ff, true));
        return;
    }
    // NumPy .npy 1.0: magic, version, u16 header length, a Python dict literal padded with
    // spaces to a multiple of 64 bytes (ending in '\n'), then the raw data.
    const int n = ff.F.n;
    std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" + std::to_string(n) + ", " +
                         std::to_string(n) + "), }";
    const std::size_t prefix = 10;
    const std::size_t total = (prefix + header.size() + 1 + 63) / 64 * 64;
    header.append(total - prefix - header.size() - 1, ' ');
    header += '\n';
    ByteWriter w;
    w.raw("\x93NUMPY", 6);
    w.u8(1);
    w.u8(0);
    w.u8(static_cast<std::uint8_t>(header.size() & 0xff));
    w.u8(static_cast<std::uint8_t>(header.size() >> 8));
    w.raw(header.data(), header.size());
    w.f64_array(ff.F.data.data(), ff.F.data.size());
    write_text_file(path, std::string(w.bytes().begin(), w.bytes().end()));  // binary-safe, atomic
    write_text_file(npy_patch_table_path(path), patch_table_csv(g, ff, false));
}

}  // namespace radiosa
