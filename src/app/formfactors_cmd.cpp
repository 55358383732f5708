#include "app/formfactors_cmd.h"

#include <tbb/global_control.h>

#include <cstdio>
#include <memory>

#include "app/report_json.h"
#include "formfactor/matrix_export.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/atomic_file.h"
#include "util/stopwatch.h"

namespace radiosa {

std::string run_formfactors(const FormFactorsJob& job) {
    const Stopwatch total;
    if (job.matrix_path) check_matrix_output(*job.matrix_path);
    if (job.report_path) check_output_path(*job.report_path);
    std::unique_ptr<tbb::global_control> limit;
    if (job.threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, job.threads);

    Stopwatch clock;
    const Scene scene = load_scene(job.scene_path);
    const SceneGeometry geometry(scene);
    const double load_s = clock.seconds();

    const FormFactorOptions ffo =
        job.form_factors.options_for(scene);
    clock = Stopwatch();
    CacheOutcome cache;
    const FormFactors ff = obtain_form_factors(scene, geometry, ffo, job.form_factors.cache, job.warn, &cache);
    const double ff_s = clock.seconds();
    const FormFactorChecks checks = check_form_factors(ff);

    clock = Stopwatch();
    if (job.matrix_path) write_matrix(*job.matrix_path, geometry, ff);
    const double export_s = clock.seconds();

    const std::string worst = checks.closure_worst_patch >= 0 ? patch_label(geometry, checks.closure_worst_patch) : "";
    if (job.report_path) {
        using nlohmann::json;
        json j;
        j["scene"] = job.scene_path;
        j["scene_name"] = scene.name;
        j["surfaces"] = geometry.surface_count();
        j["patches"] = geometry.patch_count();
        j["closed"] = scene.closed;
        add_form_factor_method(j, ffo);
        j["matrix"] = job.matrix_path ? json(*job.matrix_path) : json(nullptr);
        j["closure_max_error"] = scene.closed ? json(checks.closure_max_error) : json(nullptr);
        j["closure_worst_patch"] = scene.closed ? json(worst) : json(nullptr);
        j["reciprocity_max_error"] = checks.reciprocity_max_error;
        j["min_entry"] = checks.min_entry;
        add_form_factor_checks(j, checks);
        j["form_factor_stats"] = form_factor_stats_json(ff.stats);
        j["form_factor_cache"] = cache_outcome_json(cache);
        j["timings"] = {{"load_s", load_s}, {"form_factors_s", ff_s}, {"export_s", export_s},
                        {"total_s", total.seconds()}};
        write_text_file(*job.report_path, j.dump(2) + "\n");
    }

    char buf[256];
    std::string s = "radiosa formfactors " + job.scene_path + " (" + std::to_string(geometry.patch_count()) +
                    " patches on " + std::to_string(geometry.surface_count()) + " surfaces)\n";
    std::snprintf(buf, sizeof buf, "  form factors %8.3f s  %s, visibility %s\n", ff_s, describe(ffo).c_str(),
                  ffo.visibility ? "on" : "off");
    s += buf;
    s += "               cache " + cache_outcome_summary(cache) + "\n";
    if (scene.closed) {
        std::snprintf(buf, sizeof buf, "  closure max |sum_j F_ij - 1| = %.2e (worst: %s)\n", checks.closure_max_error,
                      worst.c_str());
        s += buf;
    }
    std::snprintf(buf, sizeof buf, "  reciprocity max |A_i F_ij - A_j F_ji| / max = %.2e, max |F_ij - A_j F_ji / A_i| = %.2e\n",
                  checks.reciprocity_max_error, checks.reciprocity_abs_error);
    s += buf;
    if (!ff.error.empty()) {
        std::snprintf(buf, sizeof buf, "  error estimates: max per entry %.2e, max per row %.2e\n",
                      checks.max_error_estimate, checks.max_row_error_estimate);
        s += buf;
    }
    if (job.matrix_path) {
        s += "  wrote " + *job.matrix_path;
        if (npy_patch_table_path(*job.matrix_path) != *job.matrix_path && job.matrix_path->ends_with(".npy"))
            s += " and " + npy_patch_table_path(*job.matrix_path).string();
        s += "\n";
    }
    return s;
}

}  // namespace radiosa
