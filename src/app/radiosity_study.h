#pragma once
// `radiosa accuracy --radiosity`: the error of the radiosity B itself (not only of F) against
// the total run time (form factors + solve), for the seed scene and its stiff variant (every
// reflectance 0.999), with both form-factor methods at several settings; and whether the
// reported radiosity_error_bound covers it. Writes radiosity.csv and radiosity.md
// (tools/plot-radiosity plots the CSV).
#include <ostream>
#include <string>

namespace radiosa {

struct RadiosityStudyJob {
    std::string out_dir = "out/accuracy";
    bool quick = false;  // a loose reference and two settings per method (a smoke test)
    std::string scene = "scenes/baranoski1991.yaml";
    std::string stiff_scene = "scenes/baranoski1991-stiff.yaml";
};

void run_radiosity_study(const RadiosityStudyJob& job, std::ostream& out);

}  // namespace radiosa
