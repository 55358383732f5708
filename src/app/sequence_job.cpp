#include "app/sequence_job.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <condition_variable>
#include <cstdio>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "app/report_json.h"
#include "encode/features.h"
#include "encode/frame_sink.h"
#include "geometry/scene_geometry.h"
#include "render/camera.h"
#include "render/shading.h"
#include "scene/scene.h"
#include "schedule/sequence.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {

// Frames go to the outputs on their own thread while the next frames render. The queue is
// short so that memory stays bounded; an output failure stops the job at the next frame.
class EncoderThread {
public:
    EncoderThread(std::vector<std::unique_ptr<FrameSink>> sinks, std::vector<FrameRecord>* records)
        : m_sinks(std::move(sinks)), m_records(records), m_thread([this] { loop(); }) {}
    ~EncoderThread() {
        close();
        if (m_thread.joinable()) m_thread.join();
    }

    void push(int frame, std::shared_ptr<const Image> image) {
        std::unique_lock lock(m_mutex);
        m_space.wait(lock, [&] { return m_queue.size() < 4 || m_error; });
        if (m_error) std::rethrow_exception(m_error);
        m_queue.emplace_back(frame, std::move(image));
        m_ready.notify_one();
    }
    // Waits for every frame, completes the outputs; rethrows an output failure.
    void finish() {
        close();
        m_thread.join();
        if (m_error) std::rethrow_exception(m_error);
        for (auto& s : m_sinks) s->finish();
    }

private:
    void close() {
        std::lock_guard lock(m_mutex);
        m_closed = true;
        m_ready.notify_one();
    }
    void loop() {
        for (;;) {
            std::pair<int, std::shared_ptr<const Image>> item;
            {
                std::unique_lock lock(m_mutex);
                m_ready.wait(lock, [&] { return !m_queue.empty() || m_closed; });
                if (m_queue.empty()) return;
                item = std::move(m_queue.front());
                m_queue.pop_front();
                m_space.notify_one();
            }
            try {
                const Stopwatch clock;
                for (auto& s : m_sinks) s->write(item.first, *item.second);
                (*m_records)[item.first].encode_s = clock.seconds();
            } catch (...) {
                std::lock_guard lock(m_mutex);
                m_error = std::current_exception();
                m_space.notify_all();
                return;
            }
        }
    }

    std::vector<std::unique_ptr<FrameSink>> m_sinks;
    std::vector<FrameRecord>* m_records;
    std::mutex m_mutex;
    std::condition_variable m_ready, m_space;
    std::deque<std::pair<int, std::shared_ptr<const Image>>> m_queue;
    bool m_closed = false;
    std::exception_ptr m_error;
    std::thread m_thread;
};

bool is_gif(const std::string& path) { return path.ends_with(".gif") || path.ends_with(".GIF"); }

void check_palette_output(const std::string& path) {
    if (!kHasVideo) throw Error(path + ": --palette: " + kNoVideoMessage);
    if (is_gif(path)) {
        check_output_path(path);
        return;
    }
    if (!path.ends_with(".png") || path.find('%') == std::string::npos)
        throw Error(path + ": with --palette, write a .gif or numbered indexed PNGs such as out/frames/%04d.png");
    check_sequence_output(path, 2, 2);
}

// Builds both palettes from the whole sequence, reports how close each comes to the
// true-colour frames, and writes the chosen one's frames.
void write_palette_outputs(const SequenceJob& job, const RenderOptions& ro, double fps,
                           const std::vector<std::vector<std::uint8_t>>& frames, const ColourHistogram& histogram,
                           SequenceReport::PaletteResult* result) {
    for (Quantiser q : {Quantiser::MedianCut, Quantiser::Popularity}) {
        PaletteMapper mapper(histogram.palette(job.palette, q));
        PsnrAccumulator psnr;
        std::vector<std::vector<std::uint8_t>> indexed;
        for (const auto& f : frames) {
            indexed.push_back(mapper.map(f));
            psnr.add(f, indexed.back(), mapper.palette());
        }
        (q == Quantiser::MedianCut ? result->psnr_median_cut_db : result->psnr_popularity_db) = psnr.psnr_db();
        if (q != job.quantiser) continue;
        result->colours = static_cast<int>(mapper.palette().size());
        for (const auto& o : job.outputs) {
            if (is_gif(o)) {
                GifWriter gif(o, ro.width, ro.height, fps, mapper.palette());
                for (const auto& ix : indexed) gif.add_frame(ix);
                gif.finish();
            } else {
                for (std::size_t k = 0; k < indexed.size(); ++k)
                    write_indexed_png(frame_path(o, static_cast<int>(k)), ro.width, ro.height, indexed[k],
                                      mapper.palette());
            }
        }
    }
}

void print_progress(std::ostream& out, int done, int total, double elapsed) {
    const double rate = elapsed > 0 ? done / elapsed : 0.0;
    const double eta = rate > 0 ? (total - done) / rate : 0.0;
    const int width = 30, filled = total > 0 ? done * width / total : width;
    char buf[160];
    std::snprintf(buf, sizeof buf, "\r  [%s%s] %d/%d frames  %.1f frames/s  ETA %.0f s ",
                  std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), done, total, rate, eta);
    out << buf << std::flush;
}

}  // namespace

SequenceReport run_sequence_job(const SequenceJob& job) {
    const Stopwatch total;
    SequenceReport r;
    if (job.report_path) check_output_path(*job.report_path);
    std::unique_ptr<tbb::global_control> limit;
    if (job.threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, job.threads);
    r.threads = job.threads > 0 ? job.threads : tbb::info::default_concurrency();

    Stopwatch clock;
    r.scene_path = job.scene_path.empty() ? sequence_scene_path(job.sequence_path) : job.scene_path;
    if (r.scene_path.empty())
        throw Error(job.sequence_path + ": the sequence names no scene; add 'scene: path' to it or give SCENE.yaml");
    const Scene scene = load_scene(r.scene_path);
    const Sequence seq = load_sequence(job.sequence_path, &scene);
    RenderOptions& ro = r.render;
    ro.width = job.width.value_or(seq.width.value_or(ro.width));
    ro.height = job.height.value_or(seq.height.value_or(ro.height));
    ro.samples = job.samples.value_or(seq.samples.value_or(ro.samples));
    for (const auto& o : job.outputs) {
        if (job.palette > 0) check_palette_output(o);
        else check_sequence_output(o, ro.width, ro.height);
    }
    const SceneGeometry geometry(scene);
    const Materials base = patch_materials(scene, geometry);
    const Plan plan = plan_sequence(seq, base, geometry);
    r.load_s = clock.seconds();
    r.scene_name = scene.name;
    r.patches = geometry.patch_count();
    r.closed = scene.closed;
    r.surfaces = geometry.surface_count();
    r.fps = seq.fps;

    std::vector<FrameRecord>& frames = r.frames;
    frames.resize(plan.frames.size());
    for (std::size_t f = 0; f < frames.size(); ++f) frames[f].plan = plan.frames[f];

    // Form factors: once for the whole sequence.
    const FormFactorOptions ffo =
        job.form_factors.options_for(scene);
    r.ff_options = ffo;
    clock = Stopwatch();
    const FormFactors ff = obtain_form_factors(scene, geometry, ffo, job.form_factors.cache, job.warn, &r.cache);
    frames[0].form_factors_s = clock.seconds();
    frames[0].form_factors = r.cache.status == CacheStatus::Hit ? "cached" : "computed";
    r.form_factor_stats = ff.stats;

    std::vector<std::unique_ptr<FrameSink>> sinks;
    SinkOptions so;
    so.fps = seq.fps;
    so.exposure = job.exposure;
    so.crf = job.crf;
    if (job.palette == 0)
        for (const auto& o : job.outputs) sinks.push_back(make_frame_sink(o, ro.width, ro.height, so));
    // With a palette the frames are kept (8-bit) until every frame has added to the histogram.
    std::vector<std::vector<std::uint8_t>> kept;
    ColourHistogram histogram;
    EncoderThread encoder(std::move(sinks), &frames);

    // Every factorisation the plan needs, before any frame is written, so that a system with no
    // steady state is refused with nothing on disk; each one's time is charged to the frame
    // that first uses it.
    std::vector<std::unique_ptr<RadiositySolver>> solvers;
    for (const auto& rho : plan.reflectances) {
        solvers.push_back(std::make_unique<RadiositySolver>(ff.F, rho, job.solver));
        r.factorisations += solvers.back()->factorisations();
        for (int c = 0; c < 3; ++c) {
            r.spectral_radius = std::max(r.spectral_radius, solvers.back()->stability(c).spectral_hi);
            r.condition_estimate = std::max(r.condition_estimate, solvers.back()->stability(c).condition);
        }
    }
    {
        std::string last_warning;
        for (const auto& fp : plan.frames) {
            if (fp.solve == SolveAction::Reused) continue;
            const std::string w = check_steady_state(*solvers[fp.reflectance_set], plan.reflectances[fp.reflectance_set],
                                                     plan.solutions[fp.solution].E, scene.closed, job.sequence_path);
            if (!w.empty() && w != last_warning) job.warn(last_warning = w);
        }
    }
    std::vector<std::vector<Rgb>> solutions(plan.solutions.size());
    std::unique_ptr<NodeRadiosity> nodes;
    int nodes_solution = -1;
    std::shared_ptr<const Image> image;
    const Stopwatch loop_clock;
    for (std::size_t f = 0; f < frames.size(); ++f) {
        FrameRecord& rec = frames[f];
        const FramePlan& fp = rec.plan;
        clock = Stopwatch();
        if (fp.solve != SolveAction::Reused) {
            const auto& solver = solvers[fp.reflectance_set];
            if (fp.solve == SolveAction::Factorised) rec.solve_s += solver->factorise_seconds();
            solutions[fp.solution] = solver->solve(plan.solutions[fp.solution].E);
            r.channel_solves += solver->last_channel_solves();
        }
        // += keeps the factorisation charged above (it ran in the prepass).
        rec.solve_s += clock.seconds();
        if (fp.solve != SolveAction::Reused) {  // diagnostics, not timed as solving
            const SolveDiagnostics d =
                diagnose_solution(ff.F, ff.area, {plan.reflectances[fp.reflectance_set], plan.solutions[fp.solution].E},
                                  solutions[fp.solution]);
            r.residual = std::max(r.residual, d.residual);
            if (scene.closed) r.energy_balance_error = std::max(r.energy_balance_error, d.energy_balance_error);
        }
        clock = Stopwatch();
        if (fp.render == RenderAction::Rendered) {
            if (nodes_solution != fp.solution) {
                nodes = std::make_unique<NodeRadiosity>(geometry, solutions[fp.solution], plan.solutions[fp.solution].E);
                nodes_solution = fp.solution;
            }
            const PinholeCamera cam(fp.camera, ro.width, ro.height);
            image = std::make_shared<const Image>(render_image(geometry, *nodes, cam, ro));
            ++r.renders;
        } else {
            ++r.copies;
        }
        rec.render_s = clock.seconds();
        if (job.on_frame) job.on_frame(static_cast<int>(f), *image);
        if (job.palette > 0) {
            kept.push_back(to_srgb8(*image, job.exposure));
            histogram.add(kept.back());
        } else {
            encoder.push(static_cast<int>(f), image);
        }
        if (job.progress) print_progress(*job.progress, static_cast<int>(f + 1), seq.frames, loop_clock.seconds());
    }
    encoder.finish();
    if (job.progress) *job.progress << "\n";
    if (job.palette > 0) {
        clock = Stopwatch();
        write_palette_outputs(job, ro, seq.fps, kept, histogram, &r.palette);
        r.palette.seconds = clock.seconds();
    }

    r.substitutions = plan.substitutions();
    r.reflectance_sets = plan.factorisations();
    for (const auto& rec : frames) {
        r.form_factors_s += rec.form_factors_s;
        r.solve_s += rec.solve_s;
        r.render_s += rec.render_s;
        r.encode_s += rec.encode_s;
    }
    r.total_s = total.seconds();
    if (job.report_path) write_text_file(*job.report_path, sequence_report_json(job, r) + "\n");
    return r;
}

std::string sequence_report_json(const SequenceJob& job, const SequenceReport& r) {
    using nlohmann::json;
    json j;
    j["scene"] = r.scene_path;
    j["scene_name"] = r.scene_name;
    j["sequence"] = job.sequence_path;
    j["outputs"] = job.outputs;
    j["surfaces"] = r.surfaces;
    j["patches"] = r.patches;
    add_form_factor_method(j, r.ff_options);
    j["threads"] = r.threads;
    j["fps"] = r.fps;
    j["frame_count"] = r.frames.size();
    j["duration_s"] = r.frames.size() / r.fps;
    j["image"] = {{"width", r.render.width}, {"height", r.render.height},
                  {"samples_per_axis", r.render.samples}, {"exposure_stops", job.exposure}, {"crf", job.crf}};
    j["form_factor_cache"] = cache_outcome_json(r.cache);
    j["form_factor_stats"] = form_factor_stats_json(r.form_factor_stats);
    j["left_out"] = left_out_json(r.ff_options, r.form_factor_stats,
                                  {r.factorisations, 3 * r.reflectance_sets, r.channel_solves, 3 * r.substitutions, false});
    j["solve"] = {{"method", solver_method_name(job.solver)},
                  {"spectral_radius", r.spectral_radius},
                  {"condition_estimate", r.condition_estimate > 0 ? json(r.condition_estimate) : json(nullptr)},
                  {"residual", r.residual},
                  {"energy_balance_error", r.closed ? json(r.energy_balance_error) : json(nullptr)}};
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
    json frames = json::array();
    for (const FrameRecord& f : r.frames)
        frames.push_back({{"frame", f.plan.frame},
                          {"time_s", f.plan.time_s},
                          {"form_factors", f.form_factors},
                          {"solve", solve_action_name(f.plan.solve)},
                          {"render", render_action_name(f.plan.render)},
                          {"form_factors_s", f.form_factors_s},
                          {"solve_s", f.solve_s},
                          {"render_s", f.render_s},
                          {"encode_s", f.encode_s}});
    j["frames"] = frames;
    j["palette"] = job.palette > 0 ? json{{"colours", r.palette.colours},
                                          {"quantiser", quantiser_name(job.quantiser)},
                                          {"psnr_db", {{"median-cut", r.palette.psnr_median_cut_db},
                                                       {"popularity", r.palette.psnr_popularity_db}}},
                                          {"seconds", r.palette.seconds}}
                                    : json(nullptr);
    return j.dump(2);
}

std::string sequence_summary(const SequenceJob& job, const SequenceReport& r) {
    char buf[256];
    std::string s = "radiosa render " + r.scene_path + " (" + std::to_string(r.patches) + " patches), sequence " +
                    job.sequence_path + ": " + std::to_string(r.frames.size()) + " frames at " +
                    std::to_string(static_cast<int>(r.fps)) + " fps\n";
    std::snprintf(buf, sizeof buf, "  %-13s %8.3f s\n", "load", r.load_s);
    s += buf;
    std::snprintf(buf, sizeof buf, "  %-13s %8.3f s  once, cache %s\n", "form factors", r.form_factors_s,
                  cache_status_name(r.cache.status));
    s += buf;
    std::snprintf(buf, sizeof buf,
                  "  %-13s %8.3f s  %d reflectance set(s): %d channel factorisation(s); %d distinct "
                  "state(s) solved: %d channel substitution(s); %zu frames\n",
                  "solve", r.solve_s, r.reflectance_sets, r.factorisations, r.substitutions, r.channel_solves,
                  r.frames.size());
    s += buf;
    std::snprintf(buf, sizeof buf, "  %-13s %8.3f s  %d rendered, %d copied, %dx%d, %d rays/pixel, %d threads\n",
                  "render", r.render_s, r.renders, r.copies, r.render.width, r.render.height,
                  r.render.samples * r.render.samples, r.threads);
    s += buf;
    std::snprintf(buf, sizeof buf, "  %-13s %8.3f s  (on its own thread, overlapping rendering)\n", "encode",
                  r.encode_s);
    s += buf;
    std::snprintf(buf, sizeof buf, "  %-13s %8.3f s  (%.1f frames/s)\n", "total", r.total_s,
                  r.frames.size() / std::max(r.total_s, 1e-9));
    s += buf;
    if (job.palette > 0) {
        std::snprintf(buf, sizeof buf,
                      "  %-13s %8.3f s  %d colours (%s) for all frames; PSNR vs true colour: median cut %.2f dB, "
                      "popularity %.2f dB\n",
                      "palette", r.palette.seconds, r.palette.colours, quantiser_name(job.quantiser),
                      r.palette.psnr_median_cut_db, r.palette.psnr_popularity_db);
        s += buf;
    }
    for (const auto& o : job.outputs) s += "  wrote " + o + "\n";
    if (job.report_path) s += "  wrote " + *job.report_path + "\n";
    return s;
}

}  // namespace radiosa
