#pragma once
// The prefix every command shares: scene file -> geometry -> form factors (cached) -> checks.
// Commands call prepare() and differ only in what they do afterwards (render a still, a
// sequence, export the matrix).
#include <functional>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>

#include "app/form_factor_request.h"
#include "cache/cache_file.h"
#include "formfactor/form_factor.h"
#include "formfactor/hierarchy.h"
#include "formfactor/sensor.h"
#include "geometry/intersections.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/warnings.h"

namespace radiosa {

struct Prepared {
    explicit Prepared(Scene s) : scene(std::move(s)), geometry(scene) {}

    Scene scene;
    SceneGeometry geometry;
    FormFactorOptions options;  // as resolved from the command line and the scene file
    // The dense path: the matrix. The hierarchical method: the links in `hierarchy`, and ff
    // holds only the patch areas, the options and the pairs-of-patches statistics.
    FormFactors ff;
    std::optional<Hierarchy> hierarchy;
    CacheOutcome cache;
    FormFactorChecks checks;
    std::string closure_worst_patch;  // "surface[is,it]", "" when none
    std::vector<SurfaceIntersection> intersections;
    std::string worst_miss;  // "surface[is,it] -> surface[is,it]", "" when no entry misses
    // A target on the radiosity (scene solve: tolerance or --solve-tolerance) and how it went.
    struct SolveTarget {
        double tolerance = 0.0;  // asked: max |B - B*| / max B per channel
        double bound = 0.0;      // the bound reached for the scene's own lights and colours
        bool reached = false;
        int rounds = 0;  // form-factor computations it took (1: the first tolerance sufficed)
    };
    std::optional<SolveTarget> solve_target;
    std::vector<SensorFactors> sensors;  // per scene sensor, in order: F(dA -> every patch)
    double sensors_s = 0.0;              // computing them
    double load_s = 0.0;                 // reading the scene and building the geometry
    double form_factors_s = 0.0;         // computing or loading the matrix
};

// Reads the scene, builds its geometry, then (after `check_inputs`, which a command uses to
// read and check the rest of its inputs while nothing has been computed) obtains the form
// factors from the cache or computes them, and checks them. Throws Error for bad input.
Prepared prepare(const std::string& scene_path, const FormFactorRequest& request, const WarningSink& warn,
                 const std::function<void(const Prepared&)>& check_inputs = {});

// The report keys every command shares: scene_name, surfaces, patches, closed, the form-factor
// method keys, closure and reciprocity, the estimates, form_factor_stats, form_factor_cache
// (docs/cli.md, "Run report").
void add_prepared_json(nlohmann::json& j, const Prepared& p);
// The form-factor lines of the printed summary: method, cache, closure, reciprocity.
std::string prepared_summary(const Prepared& p);

// --threads N: limits oneTBB's workers for as long as it lives (0: all cores).
class ThreadLimit {
public:
    explicit ThreadLimit(int threads);
    int threads() const { return m_threads; }

private:
    std::shared_ptr<void> m_control;  // a tbb::global_control (kept out of this header)
    int m_threads;
};

}  // namespace radiosa
