#include "app/still.h"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "app/report_json.h"
#include "encode/encode.h"
#include "render/camera.h"
#include "render/shading.h"
#include "scene/camera.h"
#include "solve/link_solver.h"
#include "util/atomic_file.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {

// Over the hierarchy's links: sweeps of gather, push and pull, and an error estimate.
std::vector<Rgb> solve_still_links(const Prepared& p, const Materials& mat, StillReport* r) {
    const Hierarchy& h = *p.hierarchy;
    refuse_lossless(mat.rho, mat.E, p.scene.closed, p.scene.file);
    LinkSolution s = solve_links(h, mat.rho, mat.E);
    r->iterations = s.sweeps;
    r->radiosity_error_estimate = link_error_estimate(h, mat, s.B);
    r->solve = diagnose_links(h, mat, s.B);
    return std::move(s.B);
}

// Solves the three channels (nothing when the scene has no light) and fills the solve figures.
std::vector<Rgb> solve_still(const StillJob& job, const Prepared& p, const Materials& mat, StillReport* r) {
    // A scene with no emission is black: nothing to factorise or solve.
    r->dark = std::all_of(mat.E.begin(), mat.E.end(), [](const Rgb& e) { return e == Rgb(0.0); });
    if (p.hierarchy) return solve_still_links(p, mat, r);
    std::vector<Rgb> B(mat.E.size(), Rgb(0.0));
    if (!r->dark) {
        const RadiositySolver solver(p.ff.F, mat.rho, job.solver);
        if (const std::string w = check_steady_state(solver, mat.rho, mat.E, p.scene.closed, job.scene_path);
            !w.empty())
            job.warn(w);
        r->stability.add(solver);
        B = solver.solve(mat.E);
        r->factorisations = solver.factorisations();
        r->channel_solves = solver.last_channel_solves();
        r->iterations = solver.last_iterations();
        if (!p.ff.error.empty())
            r->radiosity_error_bound = radiosity_error_bound(solver, p.ff.F, p.ff.error, mat, B);
    } else if (!p.ff.error.empty()) {
        r->radiosity_error_bound = Rgb(0.0);
    }
    r->solve = diagnose_solution(p.ff.F, p.ff.area, mat, B);
    return B;
}

// One row per patch: its label, area and radiosity, to full precision.
std::string radiosity_csv(const SceneGeometry& g, const std::vector<Rgb>& B) {
    std::string csv = "patch,area,B_r,B_g,B_b\n";
    for (int i = 0; i < g.patch_count(); ++i) {
        const Rgb& b = B[static_cast<std::size_t>(i)];
        csv += fmt::format("\"{}\",{:.17g},{:.17g},{:.17g},{:.17g}\n", g.patch_label(i), g.patch(i).area, b.r,
                           b.g, b.b);
    }
    return csv;
}

}  // namespace

StillReport run_still(const StillJob& job) {
    const Stopwatch total;
    for (const auto& out : job.outputs) check_image_output(out);
    if (job.report_path) check_output_path(*job.report_path);
    if (job.radiosities_path) {
        if (!job.radiosities_path->ends_with(".csv"))
            throw Error("--radiosities " + *job.radiosities_path + ": write a .csv file");
        check_output_path(*job.radiosities_path);
    }
    const ThreadLimit limit(job.threads);

    Stopwatch clock;
    const CameraDesc camera = load_camera(job.camera_path);
    const double camera_s = clock.seconds();
    StillReport r(prepare(job.scene_path, job.form_factors, job.warn));
    const Prepared& p = r.prep;
    r.threads = limit.threads();
    r.times.load_s = p.load_s + camera_s;
    r.times.form_factors_s = p.form_factors_s;

    clock = Stopwatch();
    const Materials mat = patch_materials(p.scene);
    const std::vector<Rgb> B = solve_still(job, p, mat, &r);
    for (std::size_t k = 0; k < p.sensors.size(); ++k) {
        StillReport::SensorReading s{p.scene.sensors[k].name, Rgb(0.0), Rgb(0.0)};
        s.irradiance = sensor_irradiance(p.sensors[k], B, &s.error);
        r.sensors.push_back(s);
    }
    r.times.solve_s = clock.seconds();

    clock = Stopwatch();
    const NodeRadiosity nodes(p.geometry, B, mat.E);
    const PinholeCamera cam(camera, job.render.width, job.render.height);
    const Image img = render_image(p.geometry, nodes, cam, job.render);
    r.times.render_s = clock.seconds();

    clock = Stopwatch();
    for (const auto& out : job.outputs) write_image(img, out, job.exposure);
    r.times.write_s = clock.seconds();
    r.times.total_s = total.seconds();
    if (job.radiosities_path) write_text_file(*job.radiosities_path, radiosity_csv(p.geometry, B));
    if (job.report_path) write_text_file(*job.report_path, still_report_json(job, r) + "\n");
    return r;
}

std::string still_report_json(const StillJob& job, const StillReport& r) {
    using nlohmann::json;
    json j;
    j["scene"] = job.scene_path;
    add_prepared_json(j, r.prep);
    j["camera"] = job.camera_path;
    j["outputs"] = job.outputs;
    j["threads"] = r.threads;
    j["image"] = {{"width", job.render.width},
                  {"height", job.render.height},
                  {"samples_per_axis", job.render.samples},
                  {"exposure_stops", job.exposure}};
    j["timings"] = {{"load_s", r.times.load_s},   {"form_factors_s", r.times.form_factors_s},
                    {"solve_s", r.times.solve_s}, {"render_s", r.times.render_s},
                    {"write_s", r.times.write_s}, {"total_s", r.times.total_s}};
    // Energy balance only means something for a closed scene.
    j["energy_balance_error"] = r.prep.scene.closed ? json(r.solve.energy_balance_error) : json(nullptr);
    j["radiosity_error_bound"] = error_bound_json(r.radiosity_error_bound);
    j["radiosity_error_estimate"] = error_bound_json(r.radiosity_error_estimate);
    json sensors = json::array();
    for (const auto& s : r.sensors)
        sensors.push_back({{"name", s.name},
                           {"irradiance", {s.irradiance.r, s.irradiance.g, s.irradiance.b}},
                           {"irradiance_error", {s.error.r, s.error.g, s.error.b}}});
    j["sensors"] = sensors;
    j["left_out"] =
        left_out_json(r.prep.options, r.prep.ff.stats, {r.factorisations, 3, r.channel_solves, 3, r.dark});
    json& solve = j["solve"] = solve_json(job.solver, r.stability, r.solve.residual);
    if (r.prep.hierarchy) solve["method"] = "links", solve["spectral_radius"] = nullptr;  // not computed
    solve["skipped"] = r.dark ? json("no emission: the image is black") : json(nullptr);
    solve["factorisations"] = r.factorisations;
    solve["iterations"] = r.iterations;
    const Rgb& e = r.solve.emitted_power;
    const Rgb& a = r.solve.absorbed_power;
    solve["emitted_power"] = {e.r, e.g, e.b};
    solve["absorbed_power"] = {a.r, a.g, a.b};
    return j.dump(2);
}

std::string still_summary(const StillJob& job, const StillReport& r) {
    const Prepared& p = r.prep;
    std::string s = fmt::format("radiosa render {} ({} patches on {} surfaces), camera {}\n", job.scene_path,
                                p.geometry.patch_count(), p.geometry.surface_count(), job.camera_path);
    s += fmt::format("  {:<13} {:8.3f} s\n", "load", r.times.load_s);
    s += prepared_summary(p);
    if (p.hierarchy)
        s += fmt::format("  {:<13} {:8.3f} s  over the links, {} sweeps, residual {:.1e}\n", "solve",
                         r.times.solve_s, r.iterations, r.solve.residual);
    else
        s += fmt::format("  {:<13} {:8.3f} s  {}, {} factorisation(s) for 3 channels, residual {:.1e}\n",
                         "solve", r.times.solve_s, solver_method_name(job.solver), r.factorisations,
                         r.solve.residual);
    s += fmt::format("  {:<13} {:8.3f} s  {}x{}, {} rays/pixel, {} threads\n", "render", r.times.render_s,
                     job.render.width, job.render.height, job.render.samples * job.render.samples, r.threads);
    s += fmt::format("  {:<13} {:8.3f} s\n  {:<13} {:8.3f} s\n", "write", r.times.write_s, "total",
                     r.times.total_s);
    if (p.scene.closed)
        s += fmt::format("  energy balance |emitted - absorbed| / emitted = {:.2e}\n",
                         r.solve.energy_balance_error);
    s += error_bound_summary(r.radiosity_error_bound);
    if (const auto& e = r.radiosity_error_estimate)
        s += fmt::format("  radiosity error estimate max |B - B*| / max B: r {:.1e}, g {:.1e}, b {:.1e}\n",
                         e->r, e->g, e->b);
    for (const auto& x : r.sensors)
        s += fmt::format("  sensor {}: irradiance ({:.6g}, {:.6g}, {:.6g}) +- {:.2g}\n", x.name,
                         x.irradiance.r, x.irradiance.g, x.irradiance.b,
                         std::max({x.error.r, x.error.g, x.error.b}));
    for (const auto& o : job.outputs) s += "  wrote " + o + "\n";
    if (job.radiosities_path) s += "  wrote " + *job.radiosities_path + "\n";
    if (job.report_path) s += "  wrote " + *job.report_path + "\n";
    return s;
}

}  // namespace radiosa
