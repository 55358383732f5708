#include "app/formfactors_cmd.h"

#include <nlohmann/json.hpp>

#include "app/pipeline.h"
#include "formfactor/matrix_export.h"
#include "util/atomic_file.h"
#include "util/stopwatch.h"

namespace radiosa {

std::string run_formfactors(const FormFactorsJob& job) {
    const Stopwatch total;
    if (job.matrix_path) check_matrix_output(*job.matrix_path);
    if (job.report_path) check_output_path(*job.report_path);
    const ThreadLimit limit(job.threads);
    const Prepared p = prepare(job.scene_path, job.form_factors, job.warn);

    const Stopwatch clock;
    if (job.matrix_path) write_matrix(*job.matrix_path, p.geometry, p.ff);
    const double export_s = clock.seconds();

    if (job.report_path) {
        nlohmann::json j;
        j["scene"] = job.scene_path;
        add_prepared_json(j, p);
        j["matrix"] = job.matrix_path ? nlohmann::json(*job.matrix_path) : nlohmann::json(nullptr);
        j["timings"] = {{"load_s", p.load_s},
                        {"form_factors_s", p.form_factors_s},
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
    return s;
}

}  // namespace radiosa
