#include "app/still.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "geometry/scene_geometry.h"
#include "render/camera.h"
#include "render/image_io.h"
#include "render/shading.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "util/atomic_file.h"
#include "util/stopwatch.h"
#include "app/report_json.h"

namespace radiosa {

StillReport run_still(const StillJob& job) {
    const Stopwatch total;
    StillReport r;
    for (const auto& out : job.outputs) check_image_output(out);
    if (job.report_path) check_output_path(*job.report_path);

    std::unique_ptr<tbb::global_control> limit;
    if (job.threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, job.threads);
    r.threads = job.threads > 0 ? job.threads : tbb::info::default_concurrency();

    Stopwatch clock;
    const Scene scene = load_scene(job.scene_path);
    const CameraDesc camera = load_camera(job.camera_path);
    const SceneGeometry geometry(scene);
    r.times.load_s = clock.seconds();
    r.scene_name = scene.name;
    r.surfaces = geometry.surface_count();
    r.patches = geometry.patch_count();
    r.closed = scene.closed;

    const FormFactorOptions ffo =
        job.form_factors.options_for(scene);
    r.ff_options = ffo;
    clock = Stopwatch();
    const FormFactors ff = obtain_form_factors(scene, geometry, ffo, job.form_factors.cache, job.warn, &r.cache);
    r.times.form_factors_s = clock.seconds();
    r.form_factor_stats = ff.stats;
    r.checks = check_form_factors(ff);
    if (r.checks.closure_worst_patch >= 0) {
        const Patch& p = geometry.patch(r.checks.closure_worst_patch);
        r.closure_worst_patch = geometry.surface_name(p.surface) + "[" + std::to_string(p.is) + "," +
                                std::to_string(p.it) + "]";
    }

    clock = Stopwatch();
    const Materials mat = patch_materials(scene, geometry);
    // A scene with no emission is black: nothing to factorise or solve.
    r.dark = std::all_of(mat.E.begin(), mat.E.end(), [](const Rgb& e) { return e == Rgb(0.0); });
    std::vector<Rgb> B(mat.E.size(), Rgb(0.0));
    if (!r.dark) {
        const RadiositySolver solver(ff.F, mat.rho, job.solver);
        if (const std::string w = check_steady_state(solver, mat.rho, mat.E, scene.closed, job.scene_path); !w.empty())
            job.warn(w);
        for (int c = 0; c < 3; ++c) {
            r.spectral_radius = std::max(r.spectral_radius, solver.stability(c).spectral_hi);
            r.condition_estimate = std::max(r.condition_estimate, solver.stability(c).condition);
        }
        B = solver.solve(mat.E);
        r.factorisations = solver.factorisations();
        r.channel_solves = solver.last_channel_solves();
        r.iterations = solver.last_iterations();
    }
    r.times.solve_s = clock.seconds();
    r.solve = diagnose_solution(ff.F, ff.area, mat, B);

    clock = Stopwatch();
    const NodeRadiosity nodes(geometry, B, mat.E);
    const PinholeCamera cam(camera, job.render.width, job.render.height);
    const Image img = render_image(geometry, nodes, cam, job.render);
    r.times.render_s = clock.seconds();

    clock = Stopwatch();
    for (const auto& out : job.outputs) write_image(img, out, job.exposure);
    r.times.write_s = clock.seconds();
    r.times.total_s = total.seconds();
    if (job.report_path) write_text_file(*job.report_path, still_report_json(job, r) + "\n");
    return r;
}

std::string still_report_json(const StillJob& job, const StillReport& r) {
    using nlohmann::json;
    json j;
    j["scene"] = job.scene_path;
    j["scene_name"] = r.scene_name;
    j["camera"] = job.camera_path;
    j["outputs"] = job.outputs;
    j["surfaces"] = r.surfaces;
    j["patches"] = r.patches;
    j["closed"] = r.closed;
    add_form_factor_method(j, r.ff_options);
    j["threads"] = r.threads;
    j["image"] = {{"width", job.render.width}, {"height", job.render.height},
                  {"samples_per_axis", job.render.samples}, {"exposure_stops", job.exposure}};
    j["timings"] = {{"load_s", r.times.load_s},       {"form_factors_s", r.times.form_factors_s},
                    {"solve_s", r.times.solve_s},     {"render_s", r.times.render_s},
                    {"write_s", r.times.write_s},     {"total_s", r.times.total_s}};
    // Closure and energy balance only mean something for a closed scene.
    j["closure_max_error"] = r.closed ? json(r.checks.closure_max_error) : json(nullptr);
    j["closure_worst_patch"] = r.closed ? json(r.closure_worst_patch) : json(nullptr);
    j["reciprocity_max_error"] = r.checks.reciprocity_max_error;
    j["energy_balance_error"] = r.closed ? json(r.solve.energy_balance_error) : json(nullptr);
    add_form_factor_checks(j, r.checks);
    j["form_factor_stats"] = form_factor_stats_json(r.form_factor_stats);
    j["form_factor_cache"] = cache_outcome_json(r.cache);
    j["left_out"] = left_out_json(r.ff_options, r.form_factor_stats, {r.factorisations, 3, r.channel_solves, 3, r.dark});
    j["solve"] = {{"method", solver_method_name(job.solver)},
                  {"skipped", r.dark ? json("no emission: the image is black") : json(nullptr)},
                  {"spectral_radius", r.spectral_radius},
                  {"condition_estimate", r.condition_estimate > 0 ? json(r.condition_estimate) : json(nullptr)},
                  {"factorisations", r.factorisations},
                  {"iterations", r.iterations},
                  {"residual", r.solve.residual},
                  {"emitted_power", {r.solve.emitted_power.r, r.solve.emitted_power.g, r.solve.emitted_power.b}},
                  {"absorbed_power", {r.solve.absorbed_power.r, r.solve.absorbed_power.g, r.solve.absorbed_power.b}}};
    return j.dump(2);
}

std::string still_summary(const StillJob& job, const StillReport& r) {
    char buf[256];
    std::ostringstream s;
    const FormFactorStats& st = r.form_factor_stats;
    s << "radiosa render " << job.scene_path << " (" << r.patches << " patches on " << r.surfaces
      << " surfaces), camera " << job.camera_path << "\n";
    std::snprintf(buf, sizeof buf, "  %-13s %8.3f s\n", "load", r.times.load_s);
    s << buf;
    std::snprintf(buf, sizeof buf, "  %-13s %8.3f s  %s, %lld pairs, %lld culled, %lld segment tests\n",
                  "form factors", r.times.form_factors_s, describe(r.ff_options).c_str(), st.pairs, st.pairs_culled,
                  st.segment_tests);
    s << buf << "  " << std::string(13, ' ') << "   cache " << cache_outcome_summary(r.cache) << "\n";
    std::snprintf(buf, sizeof buf, "  %-13s %8.3f s  %s, %d factorisation(s) for 3 channels, residual %.1e\n", "solve",
                  r.times.solve_s, solver_method_name(job.solver), r.factorisations, r.solve.residual);
    s << buf;
    std::snprintf(buf, sizeof buf, "  %-13s %8.3f s  %dx%d, %d rays/pixel, %d threads\n", "render", r.times.render_s,
                  job.render.width, job.render.height, job.render.samples * job.render.samples, r.threads);
    s << buf;
    std::snprintf(buf, sizeof buf, "  %-13s %8.3f s\n  %-13s %8.3f s\n", "write", r.times.write_s, "total",
                  r.times.total_s);
    s << buf;
    if (r.closed) {
        std::snprintf(buf, sizeof buf, "  closure max |sum_j F_ij - 1| = %.2e (worst: %s)\n",
                      r.checks.closure_max_error, r.closure_worst_patch.c_str());
        s << buf;
    }
    std::snprintf(buf, sizeof buf, "  reciprocity max |F_ij - A_j F_ji / A_i| = %.2e (relative %.2e, %.2f of the estimates)\n",
                  r.checks.reciprocity_abs_error, r.checks.reciprocity_max_error, r.checks.reciprocity_vs_estimate);
    s << buf;
    if (r.closed) {
        std::snprintf(buf, sizeof buf, "  energy balance |emitted - absorbed| / emitted = %.2e\n", r.solve.energy_balance_error);
        s << buf;
    }
    for (const auto& o : job.outputs) s << "  wrote " << o << "\n";
    if (job.report_path) s << "  wrote " << *job.report_path << "\n";
    return s.str();
}

}  // namespace radiosa
