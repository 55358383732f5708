#pragma once
// What a command asks of the form-factor stage: the command line's overrides of the scene's
// form_factors block, and where the cache is. Shared by render (stills and sequences) and
// formfactors.
#include <optional>

#include "cache/cache_file.h"
#include "formfactor/form_factor.h"
#include "scene/scene.h"
#include "util/error.h"

namespace radiosa {

struct FormFactorRequest {
    std::optional<std::string> method;         // --ff-method
    std::optional<double> tolerance;           // --ff-tolerance
    std::optional<double> receiver_tolerance;  // --ff-receiver-tolerance
    std::optional<std::string> numeric_inner;  // --ff-numeric-inner: rules or lines
    std::optional<int> gauss_points;           // --gauss-points: the paper's fixed rule
    std::optional<bool> visibility;            // --no-visibility
    bool culling = true;                       // --no-culling (a diagnostic; bypasses the cache)
    CacheSettings cache;                       // --cache-dir, --no-cache
    bool strict = false;  // --strict: intersecting surfaces and missed tolerances are errors
    std::optional<double> solve_tolerance;  // --solve-tolerance: overrides the scene's solve: tolerance

    FormFactorOptions options_for(const Scene& scene) const {
        FormFactorOptions o =
            resolve_form_factor_options(scene.form_factors, method, tolerance, gauss_points, visibility,
                                        receiver_tolerance, scene.patch_count());
        o.culling = culling;
        // The scene's numeric_inner goes with its adaptive method: another method on the command
        // line leaves it out, as it does the scene's receiver_tolerance.
        const bool lines = numeric_inner ? *numeric_inner == "lines" : scene.form_factors.numeric_lines;
        if (numeric_inner && lines && o.method != FormFactorMethod::Adaptive)
            throw Error(std::string("--ff-numeric-inner lines belongs to the adaptive method, not ") +
                        method_name(o.method) + ": use --ff-method adaptive, or leave it out");
        o.numeric_lines = lines && o.method == FormFactorMethod::Adaptive;
        if (receiver_tolerance && o.method != FormFactorMethod::Hierarchical)
            throw Error(
                "--ff-receiver-tolerance belongs to the hierarchical method: add --ff-method "
                "hierarchical, or remove it");
        return o;
    }
};

}  // namespace radiosa
