// `radiosa accuracy --quick`: every configuration runs, the CSV, Markdown and plot are written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "app/cli.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

// `radiosa accuracy ARGS --out DIR` into a fresh DIR under the temporary directory: the run's
// directory, its stdout, and the lines of its CSV `csv_name` (the header first).
struct Study {
    fs::path dir;
    std::string out;
    std::vector<std::string> lines;
};
Study run_study(const std::string& dir_name, std::vector<std::string> args, const std::string& csv_name) {
    Study st;
    st.dir = fs::temp_directory_path() / dir_name;
    fs::remove_all(st.dir);
    args.insert(args.begin(), {"radiosa", "accuracy"});
    args.insert(args.end(), {"--out", st.dir.string()});
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    std::ostringstream out, err;
    EXPECT_EQ(run_cli(static_cast<int>(argv.size()), argv.data(), out, err), 0) << err.str();
    st.out = out.str();
    std::ifstream csv(st.dir / csv_name);
    for (std::string line; std::getline(csv, line);) st.lines.push_back(line);
    return st;
}

// The comma-separated fields of a line (no quoting).
std::vector<std::string> fields(const std::string& line) {
    std::vector<std::string> f;
    std::istringstream in(line);
    for (std::string x; std::getline(in, x, ',');) f.push_back(x);
    return f;
}

}  // namespace

TEST(AccuracyCli, QuickStudyWritesCsvAndMarkdown) {
    const Study st = run_study("radiosa_accuracy", {"--quick"}, "accuracy.csv");
    ASSERT_FALSE(st.lines.empty());
    EXPECT_EQ(st.lines[0], "config,method,parameter,seconds,max_error,mean_error");
    int rows = 0, adaptive_ok = 0;
    for (std::size_t k = 1; k < st.lines.size(); ++k) {
        const std::string& line = st.lines[k];
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
    EXPECT_TRUE(fs::file_size(st.dir / "accuracy.md") > 500);
    EXPECT_FALSE(
        fs::exists(st.dir / "accuracy.png"));  // plots are tools/plot-accuracy's (gnuplot), not the program's
    fs::remove_all(st.dir);
}

// `radiosa accuracy --validation` on a few configurations per family: every measurement at
// tolerances 1e-4 and 1e-6 within its estimate (or at the reference formulas' rounding level),
// and every planar entry exact; the curved families' too.
TEST(AccuracyCli, ValidationStudyEstimatesCoverTheErrorsAtModerateTolerances) {
    const Study st = run_study("radiosa_validation", {"--validation", "--per-family", "4"}, "validation.csv");
    ASSERT_FALSE(st.lines.empty());
    EXPECT_EQ(st.lines[0],
              "config,half,family,parameters,tolerance,exact,value,error,estimate,capped,seconds");
    int rows = 0, checked = 0;
    for (std::size_t k = 1; k < st.lines.size(); ++k) {
        const std::string& line = st.lines[k];
        ++rows;
        // Fields after the quoted parameters: tolerance, exact, value, error, estimate, capped, seconds.
        const std::vector<std::string> f = fields(line.substr(line.rfind('"') + 2));
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
    // 5 families x 4, 1 sphere's inside, and the curved types' 3 x 4 (coaxial disks, a ball over
    // a disk, closed cones and frustums), 4 tolerances each.
    EXPECT_EQ(rows, (5 * 4 + 1 + 3 * 4) * 4);
    EXPECT_EQ(checked, rows / 2);
    EXPECT_NE(st.out.find("checking half: error within its estimate"), std::string::npos);
    fs::remove_all(st.dir);
}

// `accuracy --radiosity --quick`: both scenes, both methods; the adaptive rows' reported bound
// covers the measured error of B (against the reference, within the reference's own bound),
// the stiff scene's error is larger than the seed scene's at the same tolerance (the 1/(1 - rho)
// amplification), and the fixed rule's rows have no bound.
TEST(AccuracyCli, RadiosityStudyBoundsCoverTheErrorOfB) {
    const Study st = run_study("radiosa_radiosity_study", {"--radiosity", "--quick"}, "radiosity.csv");
    ASSERT_FALSE(st.lines.empty());
    EXPECT_EQ(st.lines[0], "scene,method,setting,form_factors_s,solve_s,total_s,error,bound,reference_bound");
    int rows = 0;
    std::map<std::string, double> adaptive_error;
    for (std::size_t k = 1; k < st.lines.size(); ++k) {
        const std::string& line = st.lines[k];
        ++rows;
        std::vector<std::string> f = fields(line);
        if (f.size() == 8) f.insert(f.begin() + 7, "");  // an empty bound at the end of a split
        ASSERT_EQ(f.size(), 9u) << line;
        const double error = std::stod(f[6]), reference_bound = std::stod(f[8]);
        EXPECT_GE(error, 0.0) << line;
        if (f[1] == "gauss") {
            EXPECT_TRUE(f[7].empty()) << line;
        } else {
            ASSERT_FALSE(f[7].empty()) << line;
            EXPECT_LE(error, std::stod(f[7]) + reference_bound) << line;
            adaptive_error[f[0] + f[2]] = error;
        }
    }
    EXPECT_EQ(rows, 2 * (2 + 2));  // 2 scenes x (2 Gauss orders + 2 tolerances)
    EXPECT_GT(adaptive_error["stiff0.001"], 10 * adaptive_error["seed0.001"]);
    fs::remove_all(st.dir);
}

}  // namespace radiosa
