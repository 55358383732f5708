// The sequence job's run report (JSON, docs/cli.md) and its closing summary.
#include <fmt/format.h>

#include <string_view>

#include "app/report_json.h"
#include "app/sequence_job.h"

namespace radiosa {

namespace {

nlohmann::json update_json(const std::optional<FormFactorUpdate>& u) {
    if (!u) return nullptr;
    return {{"surfaces_moved", u->surfaces_moved},
            {"pairs_moved", u->pairs_moved},
            {"pairs_shadowed", u->pairs_shadowed},
            {"pairs_unchanged", u->pairs_unchanged},
            {"full_recompute", u->full ? nlohmann::json(u->reason) : nlohmann::json(nullptr)},
            {"select_s", u->select_s},
            {"compute_s", u->compute_s},
            {"seconds", u->seconds}};
}

// What the incremental updates of a sequence did, summed over its frames.
struct UpdateTotals {
    long long recomputed = 0, total = 0, updated = 0, cached = 0;  // cached: states after frame 0
    double seconds = 0.0;
    double fraction() const { return total > 0 ? static_cast<double>(recomputed) / total : 0.0; }
};

UpdateTotals update_totals(const SequenceReport& r) {
    UpdateTotals u;
    for (const FrameRecord& f : r.frames) {
        if (f.update) {
            ++u.updated;
            u.recomputed += f.update->entries_recomputed;
            u.total += f.update->entries_total;
            u.seconds += f.update->seconds;
        }
        if (f.form_factors == std::string_view("cached") && &f != &r.frames[0]) ++u.cached;
    }
    return u;
}

// The sequence's geometry states and what obtaining them cost (null without motion).
nlohmann::json motion_json(const SequenceReport& r) {
    if (!r.moves) return nullptr;
    const UpdateTotals u = update_totals(r);
    return {{"geometry_states", r.geometry_states},
            {"states_updated", u.updated},
            {"states_cached", u.cached},
            {"entries_recomputed", u.recomputed},
            {"entries_total", u.total},
            {"recomputed_fraction", u.fraction()},
            {"update_s", u.seconds},
            {"closure_max_error", r.prep->scene.closed ? nlohmann::json(r.closure_max_error_over_states)
                                                       : nlohmann::json(nullptr)}};
}

}  // namespace

std::string sequence_report_json(const SequenceJob& job, const SequenceReport& r) {
    using nlohmann::json;
    json j;
    j["scene"] = r.scene_path;
    add_prepared_json(j, *r.prep);
    j["sequence"] = job.sequence_path;
    j["outputs"] = job.outputs;
    j["threads"] = r.threads;
    j["ranks"] = r.ranks;
    j["fps"] = r.fps;
    j["frame_count"] = r.frames.size();
    j["duration_s"] = r.frames.size() / r.fps;
    j["image"] = {{"width", r.render.width},
                  {"height", r.render.height},
                  {"samples_per_axis", r.render.samples},
                  {"exposure_stops", job.exposure},
                  {"crf", job.crf}};
    j["left_out"] = left_out_json(
        r.prep->options, r.prep->ff.stats,
        {r.factorisations, 3 * r.reflectance_sets, r.channel_solves, 3 * r.substitutions, false});
    j["solve"] = solve_json(r.solver, r.stability, r.residual);
    if (r.prep->hierarchy) j["solve"]["method"] = "links", j["solve"]["spectral_radius"] = nullptr;
    j["solve"]["energy_balance_error"] = r.prep->scene.closed ? json(r.energy_balance_error) : json(nullptr);
    j["radiosity_error_bound"] = error_bound_json(r.radiosity_error_bound);
    j["radiosity_error_estimate"] = error_bound_json(r.radiosity_error_estimate);
    j["totals"] = {{"load_s", r.load_s},
                   {"form_factors_s", r.form_factors_s},
                   {"solve_s", r.solve_s},
                   {"render_s", r.render_s},
                   {"encode_s", r.encode_s},
                   {"total_s", r.total_s},
                   {"reflectance_sets", r.reflectance_sets},
                   {"factorisations", r.factorisations},
                   {"solves", r.substitutions},
                   {"channel_solves", r.channel_solves},
                   {"renders", r.renders},
                   {"copies", r.copies}};
    // What a full computation makes: the matrix's entries, or the hierarchy's links.
    const long long entries_total =
        r.prep->hierarchy
            ? r.prep->hierarchy->stats.links
            : static_cast<long long>(r.prep->geometry.patch_count()) * r.prep->geometry.patch_count();
    j["motion"] = motion_json(r);
    json frames = json::array();
    for (const FrameRecord& f : r.frames) {
        json sensors = json::array();
        const auto s = static_cast<std::size_t>(f.plan.solution);
        if (s < r.sensor_irradiance.size())
            for (std::size_t k = 0; k < r.sensor_irradiance[s].size(); ++k) {
                const Rgb& e = r.sensor_irradiance[s][k];
                sensors.push_back({{"name", r.prep->scene.sensors[k].name}, {"irradiance", {e.r, e.g, e.b}}});
            }
        frames.push_back({{"frame", f.plan.frame},
                          {"time_s", f.plan.time_s},
                          {"form_factors", f.form_factors},
                          {"entries_recomputed", f.entries_recomputed},
                          {"entries_total", entries_total},
                          {"form_factor_update", update_json(f.update)},
                          {"solve", solve_action_name(f.plan.solve)},
                          {"render", render_action_name(f.plan.render)},
                          {"rank", f.rank},
                          {"form_factors_s", f.form_factors_s},
                          {"solve_s", f.solve_s},
                          {"sweeps", f.sweeps},
                          {"render_s", f.render_s},
                          {"encode_s", f.encode_s},
                          {"sensors", sensors}});
    }
    j["frames"] = frames;
    j["palette"] = job.palette > 0 ? json{{"colours", r.palette.colours},
                                          {"quantiser", quantiser_name(job.quantiser)},
                                          {"psnr_db",
                                           {{"median-cut", r.palette.psnr_median_cut_db},
                                            {"popularity", r.palette.psnr_popularity_db}}},
                                          {"seconds", r.palette.seconds}}
                                   : json(nullptr);
    return j.dump(2);
}

std::string sequence_summary(const SequenceJob& job, const SequenceReport& r) {
    const std::size_t n = r.frames.size();
    std::string s =
        fmt::format("radiosa render {} ({} patches), sequence {}: {} frames at {} fps\n", r.scene_path,
                    r.prep->geometry.patch_count(), job.sequence_path, n, static_cast<int>(r.fps));
    s += fmt::format("  {:<13} {:8.3f} s\n", "load", r.load_s);
    s += fmt::format("  {:<13} {:8.3f} s  once, cache {}\n", "form factors", r.form_factors_s,
                     cache_status_name(r.prep->cache.status));
    if (r.moves) {
        const UpdateTotals u = update_totals(r);
        s += fmt::format(
            "  {:<13}    {} geometry states, {} updated: {} of {} entries recomputed ({:.2f} %)\n", "moving",
            r.geometry_states, u.updated, u.recomputed, u.total, 100.0 * u.fraction());
    }
    s += fmt::format(
        "  {:<13} {:8.3f} s  {} reflectance set(s): {} channel factorisation(s); {} distinct "
        "state(s) solved: {} channel substitution(s); {} frames\n",
        "solve", r.solve_s, r.reflectance_sets, r.factorisations, r.substitutions, r.channel_solves, n);
    s += fmt::format("  {:<13} {:8.3f} s  {} rendered, {} copied, {}x{}, {} rays/pixel, {} threads\n",
                     "render", r.render_s, r.renders, r.copies, r.render.width, r.render.height,
                     r.render.samples * r.render.samples, r.threads);
    s +=
        fmt::format("  {:<13} {:8.3f} s  (on its own thread, overlapping rendering)\n", "encode", r.encode_s);
    s += fmt::format("  {:<13} {:8.3f} s  ({:.1f} frames/s)\n", "total", r.total_s,
                     n / std::max(r.total_s, 1e-9));
    if (job.palette > 0)
        s += fmt::format(
            "  {:<13} {:8.3f} s  {} colours ({}) for all frames; PSNR vs true colour: median cut {:.2f} "
            "dB, popularity {:.2f} dB\n",
            "palette", r.palette.seconds, r.palette.colours, quantiser_name(job.quantiser),
            r.palette.psnr_median_cut_db, r.palette.psnr_popularity_db);
    s += error_bound_summary(r.radiosity_error_bound);
    if (const auto& e = r.radiosity_error_estimate) {
        int sweeps = 0;
        for (const FrameRecord& f : r.frames) sweeps += f.sweeps;
        s += fmt::format(
            "  over links: {} sweeps in all, warm-started; radiosity error estimate max |B - B*| / max B: "
            "r {:.1e}, g {:.1e}, b {:.1e}\n",
            sweeps, e->r, e->g, e->b);
    }
    for (const auto& o : job.outputs) s += "  wrote " + o + "\n";
    if (job.report_path) s += "  wrote " + *job.report_path + "\n";
    return s;
}

}  // namespace radiosa
