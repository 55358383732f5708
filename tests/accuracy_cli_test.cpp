// `radiosa accuracy --quick`: every configuration runs, the CSV, Markdown and plot are written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "app/cli.h"

namespace radiosa {

namespace fs = std::filesystem;

TEST(AccuracyCli, QuickStudyWritesCsvAndMarkdown) {
    const fs::path d = fs::temp_directory_path() / "radiosa_accuracy";
    fs::remove_all(d);
    const std::string outdir = d.string();
    const char* argv[] = {"radiosa", "accuracy", "--quick", "--out", outdir.c_str()};
    std::ostringstream out, err;
    ASSERT_EQ(run_cli(5, argv, out, err), 0) << err.str();
    std::ifstream csv(d / "accuracy.csv");
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "config,method,parameter,seconds,max_error,mean_error");
    int rows = 0, adaptive_ok = 0;
    while (std::getline(csv, line)) {
        ++rows;
        // Error-controlled rows at tolerance 1e-3 stay within it on every configuration.
        if (line.find(",adaptive,0.001,") != std::string::npos) {
            const double max_err = std::stod(line.substr(line.rfind(',', line.rfind(',') - 1) + 1));
            EXPECT_LE(max_err, 1e-3) << line;
            ++adaptive_ok;
        }
    }
    EXPECT_EQ(rows, 20 * 2 + 1);  // 20 configurations x (Gauss p = 2, adaptive 1e-3) + 32 facets
    EXPECT_EQ(adaptive_ok, 20);
    EXPECT_TRUE(fs::file_size(d / "accuracy.md") > 500);
    EXPECT_FALSE(
        fs::exists(d / "accuracy.png"));  // plots are tools/plot-accuracy's (gnuplot), not the program's
    fs::remove_all(d);
}

// `radiosa accuracy --validation` on a few configurations per family: every measurement at
// tolerances 1e-4 and 1e-6 within its estimate (or at the reference formulas' rounding level),
// and every planar entry exact.
TEST(AccuracyCli, ValidationStudyEstimatesCoverTheErrorsAtModerateTolerances) {
    const fs::path d = fs::temp_directory_path() / "radiosa_validation";
    fs::remove_all(d);
    const std::string outdir = d.string();
    const char* argv[] = {"radiosa", "accuracy", "--validation", "--per-family",
                          "6",       "--out",    outdir.c_str()};
    std::ostringstream out, err;
    ASSERT_EQ(run_cli(7, argv, out, err), 0) << err.str();
    std::ifstream csv(d / "validation.csv");
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "config,half,family,parameters,tolerance,exact,value,error,estimate,capped,seconds");
    int rows = 0, checked = 0;
    while (std::getline(csv, line)) {
        ++rows;
        // Fields after the quoted parameters: tolerance, exact, value, error, estimate, capped, seconds.
        std::istringstream tail(line.substr(line.rfind('"') + 2));
        std::vector<std::string> f;
        for (std::string x; std::getline(tail, x, ',');) f.push_back(x);
        ASSERT_EQ(f.size(), 7u) << line;
        const double tol = std::stod(f[0]), error = std::stod(f[3]), estimate = std::stod(f[4]);
        if (line.find("rectangles") != std::string::npos) {
            EXPECT_LT(error, 1e-12) << line;
        }
        if (tol >= 1e-6) {
            EXPECT_LE(error, std::max(estimate, 1e-13)) << line;
            EXPECT_LE(error, tol) << line;
            ++checked;
        }
    }
    EXPECT_EQ(rows, (5 * 6 + 2) * 4);  // 5 families x 6, 2 spheres' insides, 4 tolerances each
    EXPECT_EQ(checked, rows / 2);
    EXPECT_NE(out.str().find("checking half: error within its estimate"), std::string::npos);
    fs::remove_all(d);
}

}  // namespace radiosa
