#pragma once
// `radiosa accuracy --validation`: do the error estimates cover the true errors? Random
// configurations with closed-form answers (Howell's catalogue: opposed and perpendicular
// rectangles with and without a gap, a sphere above a rectangle's corner, a plate between two
// parallel squares; the inside of a sphere), over gaps from 1 down to 1e-9 of the patch size and scales from
// 1e-6 to 1e6, each at several tolerances. Configurations alternate between a fitting half, on which the
// safety factor the estimates would need is measured, and a checking half, on which coverage, tolerance and
// monotonicity are counted.
#include <ostream>
#include <string>

namespace radiosa {

struct ValidationJob {
    std::string out_dir = "out/accuracy";
    int per_family = 50;  // configurations per family
    unsigned seed = 1991;
};

struct ValidationSummary {
    int configurations = 0, measurements = 0;
    double fit_needed_factor = 0.0;                 // max over the fitting half of |error| / estimate
    int check_measurements = 0, check_covered = 0;  // |error| <= estimate
    int check_uncapped = 0, check_within_tolerance = 0;
    int check_pairs = 0, check_monotone = 0;  // consecutive tolerances: tighter is no worse
};

// Runs the study, writes validation.md and validation.csv into out_dir, prints a summary.
ValidationSummary run_validation(const ValidationJob& job, std::ostream& out);

}  // namespace radiosa
