#pragma once
// `radiosa accuracy`: error against run time of each form-factor method on configurations
// whose answers are known in advance (closed forms, symmetry, closure), written as a CSV, a
// Markdown table and a log-log plot.
#include <ostream>
#include <string>

namespace radiosa {

struct AccuracyJob {
    std::string out_dir = "out/accuracy";
    bool quick = false;      // a few methods only (smoke test)
    double budget_s = 30.0;  // stop refining a method on a configuration once a run exceeds this
    int threads = 0;
    // --validation: the estimates' coverage study instead (app/validation_study.h), with this
    // many configurations per family.
    bool validation = false;
    int per_family = 50;
    // --radiosity: the error of B against run time instead (app/radiosity_study.h).
    bool radiosity = false;
};

// Runs the study, writes accuracy.csv and accuracy.md into out_dir (tools/plot-accuracy plots the CSV),
// prints a summary.
void run_accuracy(const AccuracyJob& job, std::ostream& out);

}  // namespace radiosa
