#pragma once
// `radiosa formfactors`: compute (or load from the cache) a scene's form-factor matrix, print
// its closure and reciprocity figures, and optionally export it.
#include <optional>
#include <string>

#include "app/form_factor_request.h"
#include "cache/cache_file.h"

namespace radiosa {

struct FormFactorsJob {
    std::string scene_path;
    std::optional<std::string> matrix_path;  // .csv or .npy
    std::optional<std::string> report_path;
    std::optional<std::string> sensors_path;  // .csv: F(dA -> patch) per sensor
    FormFactorRequest form_factors;
    int threads = 0;
    WarningSink warn = [](const std::string&) {};
};

// Runs the job and returns the text summary for stdout; throws Error for bad input.
std::string run_formfactors(const FormFactorsJob& job);

}  // namespace radiosa
