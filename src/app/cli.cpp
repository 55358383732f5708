#include "app/cli.h"

#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <new>

#include "app/accuracy_cmd.h"
#include "app/cache_cmd.h"
#include "app/formfactors_cmd.h"
#include "app/radiosity_study.h"
#include "app/sequence_job.h"
#include "app/still.h"
#include "app/validation_study.h"
#include "distribute/cluster.h"
#include "distribute/form_factors.h"
#include "encode/features.h"
#include "geometry/scene_geometry.h"
#include "surfaces/registry.h"
#include "util/error.h"
#include "util/progress.h"

namespace radiosa {

namespace {

// The built-in demo: an orbit of the paper's scene with a relighting sweep and a colour change.
constexpr const char* kDemoScene = "scenes/baranoski1991.yaml";
constexpr const char* kDemoSequence = "cameras/demo.yaml";
constexpr const char* kDemoReport = "out/demo.json";

void add_cache_dir_option(CLI::App* cmd, CacheSettings* cache) {
    cmd->add_option("--cache-dir", cache->dir,
                    "Form-factor cache directory (default: $RADIOSA_CACHE_DIR, else out/cache)");
}

void add_form_factor_options(CLI::App* cmd, FormFactorRequest* req) {
    CacheSettings* cache = &req->cache;
    std::optional<bool>* visibility = &req->visibility;
    auto* p =
        cmd->add_option("--gauss-points,-p", req->gauss_points,
                        "The paper's fixed Gauss-Legendre rule, P points per parameter (no error control)")
            ->check(CLI::Range(1, 64));
    cmd->add_option("--ff-tolerance", req->tolerance,
                    "Error-controlled form factors: absolute tolerance on each F_ij (default 1e-6); "
                    "hierarchical: on each link (default 2e-5)")
        ->check(CLI::Range(1e-12, 0.1))
        ->excludes(p);
    cmd->add_option("--ff-receiver-tolerance", req->receiver_tolerance,
                    "Hierarchical: also hold each link's misfit over its receiver to this (slower; rows "
                    "closer to 1: docs/scale.md), 0 = off; overrides the scene's "
                    "form_factors.receiver_tolerance (default: link tolerance / 8 up to 10,000 patches, "
                    "off above)")
        ->check(CLI::Validator(
            [](std::string& v) {
                char* end = nullptr;
                const double x = std::strtod(v.c_str(), &end);
                if (end == v.c_str() || *end) return std::string();  // not a number: the conversion says so
                return valid_receiver_tolerance(x) ? std::string()
                                                   : "must be 0 (off) or in [1e-12, 0.1], got " + v;
            },
            "0 or [1e-12 - 0.1]"))
        ->excludes(p);
    cmd->add_option("--ff-numeric-inner", req->numeric_inner,
                    "Adaptive: the inner integral of pairs without a closed form (curved receivers, "
                    "general occluders): rules (two fixed Gauss rules, the default) or lines (follows "
                    "shadow edges by bisection: estimates that hold, at several times the cost; "
                    "docs/accuracy.md); overrides the scene's form_factors.numeric_inner")
        ->check(CLI::IsMember({"rules", "lines"}))
        ->excludes(p);
    cmd->add_option("--ff-method", req->method,
                    "Form-factor method: adaptive (the default), gauss (the paper's rule, -p points) or "
                    "hierarchical (links between groups of patches, no N x N matrix; docs/scale.md)")
        ->check(CLI::IsMember({"adaptive", "gauss", "hierarchical"}))
        ->excludes(p);
    cmd->add_flag_callback(
        "--no-visibility", [visibility] { *visibility = false; },
        "Ignore occlusion in form factors (for comparison)");
    bool* culling = &req->culling;
    cmd->add_flag_callback(
        "--no-culling", [culling] { *culling = false; },
        "Integrate every pair and test every surface as an occluder, without the cache: "
        "measures what culling saves");
    cmd->add_option("--solve-tolerance", req->solve_tolerance,
                    "Target on the radiosity: max |B - B*| / max B per channel; the form-factor tolerance is "
                    "tightened until the bound meets it (overrides the scene's solve: tolerance)")
        ->check(CLI::Range(1e-12, 0.1))
        ->excludes(p);
    cmd->add_flag("--strict", req->strict,
                  "Refuse (exit 1, no output) a scene whose surfaces intersect or a matrix with any entry "
                  "whose error estimate misses its tolerance, instead of warning");
    add_cache_dir_option(cmd, cache);
    cmd->add_flag_callback(
        "--no-cache", [cache] { cache->enabled = false; }, "Neither read nor write the form-factor cache");
}

struct SequenceOptions {
    std::string sequence;
    int crf = 18;
    int palette = 0;
    Quantiser quantiser = Quantiser::MedianCut;
};

void add_render_options(CLI::App* cmd, StillJob* job, SequenceOptions* so, bool* quiet) {
    std::string* sequence = &so->sequence;
    int* crf = &so->crf;
    cmd->add_option("scene", job->scene_path,
                    "Scene file (YAML); optional with a sequence that names its scene");
    auto* camera =
        cmd->add_option("--camera,-c", job->camera_path, "Camera file (YAML): render one still image");
    cmd->add_option("--sequence,-s", *sequence, "Sequence file (YAML): render an animation")
        ->excludes(camera);
    cmd->add_option("-o,--output", job->outputs,
                    "Output. Still: .png (8-bit sRGB) or .exr (linear float). Sequence: .mp4 (H.264) or "
                    "numbered images such as out/frames/%04d.png. Repeatable");
    cmd->add_option("--crf", *crf, "Video quality, x264 constant rate factor (0 lossless .. 51; default 18)")
        ->check(CLI::Range(0, 51));
    cmd->add_option(
           "--palette", so->palette,
           "Sequence: one palette of N colours (2..256) for all frames, as the 1991 paper's display; "
           "outputs .gif or numbered indexed .png")
        ->check(CLI::Range(2, 256));
    cmd->add_option_function<std::string>(
           "--quantiser", [so](const std::string& s) { so->quantiser = parse_quantiser(s); },
           "Palette quantiser: median-cut (default) or popularity (the paper's)")
        ->check(CLI::IsMember({"median-cut", "popularity"}));
    cmd->add_option("--report", job->report_path, "Write the JSON run report here");
    cmd->add_option("--radiosities", job->radiosities_path,
                    "Still: write every patch's radiosity here (.csv: patch, area, B_r, B_g, B_b)");
    cmd->add_option("--width", job->render.width, "Image width in pixels")->check(CLI::Range(1, 16384));
    cmd->add_option("--height", job->render.height, "Image height in pixels")->check(CLI::Range(1, 16384));
    cmd->add_option("--samples", job->render.samples, "Sub-pixel rays per axis (S x S per pixel)")
        ->check(CLI::Range(1, 16));
    cmd->add_option("--threads", job->threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024));
    add_form_factor_options(cmd, &job->form_factors);
    cmd->add_option_function<std::string>(
           "--solver", [job](const std::string& s) { job->solver = parse_solver_method(s); },
           "lu (default), gauss-jordan (the 1991 paper's method), or iterative: jacobi, gauss-seidel, "
           "southwell")
        ->check(CLI::IsMember({"lu", "gauss-jordan", "jacobi", "gauss-seidel", "southwell"}));
    cmd->add_option("--exposure", job->exposure, "Exposure in stops for 8-bit outputs (default 0)")
        ->check(CLI::Range(-200.0, 200.0));
    cmd->add_flag("--quiet,-q", *quiet, "Print nothing on success");
}

void add_formfactors_options(CLI::App* cmd, FormFactorsJob* job, bool* quiet) {
    cmd->add_option("scene", job->scene_path, "Scene file (YAML)")->required();
    cmd->add_option(
        "--sensors", job->sensors_path,
        "Write the scene's sensors' form factors: .csv, a row per sensor, F(dA -> patch) per column");
    cmd->add_option("--matrix,-m", job->matrix_path,
                    "Export the matrix: .csv (with header and patch table) or .npy (numpy.load; "
                    "patch table beside it as <stem>.patches.csv)");
    cmd->add_option("--report", job->report_path, "Write the JSON run report here");
    cmd->add_option("--threads", job->threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024));
    add_form_factor_options(cmd, &job->form_factors);
    cmd->add_flag("--quiet,-q", *quiet, "Print nothing on success");
}

// out/STEM.mp4; in a build without video, numbered PNGs in out/STEM/ (created).
std::string default_sequence_output(const std::string& sequence) {
    namespace fs = std::filesystem;
    const std::string stem = fs::path(sequence).stem().string();
    if (kHasVideo) return (fs::path("out") / (stem + ".mp4")).string();
    std::error_code ec;
    fs::create_directories(fs::path("out") / stem, ec);
    return (fs::path("out") / stem / "%04d.png").string();
}

std::string default_output(const StillJob& job) {
    namespace fs = std::filesystem;
    return (fs::path("out") / (fs::path(job.scene_path).stem().string() + "-" +
                               fs::path(job.camera_path).stem().string() + ".png"))
        .string();
}

// The versions every document refers to, from the one place each is defined.
std::string version_text() {
    return fmt::format(
        "radiosa {}; form-factor algorithm version {}, cache file format {}; surface types: {}; video and "
        "palette outputs (libav): {}; MPI: {}",
        RADIOSA_VERSION, kFormFactorAlgorithmVersion, kCacheFormatVersion, surface_type_names(),
        kHasVideo ? "yes" : "no, built with -DRADIOSA_VIDEO=OFF", mpi_build_description());
}

// Every subcommand with the job its options fill.
struct Commands {
    bool quiet = false;
    StillJob still;
    SequenceOptions sequence;
    FormFactorsJob formfactors_job;
    AccuracyJob accuracy_job;
    CacheSettings cache_dir;
    CLI::App *render = nullptr, *formfactors = nullptr, *accuracy = nullptr, *cache = nullptr;
    CLI::App *cache_list = nullptr, *cache_verify = nullptr, *cache_clear = nullptr;
};

void add_accuracy_command(CLI::App& app, Commands* c) {
    AccuracyJob& job = c->accuracy_job;
    c->accuracy = app.add_subcommand(
        "accuracy",
        "Form-factor error against run time on configurations with known answers (CSV, Markdown)");
    c->accuracy->add_option("--out", job.out_dir, "Output directory (default out/accuracy)");
    c->accuracy->add_flag("--quick", job.quick, "A few methods only (a smoke test)");
    c->accuracy
        ->add_option(
            "--budget", job.budget_s,
            "Stop refining a method on a configuration once one run takes longer (seconds, default 30)")
        ->check(CLI::Range(0.01, 3600.0));
    c->accuracy->add_flag("--validation", job.validation,
                          "Instead: do the error estimates cover the true errors? Random configurations with "
                          "closed forms, a fitting and a checking half (validation.md, validation.csv)");
    c->accuracy->add_flag(
        "--radiosity", job.radiosity,
        "Instead: the error of the radiosity B against run time (form factors + solve) for the "
        "seed scene and its stiff variant, both methods (radiosity.md, radiosity.csv)");
    c->accuracy
        ->add_option("--per-family", job.per_family, "--validation: configurations per family (default 50)")
        ->check(CLI::Range(2, 10000));
    c->accuracy->add_option("--threads", job.threads, "Worker threads (0 = all cores)")
        ->check(CLI::Range(0, 1024));
}

void add_cache_command(CLI::App& app, Commands* c) {
    c->cache = app.add_subcommand("cache", "Inspect or empty the form-factor cache");
    c->cache->require_subcommand(1, 1);
    c->cache_list = c->cache->add_subcommand("list", "List cached matrices: key, scene, patches, size, age");
    c->cache_verify =
        c->cache->add_subcommand("verify", "Check every cached matrix completely; exit 1 if any is bad");
    c->cache_clear = c->cache->add_subcommand("clear", "Remove cached matrices, stale temporaries and locks");
    for (CLI::App* sub : {c->cache_list, c->cache_verify, c->cache_clear})
        add_cache_dir_option(sub, &c->cache_dir);
}

// --help (also on a subcommand) and --version exit 0; anything else is a usage error, exit 1.
int parse_error(const CLI::App& app, const Commands& c, const CLI::ParseError& e, std::ostream& out,
                std::ostream& err) {
    if (e.get_exit_code() != 0) {
        err << "error: " << e.what() << " (see 'radiosa --help')\n";
        return 1;
    }
    for (const CLI::App* sub :
         {c.render, c.formfactors, c.accuracy, c.cache_list, c.cache_verify, c.cache_clear, c.cache})
        if (sub->parsed()) {
            out << sub->help();
            return 0;
        }
    out << app.help();
    return 0;
}

SequenceJob sequence_job(const Commands& c, const WarningSink& warn, std::ostream& err) {
    const StillJob& job = c.still;
    SequenceJob sj;
    sj.scene_path = job.scene_path;
    sj.sequence_path = c.sequence.sequence;
    sj.outputs = job.outputs.empty() ? std::vector<std::string>{default_sequence_output(sj.sequence_path)}
                                     : job.outputs;
    sj.report_path = job.report_path;
    if (c.render->count("--width")) sj.width = job.render.width;
    if (c.render->count("--height")) sj.height = job.render.height;
    if (c.render->count("--samples")) sj.samples = job.render.samples;
    sj.form_factors = job.form_factors;
    sj.solver = job.solver;
    sj.solver_given = c.render->count("--solver") > 0;
    sj.exposure = job.exposure;
    sj.crf = c.sequence.crf;
    sj.palette = c.sequence.palette;
    sj.quantiser = c.sequence.quantiser;
    sj.threads = job.threads;
    sj.warn = warn;
    if (!c.quiet && &err == &std::cerr && ::isatty(2)) sj.progress = &err;
    return sj;
}

// render: the demo (no arguments), a sequence, or a still.
int run_render(bool no_subcommand, Commands& c, const WarningSink& warn, std::ostream& out,
               std::ostream& err) {
    StillJob& job = c.still;
    std::string& sequence = c.sequence.sequence;
    if (no_subcommand || (job.scene_path.empty() && job.camera_path.empty() && sequence.empty())) {
        sequence = kDemoSequence;
        job.scene_path = kDemoScene;
        if (job.outputs.empty()) job.outputs = {default_sequence_output(kDemoSequence)};
        if (!job.report_path) job.report_path = kDemoReport;
    }
    if (!sequence.empty()) {
        if (job.radiosities_path) throw Error("render: --radiosities applies to stills (--camera)");
        const SequenceJob sj = sequence_job(c, warn, err);
        const SequenceReport report = run_sequence_job(sj);
        if (!c.quiet) out << sequence_summary(sj, report);
        return 0;
    }
    if (c.sequence.palette > 0) throw Error("render: --palette applies to sequences (--sequence)");
    if (job.camera_path.empty())
        throw Error(
            "render: give --camera CAMERA.yaml for a still or --sequence SEQUENCE.yaml for an animation");
    if (job.scene_path.empty())
        throw Error("render: a still needs the scene file (radiosa render SCENE.yaml --camera ...)");
    if (job.outputs.empty()) job.outputs.push_back(default_output(job));
    const StillReport report = run_still(job);
    if (!c.quiet) out << still_summary(job, report);
    return 0;
}

// compute_form_factors with a progress bar on `out` (by pairs: rows are uneven).
ComputeFormFactors computing_with_progress(std::ostream& out) {
    return [&out](const Scene&, const SceneGeometry& geometry, const FormFactorOptions& options) {
        const long long n = geometry.patch_count();
        ProgressBar bar(&out, "form factors", n * (n + 1) / 2);
        return compute_form_factors(geometry, options, [&bar](long long pairs) { bar.add(pairs); });
    };
}

int run_command(const CLI::App& app, Commands& c, const WarningSink& warn, std::ostream& out,
                std::ostream& err) {
    // In an MPI job, matrices this run computes are shared out among the ranks.
    Cluster& cluster = Cluster::current();
    c.still.form_factors.cache.compute = form_factors_across(cluster, c.still.threads);
    c.formfactors_job.form_factors.cache.compute = form_factors_across(cluster, c.formfactors_job.threads);
    // In one process on a terminal, a matrix being computed shows its progress.
    if (!cluster.distributed() && !c.quiet && &err == &std::cerr && ::isatty(2)) {
        c.still.form_factors.cache.compute = c.formfactors_job.form_factors.cache.compute =
            computing_with_progress(err);
        c.still.form_factors.cache.progress = c.formfactors_job.form_factors.cache.progress = &err;
    }
    const std::filesystem::path dir = c.cache_dir.dir.empty() ? default_cache_dir() : c.cache_dir.dir;
    if (c.cache_list->parsed()) {
        cache_list(dir, out);
        return 0;
    }
    if (c.cache_verify->parsed()) return cache_verify(dir, out) ? 0 : 1;
    if (c.cache_clear->parsed()) {
        cache_clear(dir, out);
        return 0;
    }
    if (c.accuracy->parsed()) {
        if (c.accuracy_job.radiosity)
            run_radiosity_study({c.accuracy_job.out_dir, c.accuracy_job.quick}, out);
        else if (c.accuracy_job.validation)
            run_validation({c.accuracy_job.out_dir, c.accuracy_job.per_family, 1991}, out);
        else
            run_accuracy(c.accuracy_job, out);
        return 0;
    }
    if (c.formfactors->parsed()) {
        const std::string summary = run_formfactors(c.formfactors_job);
        if (!c.quiet) out << summary;
        return 0;
    }
    return run_render(app.get_subcommands().empty(), c, warn, out, err);
}

}  // namespace

int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app{"radiosa: radiosity for curved parametric surfaces (parametric differential method)",
                 "radiosa"};
    app.require_subcommand(0, 1);
    app.set_version_flag("--version", version_text());
    const WarningSink warn = [&err](const std::string& w) { err << "warning: " << w << "\n"; };
    Commands c;
    c.still.warn = c.formfactors_job.warn = warn;
    c.render = app.add_subcommand(
        "render", "Render a still (--camera) or an animation (--sequence); with no arguments, the demo");
    add_render_options(c.render, &c.still, &c.sequence, &c.quiet);
    c.formfactors =
        app.add_subcommand("formfactors", "Compute or load a scene's form factors, check and export them");
    add_formfactors_options(c.formfactors, &c.formfactors_job, &c.quiet);
    add_accuracy_command(app, &c);
    add_cache_command(app, &c);
    try {
        try {
            app.parse(argc, argv);
        } catch (const CLI::CallForHelp&) {
            out << app.help();
            return 0;
        } catch (const CLI::CallForVersion& v) {
            out << v.what() << "\n";
            return 0;
        } catch (const CLI::ParseError& e) {
            return parse_error(app, c, e, out, err);
        }
        return run_command(app, c, warn, out, err);
    } catch (const Error& e) {
        err << "error: " << e.what() << "\n";
        return 1;
    } catch (const std::bad_alloc&) {
        err << "error: out of memory (the scene needs more than this machine or its limits allow; use fewer "
               "patches)\n";
        return 2;
    } catch (const std::exception& e) {
        err << "error: internal failure: " << e.what() << "\n";
        return 2;
    } catch (...) {
        err << "error: internal failure: an unknown exception\n";
        return 2;
    }
}

}  // namespace radiosa
