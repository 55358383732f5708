#pragma once
// Exports the form-factor matrix with the table that identifies its rows and columns.
//   .csv  header "patch,surface,is,it,area,<label of column 0>,...", one row per patch,
//         labels "surface[is,it]", values with 17 significant digits (exact round trip)
//   .npy  NumPy format 1.0, little-endian float64, shape (N, N), C order (numpy.load reads it),
//         plus the patch table beside it as "<stem>.patches.csv" (patch,surface,is,it,area)
#include <filesystem>
#include <string>

#include "formfactor/form_factor.h"

namespace radiosa {

class SceneGeometry;

// Throws Error for an unknown extension (before any work, see check_matrix_output) or a failed write.
void check_matrix_output(const std::filesystem::path& path);
void write_matrix(const std::filesystem::path& path, const SceneGeometry& geometry, const FormFactors& ff);

// The sidecar patch table written next to an .npy export.
std::filesystem::path npy_patch_table_path(const std::filesystem::path& npy);

}  // namespace radiosa
