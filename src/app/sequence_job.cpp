#include "app/sequence_job.h"

#include <fmt/format.h>
#include <tbb/concurrent_queue.h>

#include <atomic>
#include <exception>
#include <memory>
#include <thread>

#include "app/geometry_states.h"
#include "app/pipeline.h"
#include "app/report_json.h"
#include "distribute/cluster.h"
#include "distribute/frames.h"
#include "encode/encode.h"
#include "encode/features.h"
#include "geometry/scene_geometry.h"
#include "render/camera.h"
#include "render/shading.h"
#include "scene/scene.h"
#include "schedule/sequence.h"
#include "solve/link_solver.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {

// Frames rendered by other ranks that may wait on rank 0 for the ones before them.
constexpr int kFramesAhead = 8;

// Frames go to the outputs on their own thread while the next frames render. The queue is
// short so that memory stays bounded. After an output failure the thread keeps draining the
// queue (so a push never blocks for ever) and the job stops at its next frame.
class EncoderThread {
public:
    EncoderThread(std::vector<std::unique_ptr<FrameSink>> sinks, std::vector<FrameRecord>* records)
        : m_sinks(std::move(sinks)), m_records(records) {
        m_queue.set_capacity(4);
        m_thread = std::thread([this] { loop(); });
    }
    ~EncoderThread() { stop(); }

    void push(int frame, std::shared_ptr<const Image> image) {
        if (m_failed) std::rethrow_exception(m_error);
        m_queue.push({frame, std::move(image)});
    }
    // Waits for every frame, completes the outputs; rethrows an output failure.
    void finish() {
        stop();
        if (m_failed) std::rethrow_exception(m_error);
        for (auto& s : m_sinks) s->finish();
    }

private:
    using Item = std::pair<int, std::shared_ptr<const Image>>;  // a null image ends the queue

    void stop() {
        if (!m_thread.joinable()) return;
        m_queue.push({-1, nullptr});
        m_thread.join();
    }
    void loop() {
        for (Item item;;) {
            m_queue.pop(item);
            if (!item.second) return;
            if (m_failed) continue;
            try {
                const Stopwatch clock;
                for (auto& s : m_sinks) s->write(item.first, *item.second);
                (*m_records)[item.first].encode_s = clock.seconds();
            } catch (...) {
                m_error = std::current_exception();
                m_failed = true;
            }
        }
    }

    std::vector<std::unique_ptr<FrameSink>> m_sinks;
    std::vector<FrameRecord>* m_records;
    tbb::concurrent_bounded_queue<Item> m_queue;
    std::exception_ptr m_error;
    std::atomic<bool> m_failed = false;
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
        throw Error(path +
                    ": with --palette, write a .gif or numbered indexed PNGs such as out/frames/%04d.png");
    check_sequence_output(path, 2, 2);
}

// Builds both palettes from the whole sequence, reports how close each comes to the
// true-colour frames, and writes the chosen one's frames.
void write_palette_outputs(const SequenceJob& job, const RenderOptions& ro, double fps,
                           const std::vector<std::vector<std::uint8_t>>& frames,
                           const ColourHistogram& histogram, SequenceReport::PaletteResult* result) {
    for (Quantiser q : {Quantiser::MedianCut, Quantiser::Popularity}) {
        PaletteMapper mapper(histogram.palette(job.palette, q));
        PsnrAccumulator psnr;
        std::vector<std::vector<std::uint8_t>> indexed;
        for (const auto& f : frames) {
            indexed.push_back(mapper.map(f));
            psnr.add(f, indexed.back(), mapper.palette());
        }
        (q == Quantiser::MedianCut ? result->psnr_median_cut_db : result->psnr_popularity_db) =
            psnr.psnr_db();
        if (q != job.quantiser) continue;
        result->colours = static_cast<int>(mapper.palette().size());
        for (const auto& o : job.outputs) {
            if (is_gif(o)) {
                write_gif(o, ro.width, ro.height, fps, mapper.palette(), indexed);
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
    out << fmt::format("\r  [{}{}] {}/{} frames  {:.1f} frames/s  ETA {:.0f} s ", std::string(filled, '#'),
                       std::string(width - filled, '.'), done, total, rate, eta)
        << std::flush;
}

// With a palette, frames are kept (8-bit) until every frame has added to the histogram.
struct SequenceKept {
    std::vector<std::vector<std::uint8_t>> frames;
    ColourHistogram histogram;
    void add(std::vector<std::uint8_t> rgb) {
        histogram.add(rgb);
        frames.push_back(std::move(rgb));
    }
};

// Renders (or copies) every frame as planned and hands it to the outputs.
class FrameLoop {
public:
    FrameLoop(const SequenceJob& job, const Prepared& p, const Plan& plan, const Sequence& seq,
              SequenceReport* r)
        : m_job(job),
          m_p(p),
          m_plan(plan),
          m_r(r),
          m_states(p, plan, seq, job.form_factors, job.warn),
          m_solvers(plan.reflectances.size()),
          m_solutions(plan.solutions.size()),
          m_estimates(plan.solutions.size(), Rgb(0.0)),
          m_irradiance(plan.solutions.size()),
          m_last_of_set(plan.reflectances.size(), -1) {}

    // Every factorisation a geometry state needs, before its first frame is written: a system
    // with no steady state is refused with nothing of it on disk (nothing at all without motion).
    void enter_first() { enter(m_r->frames[0]); }

    void run(EncoderThread& encoder, SequenceKept* kept) {
        for (std::size_t f = 0; f < m_r->frames.size(); ++f) {
            FrameRecord& rec = m_r->frames[f];
            enter(rec);
            solve(rec);
            render(rec);
            deliver(f, encoder, kept);
            leave(static_cast<int>(f));
        }
    }
    // The same frames with an MPI job's ranks rendering (src/distribute/frames.h): every state
    // is solved here first, as run() solves it, then the frames to render are shared out and
    // come back in order; copies are made here.
    // Only without motion: the other ranks place the surfaces as the scene file does.
    void run_across(Cluster& cluster, EncoderThread& encoder, SequenceKept* kept) {
        for (FrameRecord& rec : m_r->frames) {
            enter(rec);
            solve(rec);
        }
        FrameOrder order{m_p.scene.file, m_job.threads, m_r->render, {}, {}};
        for (std::size_t s = 0; s < m_solutions.size(); ++s)
            order.states.push_back({m_solutions[s], m_plan.solutions[s].E});
        for (std::size_t f = 0; f < m_r->frames.size(); ++f)
            if (m_r->frames[f].plan.render == RenderAction::Rendered)
                order.frames.push_back(
                    {static_cast<int>(f), m_r->frames[f].plan.camera, m_r->frames[f].plan.solution});
        std::size_t next = 0;  // the next frame to deliver
        auto copies_until = [&](std::size_t end) {
            for (; next < end; ++next) {
                ++m_r->copies;
                deliver(next, encoder, kept);
            }
        };
        render_frames_across(
            cluster, m_p.scene, m_p.geometry, order,
            [&](int k, RenderedFrame frame) {
                const auto f = static_cast<std::size_t>(order.frames[static_cast<std::size_t>(k)].frame);
                copies_until(f);
                FrameRecord& rec = m_r->frames[f];
                rec.render_s = frame.render_s;
                rec.rank = frame.rank;
                m_image = std::move(frame.image);
                ++m_r->renders;
                deliver(f, encoder, kept);
                next = f + 1;
            },
            kFramesAhead);
        copies_until(m_r->frames.size());
    }

private:
    const GeometryState& state() const { return m_states.state(m_current); }

    // The frame's geometry state: its form factors (recorded on the frame that obtained them)
    // and the factorisations of its reflectance sets.
    void enter(FrameRecord& rec) {
        const int g = rec.plan.geometry;
        if (g == m_current) return;
        bool obtained = false;
        const GeometryState& st = m_states.enter(g, &obtained);
        m_current = g;
        m_nodes.reset();
        m_nodes_solution = -1;
        if (!obtained) return;
        if (st.update) {
            rec.form_factors = "updated";
            rec.update = st.update;
            rec.entries_recomputed = st.update->entries_recomputed;
        } else if (st.cached) {
            rec.form_factors = "cached";
        }
        rec.form_factors_s += st.seconds;
        if (m_p.scene.closed)
            m_r->closure_max_error_over_states =
                std::max(m_r->closure_max_error_over_states, st.checks.closure_max_error);
        build_solvers(g);
    }
    void build_solvers(int g) {
        if (m_p.hierarchy) {
            // Over links nothing is factorised; a system with no steady state is refused up front.
            for (const auto& fp : m_plan.frames)
                if (fp.solve != SolveAction::Reused)
                    refuse_lossless(m_plan.reflectances[static_cast<std::size_t>(fp.reflectance_set)],
                                    m_plan.solutions[static_cast<std::size_t>(fp.solution)].E,
                                    m_p.scene.closed, m_job.sequence_path);
            return;
        }
        for (std::size_t rs = 0; rs < m_plan.reflectances.size(); ++rs) {
            if (m_plan.reflectance_geometry[rs] != g || m_solvers[rs]) continue;
            m_solvers[rs] =
                std::make_unique<RadiositySolver>(state().ff->F, m_plan.reflectances[rs], m_r->solver);
            m_r->factorisations += m_solvers[rs]->factorisations();
            m_r->stability.add(*m_solvers[rs]);
        }
        for (const auto& fp : m_plan.frames) {
            if (fp.solve == SolveAction::Reused || fp.geometry != g) continue;
            const auto rs = static_cast<std::size_t>(fp.reflectance_set);
            const std::string w =
                check_steady_state(*m_solvers[rs], m_plan.reflectances[rs], m_plan.solutions[fp.solution].E,
                                   m_p.scene.closed, m_job.sequence_path);
            if (!w.empty() && w != m_last_warning) m_job.warn(m_last_warning = w);
        }
    }
    // After frame f: a geometry state whose last frame it was is let go, with its solvers.
    void leave(int f) {
        const int g = m_r->frames[static_cast<std::size_t>(f)].plan.geometry;
        if (m_plan.last_frame_of_geometry[static_cast<std::size_t>(g)] != f) return;
        for (std::size_t rs = 0; rs < m_solvers.size(); ++rs)
            if (m_plan.reflectance_geometry[rs] == g) m_solvers[rs].reset();
        m_nodes.reset();
        m_nodes_solution = -1;
        m_states.release(g);
        m_current = -1;
    }

    // The solution it starts from: the last answer for the same reflectance (nearby lights,
    // nearby radiosities), or else the last answer of all (the previous frame's, before a
    // surface moved); none for a direct solve.
    const std::vector<Rgb>* warm_start(const FramePlan& fp) const {
        const int warm =
            m_last_of_set[fp.reflectance_set] >= 0 ? m_last_of_set[fp.reflectance_set] : m_last_solved;
        return fp.solve == SolveAction::Iterated && warm >= 0 ? &m_solutions[warm] : nullptr;
    }
    void solve(FrameRecord& rec) {
        const FramePlan& fp = rec.plan;
        if (fp.solve == SolveAction::Reused) return;
        if (m_p.hierarchy) return solve_links_frame(rec);
        const RadiositySolver& solver = *m_solvers[static_cast<std::size_t>(fp.reflectance_set)];
        const Stopwatch clock;
        // The factorisation ran in build_solvers; it is charged to the frame that first uses it.
        if (fp.solve == SolveAction::Factorised) rec.solve_s += solver.factorise_seconds();
        m_solutions[fp.solution] = solver.solve(m_plan.solutions[fp.solution].E, warm_start(fp));
        m_last_of_set[fp.reflectance_set] = fp.solution;
        m_last_solved = fp.solution;
        rec.sweeps = solver.last_iterations();
        m_r->channel_solves += solver.last_channel_solves();
        rec.solve_s += clock.seconds();
        read_sensors(fp);
        // Diagnostics, not timed as solving.
        const FormFactors& ff = *state().ff;
        const SolveDiagnostics d = diagnose_solution(
            ff.F, ff.area, {m_plan.reflectances[fp.reflectance_set], m_plan.solutions[fp.solution].E},
            m_solutions[fp.solution]);
        m_r->residual = std::max(m_r->residual, d.residual);
        if (!ff.error.empty()) {
            const Rgb b = radiosity_error_bound(
                solver, ff.F, ff.error,
                {m_plan.reflectances[fp.reflectance_set], m_plan.solutions[fp.solution].E},
                m_solutions[fp.solution]);
            if (!m_r->radiosity_error_bound) m_r->radiosity_error_bound = Rgb(0.0);
            for (int c = 0; c < 3; ++c)
                (*m_r->radiosity_error_bound)[c] = std::max((*m_r->radiosity_error_bound)[c], b[c]);
        }
        if (m_p.scene.closed)
            m_r->energy_balance_error = std::max(m_r->energy_balance_error, d.energy_balance_error);
    }
    // Whether a later Combined solution takes solution k as a term.
    bool is_term(int k) const {
        for (const auto& terms : m_plan.combinations)
            for (const Combination& t : terms)
                if (t.solution == k) return true;
        return false;
    }
    // A Combined solution's terms applied to per-solution vectors (radiosities or irradiances),
    // weighted per channel: both are linear in emission.
    std::vector<Rgb> weighted(const FramePlan& fp, const std::vector<std::vector<Rgb>>& of) const {
        std::vector<Rgb> out(m_plan.solutions[fp.solution].E.size(), Rgb(0.0));
        for (const Combination& t : m_plan.combinations[fp.solution]) {
            const std::vector<Rgb>& v = of[static_cast<std::size_t>(t.solution)];
            for (std::size_t i = 0; i < out.size(); ++i) out[i] += t.weight * v[i];
        }
        return out;
    }
    void read_sensors(const FramePlan& fp) {
        m_r->sensor_irradiance.resize(m_plan.solutions.size());
        std::vector<Rgb>& readings = m_r->sensor_irradiance[fp.solution];
        const std::vector<SensorFactors>& sensors = *state().sensors;
        readings.assign(sensors.size(), Rgb(0.0));
        for (std::size_t k = 0; k < sensors.size(); ++k)
            readings[k] = sensor_irradiance(sensors[k], m_solutions[fp.solution]);
    }
    // Over the hierarchy's links: sweeps of gather, push and pull, warm-started from the last
    // answer, carrying along the emissions solved ahead with this one (Plan::solved_together),
    // then the diagnostics and the error estimate.
    void solve_links_frame(FrameRecord& rec) {
        const FramePlan& fp = rec.plan;
        const Stopwatch clock;
        const Materials mat{m_plan.reflectances[fp.reflectance_set], m_plan.solutions[fp.solution].E};
        if (fp.solve == SolveAction::Combined)
            m_solutions[fp.solution] = weighted(fp, m_solutions);
        else if (fp.solve == SolveAction::Iterated)
            rec.sweeps = sweep_together(fp, mat.rho);
        m_last_of_set[fp.reflectance_set] = fp.solution;
        m_last_solved = fp.solution;
        rec.solve_s += clock.seconds();
        read_sensors(fp);
        // Diagnostics, not timed as solving.
        if (fp.solve == SolveAction::Iterated) check_together(fp, mat.rho);
        // Irradiance is linear in radiosity too: a combination's is its terms', combined (kept
        // for the iterated solutions), so its diagnostics need no gather over the links.
        std::vector<Rgb> H = fp.solve == SolveAction::Combined ? weighted(fp, m_irradiance)
                             : is_term(fp.solution)            ? m_irradiance[fp.solution]
                                                               : std::move(m_irradiance[fp.solution]);
        const SolveDiagnostics d = diagnose_links(*m_p.hierarchy, mat, m_solutions[fp.solution], H);
        m_r->residual = std::max(m_r->residual, d.residual);
        if (m_p.scene.closed)
            m_r->energy_balance_error = std::max(m_r->energy_balance_error, d.energy_balance_error);
        // A combination's error is at most its terms' errors times their weights: no extra solve.
        // An iterated or ahead solution's estimate came from check_together.
        if (fp.solve == SolveAction::Combined)
            for (const Combination& t : m_plan.combinations[fp.solution])
                m_estimates[fp.solution] +=
                    glm::abs(t.weight) * m_estimates[static_cast<std::size_t>(t.solution)];
        const Rgb e = m_estimates[fp.solution];
        if (!m_r->radiosity_error_estimate) m_r->radiosity_error_estimate = Rgb(0.0);
        for (int c = 0; c < 3; ++c)
            (*m_r->radiosity_error_estimate)[c] = std::max((*m_r->radiosity_error_estimate)[c], e[c]);
    }
    // The sweeps of an Iterated frame: its own emission (warm-started) and those solved ahead with
    // it (from their emissions), all in one run; their sweep count.
    int sweep_together(const FramePlan& fp, const std::vector<Rgb>& rho) {
        static_assert(kMaxSolvedAhead <= static_cast<int>(kMaxSolvedTogether), "a plan's group fits one run");
        const std::vector<int>& together = m_plan.solved_together[static_cast<std::size_t>(fp.solution)];
        std::vector<std::vector<Rgb>> E;
        for (const int k : together) E.push_back(m_plan.solutions[static_cast<std::size_t>(k)].E);
        std::vector<LinkSolution> s = solve_links_together(*m_p.hierarchy, rho, E, {}, {warm_start(fp)});
        for (std::size_t j = 0; j < together.size(); ++j)
            m_solutions[static_cast<std::size_t>(together[j])] = std::move(s[j].B);
        m_r->channel_solves += 3 * static_cast<int>(together.size());
        return s.front().sweeps;
    }
    // Each solution of that run's irradiance (for its residual) and radiosity error estimate,
    // gathered and solved together too; read at each one's frame.
    void check_together(const FramePlan& fp, const std::vector<Rgb>& rho) {
        const std::vector<int>& together = m_plan.solved_together[static_cast<std::size_t>(fp.solution)];
        std::vector<const std::vector<Rgb>*> B;
        for (const int k : together) B.push_back(&m_solutions[static_cast<std::size_t>(k)]);
        std::vector<std::vector<Rgb>> H = irradiance_together(*m_p.hierarchy, B);
        const std::vector<Rgb> e = link_error_estimates(*m_p.hierarchy, rho, B);
        for (std::size_t j = 0; j < together.size(); ++j) {
            m_irradiance[static_cast<std::size_t>(together[j])] = std::move(H[j]);
            m_estimates[static_cast<std::size_t>(together[j])] = e[j];
        }
    }
    // Frame f (m_image) to the test hook, the outputs and the progress bar.
    void deliver(std::size_t f, EncoderThread& encoder, SequenceKept* kept) {
        if (m_job.on_frame) m_job.on_frame(static_cast<int>(f), *m_image);
        if (m_job.palette > 0)
            kept->add(to_srgb8(*m_image, m_job.exposure));
        else
            encoder.push(static_cast<int>(f), m_image);
        if (m_job.progress)
            print_progress(*m_job.progress, static_cast<int>(f + 1), static_cast<int>(m_r->frames.size()),
                           m_clock.seconds());
    }
    void render(FrameRecord& rec) {
        const FramePlan& fp = rec.plan;
        const Stopwatch clock;
        if (fp.render == RenderAction::Rendered) {
            if (m_nodes_solution != fp.solution) {
                m_nodes = std::make_unique<NodeRadiosity>(*state().geometry, m_solutions[fp.solution],
                                                          m_plan.solutions[fp.solution].E);
                m_nodes_solution = fp.solution;
            }
            const PinholeCamera cam(fp.camera, m_r->render.width, m_r->render.height);
            m_image =
                std::make_shared<const Image>(render_image(*state().geometry, *m_nodes, cam, m_r->render));
            ++m_r->renders;
        } else {
            ++m_r->copies;
        }
        rec.render_s = clock.seconds();
    }

    const SequenceJob& m_job;
    const Prepared& m_p;
    const Plan& m_plan;
    SequenceReport* m_r;
    GeometryStates m_states;
    int m_current = -1;  // the geometry state entered last (-1: none held)
    std::vector<std::unique_ptr<RadiositySolver>> m_solvers;  // per reflectance set, while its state is held
    std::string m_last_warning;
    std::vector<std::vector<Rgb>> m_solutions;
    std::vector<Rgb> m_estimates;                // over links: each solution's radiosity error estimate
    std::vector<std::vector<Rgb>> m_irradiance;  // over links: of each term of a combination, and of each
                                                 // solution solved ahead until its frame
    int m_last_solved = -1;
    std::vector<int> m_last_of_set;  // per reflectance set, the solution solved for it last (-1: none)
    std::unique_ptr<NodeRadiosity> m_nodes;
    int m_nodes_solution = -1;
    std::shared_ptr<const Image> m_image;
    Stopwatch m_clock;
};

// Reads the sequence and resolves the image size, then checks every output: all before any
// form factor is computed.
Sequence read_sequence(const SequenceJob& job, const Scene& scene, RenderOptions* ro) {
    Sequence seq = load_sequence(job.sequence_path, &scene);
    ro->width = job.width.value_or(seq.width.value_or(ro->width));
    ro->height = job.height.value_or(seq.height.value_or(ro->height));
    ro->samples = job.samples.value_or(seq.samples.value_or(ro->samples));
    for (const auto& o : job.outputs) {
        if (job.palette > 0)
            check_palette_output(o);
        else
            check_sequence_output(o, ro->width, ro->height);
    }
    return seq;
}

void add_totals(SequenceReport* r) {
    for (const auto& rec : r->frames) {
        r->form_factors_s += rec.form_factors_s;
        r->solve_s += rec.solve_s;
        r->render_s += rec.render_s;
        r->encode_s += rec.encode_s;
    }
}

}  // namespace

SequenceReport run_sequence_job(const SequenceJob& job) {
    const Stopwatch total;
    SequenceReport r;
    if (job.report_path) check_output_path(*job.report_path);
    const ThreadLimit limit(job.threads);
    r.threads = limit.threads();
    r.scene_path = job.scene_path.empty() ? sequence_scene_path(job.sequence_path) : job.scene_path;
    if (r.scene_path.empty())
        throw Error(job.sequence_path +
                    ": the sequence names no scene; add 'scene: path' to it or give SCENE.yaml");
    std::optional<Sequence> seq;
    r.prep =
        std::make_unique<Prepared>(prepare(r.scene_path, job.form_factors, job.warn, [&](const Prepared& p) {
            seq = read_sequence(job, p.scene, &r.render);
            if (seq->has_motion() &&
                job.form_factors.options_for(p.scene).method == FormFactorMethod::Hierarchical)
                throw Error(FileLoc{job.sequence_path, 0, 0},
                            "the sequence moves surfaces, and hierarchical links are not updated for motion "
                            "in this version; run it with --ff-method adaptive");
        }));
    const Prepared& p = *r.prep;
    r.solver = job.solver;
    if (!job.solver_given && seq->has_motion() && p.geometry.patch_count() > kMovingIterativeFromPatches)
        r.solver = SolverMethod::GaussSeidel;
    // Over links every solve is an iteration, warm-started from the last.
    const Plan plan = plan_sequence(*seq, patch_materials(p.scene), p.geometry,
                                    is_iterative(r.solver) || p.hierarchy, p.hierarchy.has_value());
    r.fps = seq->fps;
    r.frames.resize(plan.frames.size());
    for (std::size_t f = 0; f < r.frames.size(); ++f) r.frames[f].plan = plan.frames[f];
    // Form factors: once for the whole sequence, charged to frame 0.
    r.frames[0].form_factors_s = p.form_factors_s;
    r.frames[0].form_factors = p.cache.status == CacheStatus::Hit ? "cached" : "computed";
    if (p.cache.status != CacheStatus::Hit)
        r.frames[0].entries_recomputed =
            p.hierarchy ? p.hierarchy->stats.links
                        : static_cast<long long>(p.geometry.patch_count()) * p.geometry.patch_count();
    r.geometry_states = static_cast<int>(plan.geometries.size());
    r.moves = plan.moves();

    std::vector<std::unique_ptr<FrameSink>> sinks;
    if (job.palette == 0)
        for (const auto& o : job.outputs)
            sinks.push_back(
                make_frame_sink(o, r.render.width, r.render.height, {seq->fps, job.exposure, job.crf}));
    FrameLoop loop(job, p, plan, *seq, &r);
    loop.enter_first();
    EncoderThread encoder(std::move(sinks), &r.frames);
    SequenceKept kept;  // with a palette: every frame, 8-bit, until all have added to the histogram
    Cluster& cluster = Cluster::current();
    r.ranks = cluster.size();
    if (cluster.distributed() && plan.moves())
        job.warn(
            "the sequence moves surfaces: rank 0 renders every frame (the other ranks would place "
            "the surfaces as the scene file does)");
    if (cluster.distributed() && !plan.moves())
        loop.run_across(cluster, encoder, &kept);
    else
        loop.run(encoder, &kept);
    encoder.finish();
    if (job.progress) *job.progress << "\n";
    if (job.palette > 0) {
        const Stopwatch clock;
        write_palette_outputs(job, r.render, seq->fps, kept.frames, kept.histogram, &r.palette);
        r.palette.seconds = clock.seconds();
    }
    r.substitutions = plan.substitutions();
    r.reflectance_sets = plan.factorisations();
    add_totals(&r);
    r.load_s = p.load_s;
    r.total_s = total.seconds();
    if (job.report_path) write_text_file(*job.report_path, sequence_report_json(job, r) + "\n");
    return r;
}

}  // namespace radiosa
