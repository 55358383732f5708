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
        case FormFactorMethod::Hierarchical:
            return "hierarchical";
    }
    return "?";
}

FormFactorOptions resolve_form_factor_options(const FormFactorSettings& scene,
                                              std::optional<std::string> method,
                                              std::optional<double> tolerance,
                                              std::optional<int> gauss_points, std::optional<bool> visibility,
                                              std::optional<double> receiver_tolerance, int patches) {
    // The command line first, then the scene file; either names one method. A command-line
    // tolerance keeps the scene's hierarchical method (it is then the links' tolerance).
    const std::string scene_method = scene.hierarchical   ? "hierarchical"
                                     : scene.gauss_points ? "gauss"
                                                          : "adaptive";
    std::string m = method         ? *method
                    : gauss_points ? "gauss"
                    : tolerance    ? (scene.hierarchical ? "hierarchical" : "adaptive")
                                   : scene_method;
    const bool own = tolerance || (m == scene_method && scene.tolerance);  // a tolerance given for m
    const double tol = tolerance ? *tolerance : own ? *scene.tolerance : 0.0;
    FormFactorOptions o;
    if (m == "gauss")
        o = FormFactorOptions::gauss(gauss_points.value_or(scene.gauss_points.value_or(6)));
    else if (m == "hierarchical")
        o = FormFactorOptions::hierarchical(own ? tol : kDefaultLinkTolerance);
    else
        o = FormFactorOptions::adaptive(own ? tol : kDefaultFormFactorTolerance);
    // The command line's receiver tolerance, else the scene's (0: off), else the automatic one
    // up to kAutoReceiverMaxPatches; never above the link tolerance.
    const std::optional<double> rt = receiver_tolerance   ? receiver_tolerance
                                     : scene.hierarchical ? scene.receiver_tolerance
                                                          : std::nullopt;
    if (m == "hierarchical")
        o.receiver_tolerance = rt                                   ? std::min(*rt, o.link_tolerance)
                               : patches <= kAutoReceiverMaxPatches ? kAutoReceiverFraction * o.link_tolerance
                                                                    : 0.0;
    o.visibility = visibility.value_or(scene.visibility);
    return o;
}

std::string describe(const FormFactorOptions& o) {
    const long long p = o.gauss_points;
    switch (o.method) {
        case FormFactorMethod::Fixed:
            return fmt::format("Gauss p = {} ({} terms/pair)", p, p * p * p * p);
        case FormFactorMethod::Adaptive:
            return fmt::format("adaptive, tolerance {:.0e}{}", o.tolerance,
                               o.numeric_lines ? ", numeric inner integrals along lines" : "");
        case FormFactorMethod::Hierarchical:
            if (o.receiver_tolerance > 0.0)
                return fmt::format(
                    "hierarchical, link tolerance {:.0e}, receivers {:.0e} (pairs of patches {:.0e})",
                    o.link_tolerance, o.receiver_tolerance, o.tolerance);
            return fmt::format("hierarchical, link tolerance {:.0e} (pairs of patches {:.0e})",
                               o.link_tolerance, o.tolerance);
    }
    return "?";
}

}  // namespace radiosa
