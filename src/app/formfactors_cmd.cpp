#include "app/formfactors_cmd.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "app/pipeline.h"
#include "formfactor/matrix_export.h"
#include "util/atomic_file.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {
// --matrix with hierarchical links: the dense matrix they stand for, up to 8 x 8,192^2 bytes
// (512 MB, with as much again for the estimates).
constexpr int kMaxExpandedPatches = 8192;
}  // namespace

std::string run_formfactors(const FormFactorsJob& job) {
    const Stopwatch total;
    if (job.matrix_path) check_matrix_output(*job.matrix_path);
    if (job.report_path) check_output_path(*job.report_path);
    if (job.sensors_path) {
        if (!job.sensors_path->ends_with(".csv"))
            throw Error("--sensors " + *job.sensors_path + ": write a .csv file");
        check_output_path(*job.sensors_path);
    }
    const ThreadLimit limit(job.threads);
    const Prepared p = prepare(job.scene_path, job.form_factors, job.warn, [&](const Prepared& q) {
        if (job.matrix_path &&
            job.form_factors.options_for(q.scene).method == FormFactorMethod::Hierarchical &&
            q.geometry.patch_count() > kMaxExpandedPatches)
            throw Error(
                FileLoc{job.scene_path, 0, 0},
                fmt::format("--matrix: the hierarchical links stand for a {0} x {0} matrix, more than "
                            "the {1} x {1} this command expands; drop --matrix (the report and the "
                            "summary need none) or use fewer patches",
                            q.geometry.patch_count(), kMaxExpandedPatches));
        if (job.sensors_path && q.scene.sensors.empty())
            throw Error(FileLoc{job.scene_path, 0, 0},
                        "--sensors: the scene has no sensors (add {name, type: sensor, position: [x, y, z], "
                        "normal: [x, y, z]} to its surfaces)");
    });

    const Stopwatch clock;
    if (job.matrix_path)
        write_matrix(*job.matrix_path, p.geometry,
                     p.hierarchy ? expand_links(*p.hierarchy, p.geometry) : p.ff);
    if (job.sensors_path) {
        // The matrix CSV's column labels; one row per sensor.
        std::string csv = "sensor";
        for (int j = 0; j < p.geometry.patch_count(); ++j) csv += ",\"" + p.geometry.patch_label(j) + "\"";
        csv += "\n";
        for (std::size_t k = 0; k < p.sensors.size(); ++k) {
            csv += "\"" + p.scene.sensors[k].name + "\"";
            for (const double f : p.sensors[k].F) csv += fmt::format(",{:.17g}", f);
            csv += "\n";
        }
        write_text_file(*job.sensors_path, csv);
    }
    const double export_s = clock.seconds();

    if (job.report_path) {
        nlohmann::json j;
        j["scene"] = job.scene_path;
        add_prepared_json(j, p);
        j["matrix"] = job.matrix_path ? nlohmann::json(*job.matrix_path) : nlohmann::json(nullptr);
        j["sensors_file"] = job.sensors_path ? nlohmann::json(*job.sensors_path) : nlohmann::json(nullptr);
        j["timings"] = {{"load_s", p.load_s},
                        {"form_factors_s", p.form_factors_s},
                        {"sensors_s", p.sensors_s},
                        {"export_s", export_s},
                        {"total_s", total.seconds()}};
        write_text_file(*job.report_path, j.dump(2) + "\n");
    }

    std::string s = "radiosa formfactors " + job.scene_path + " (" +
                    std::to_string(p.geometry.patch_count()) + " patches on " +
                    std::to_string(p.geometry.surface_count()) + " surfaces)\n";
    s += prepared_summary(p);
    if (job.matrix_path) {
        s += "  wrote " + *job.matrix_path;
        if (job.matrix_path->ends_with(".npy"))
            s += " and " + npy_patch_table_path(*job.matrix_path).string();
        s += "\n";
    }
    if (job.sensors_path) s += "  wrote " + *job.sensors_path + "\n";
    return s;
}

}  // namespace radiosa
