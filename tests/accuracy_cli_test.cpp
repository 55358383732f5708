// `radiosa accuracy --quick`: every configuration runs, the CSV, Markdown and plot are written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

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
    EXPECT_EQ(rows, 9 * 2 + 1);  // 9 configurations x (Gauss p = 2, adaptive 1e-3) + 32 facets
    EXPECT_EQ(adaptive_ok, 9);
    EXPECT_TRUE(fs::file_size(d / "accuracy.md") > 500);
    EXPECT_FALSE(
        fs::exists(d / "accuracy.png"));  // plots are tools/plot-accuracy's (gnuplot), not the program's
    fs::remove_all(d);
}

}  // namespace radiosa
