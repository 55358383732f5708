// The form-factor method's names, the options a run resolves from the command line and the scene,
// and their one-line description.
#include <fmt/format.h>

#include "formfactor/form_factor.h"
#include "scene/scene.h"

namespace radiosa {

const char* method_name(FormFactorMethod m) {
    switch (m) {
        case FormFactorMethod::Fixed:
            return "gauss";
        case FormFactorMethod::Adaptive:
            return "adaptive";
    }
    return "?";
}

FormFactorOptions resolve_form_factor_options(const FormFactorSettings& scene,
                                              std::optional<double> tolerance,
                                              std::optional<int> gauss_points,
                                              std::optional<bool> visibility) {
    FormFactorOptions o;
    // The command line first, then the scene file; either names one method.
    if (gauss_points)
        o = FormFactorOptions::gauss(*gauss_points);
    else if (tolerance)
        o = FormFactorOptions::adaptive(*tolerance);
    else if (scene.gauss_points)
        o = FormFactorOptions::gauss(*scene.gauss_points);
    else
        o = FormFactorOptions::adaptive(scene.tolerance.value_or(kDefaultFormFactorTolerance));
    o.visibility = visibility.value_or(scene.visibility);
    return o;
}

std::string describe(const FormFactorOptions& o) {
    const long long p = o.gauss_points;
    switch (o.method) {
        case FormFactorMethod::Fixed:
            return fmt::format("Gauss p = {} ({} terms/pair)", p, p * p * p * p);
        case FormFactorMethod::Adaptive:
            return fmt::format("adaptive, tolerance {:.0e}", o.tolerance);
    }
    return "?";
}

}  // namespace radiosa
