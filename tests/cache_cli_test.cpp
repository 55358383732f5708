// The cache through the command line and across processes: formfactors, export, list,
// verify, clear, and two processes racing on a cold cache.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/cli.h"
#include "cli_run.h"
#include "util/math.h"

namespace radiosa {

namespace fs = std::filesystem;
using test::CliRun;
using test::fresh_dir;
using test::read_json;
using test::run;

namespace {
const std::string kScene = RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml";
const std::string kCamA = RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml";

std::vector<fs::path> files_in(const fs::path& d) {
    std::vector<fs::path> v;
    for (const auto& e : fs::directory_iterator(d)) v.push_back(e.path());
    return v;
}

// A minimal .npy 1.0 reader, written from the format's definition, independent of the writer.
std::vector<double> read_npy(const fs::path& p, int* rows, int* cols) {
    std::ifstream in(p, std::ios::binary);
    std::string bytes{std::istreambuf_iterator<char>(in), {}};
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
    const std::size_t hlen =
        static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
    EXPECT_EQ((10 + hlen) % 64, 0u);
    const std::string header = bytes.substr(10, hlen);
    EXPECT_NE(header.find("'descr': '<f8'"), std::string::npos);
    EXPECT_NE(header.find("'fortran_order': False"), std::string::npos);
    EXPECT_EQ(header.back(), '\n');
    std::sscanf(header.c_str() + header.find("'shape': (") + 10, "%d, %d", rows, cols);
    std::vector<double> v(static_cast<std::size_t>(*rows) * *cols);
    EXPECT_EQ(bytes.size(), 10 + hlen + 8 * v.size());
    std::memcpy(v.data(), bytes.data() + 10 + hlen, 8 * v.size());
    return v;
}
}  // namespace

TEST(CacheCli, SecondRenderHitsAndReportsIt) {
    const fs::path d = fresh_dir("radiosa_cachecli_hit");
    const std::string cache = (d / "cache").string();
    auto render = [&](const std::string& report) {
        return run({"render", kScene, "-c", kCamA, "-o", (d / "a.png").string(), "--width", "32", "--height",
                    "32", "--samples", "1", "--cache-dir", cache, "--report", (d / report).string()});
    };
    CliRun r = render("1.json");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("cache miss"), std::string::npos);
    r = render("2.json");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("cache hit"), std::string::npos);
    const auto j1 = read_json(d / "1.json"), j2 = read_json(d / "2.json");
    EXPECT_EQ(j1["form_factor_cache"]["status"], "miss");
    EXPECT_EQ(j2["form_factor_cache"]["status"], "hit");
    EXPECT_EQ(j2["form_factor_cache"]["compute_s"], 0.0);
    EXPECT_EQ(j1["closure_max_error"], j2["closure_max_error"]);
    EXPECT_EQ(j1["form_factor_stats"], j2["form_factor_stats"]);
    // The seed scene's quads and sphere each took time; the cached matrix has no times.
    const auto& by_type = j1["form_factor_seconds_by_type"];
    ASSERT_TRUE(by_type.is_object()) << by_type;
    EXPECT_EQ(by_type.size(), 2u) << by_type;
    EXPECT_GT(by_type.value("quad", 0.0), 0.0) << by_type;
    EXPECT_GT(by_type.value("sphere", 0.0), 0.0) << by_type;
    EXPECT_TRUE(j2["form_factor_seconds_by_type"].is_null());
    EXPECT_GT(j1.value("peak_memory_mb", 0.0), 1.0);
    r = run({"render", kScene, "-c", kCamA, "-o", (d / "a.png").string(), "--width", "8", "--height", "8",
             "--no-cache", "--report", (d / "3.json").string()});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(read_json(d / "3.json")["form_factor_cache"]["status"], "off");
    fs::remove_all(d);
}

TEST(CacheCli, FormfactorsExportsNpyAndCsv) {
    const fs::path d = fresh_dir("radiosa_cachecli_export");
    CliRun r = run({"formfactors", kScene, "--no-cache", "-m", (d / "F.npy").string(), "--report",
                    (d / "r.json").string()});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("closure max"), std::string::npos);
    EXPECT_NE(r.out.find("reciprocity max"), std::string::npos);
    int rows = 0, cols = 0;
    const std::vector<double> F = read_npy(d / "F.npy", &rows, &cols);
    ASSERT_EQ(rows, 86);
    ASSERT_EQ(cols, 86);
    // Patch table beside it; areas and F satisfy reciprocity.
    std::ifstream table(d / "F.patches.csv");
    std::string line;
    std::getline(table, line);
    EXPECT_EQ(line, "patch,surface,is,it,area");
    std::vector<double> area;
    while (std::getline(table, line)) area.push_back(std::stod(line.substr(line.rfind(',') + 1)));
    ASSERT_EQ(area.size(), 86u);
    EXPECT_NEAR(area[0], 16.0 / 9.0, 1e-15);
    // A polar sphere patch: a cap of polar angle pi/4 split in 8: 2 pi (1 - cos(pi/4)) / 8.
    EXPECT_NEAR(area[85], kPi / 4.0 * (1.0 - std::sqrt(0.5)), 1e-12);
    for (int i = 0; i < 86; ++i)
        for (int j = 0; j < 86; ++j)  // within the default tolerance (1e-6 on each F) on both sides
            EXPECT_NEAR(area[i] * F[i * 86 + j], area[j] * F[j * 86 + i], 1e-6 * (area[i] + area[j]));
    const auto rep = read_json(d / "r.json");
    EXPECT_EQ(rep["form_factor_cache"]["status"], "off");
    EXPECT_EQ(rep["patches"], 86);

    // CSV: a header naming the columns, the same numbers to the last bit.
    r = run({"formfactors", kScene, "--no-cache", "-q", "-m", (d / "F.csv").string()});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.out, "");
    std::ifstream csv(d / "F.csv");
    std::getline(csv, line);
    EXPECT_EQ(line.rfind("patch,surface,is,it,area,\"face1[0,0]\",\"face1[1,0]\"", 0), 0u);
    int n = 0;
    while (std::getline(csv, line)) {
        std::vector<std::string> f;
        std::stringstream ss(line);
        for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
        ASSERT_EQ(f.size(), 5u + 86u);
        for (int j = 0; j < 86; ++j) EXPECT_EQ(std::stod(f[5 + j]), F[n * 86 + j]);
        ++n;
    }
    EXPECT_EQ(n, 86);
    r = run({"formfactors", kScene, "-m", (d / "F.txt").string()});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err,
              "error: " + (d / "F.txt").string() + ": unknown matrix format '.txt' (use .csv or .npy)\n");
    fs::remove_all(d);
}

TEST(CacheCli, ListVerifyClear) {
    const fs::path d = fresh_dir("radiosa_cachecli_cmds");
    const std::string cache = (d / "c").string();
    ASSERT_EQ(run({"formfactors", kScene, "--cache-dir", cache, "-q"}).code, 0);
    ASSERT_EQ(run({"formfactors", kScene, "-p", "3", "--cache-dir", cache, "-q"}).code, 0);
    CliRun r = run({"cache", "list", "--cache-dir", cache});
    EXPECT_EQ(r.code, 0);
    EXPECT_NE(r.out.find("2 matrix file(s)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("baranoski1991"), std::string::npos);
    r = run({"cache", "verify", "--cache-dir", cache});
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("2 file(s) checked, 0 bad"), std::string::npos) << r.out;
    // Damage one file: verify names it and fails; the next run rebuilds it with a warning.
    const fs::path victim = files_in(cache).front();
    fs::resize_file(victim, fs::file_size(victim) - 10);
    r = run({"cache", "verify", "--cache-dir", cache});
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.out.find("BAD  " + victim.string()), std::string::npos) << r.out;
    r = run({"cache", "clear", "--cache-dir", cache});
    EXPECT_EQ(r.code, 0);
    EXPECT_NE(r.out.find("removed 2 file(s)"), std::string::npos) << r.out;
    EXPECT_TRUE(fs::is_empty(cache));
    fs::remove_all(d);
}

TEST(CacheCli, DamagedFileWarnsOnStderrAndRenders) {
    const fs::path d = fresh_dir("radiosa_cachecli_warn");
    const std::string cache = (d / "c").string();
    ASSERT_EQ(run({"formfactors", kScene, "--cache-dir", cache, "-q"}).code, 0);
    const fs::path file = files_in(cache).front();
    std::fstream(file, std::ios::in | std::ios::out | std::ios::binary).seekp(200).put('\x7f');
    const CliRun r = run({"formfactors", kScene, "--cache-dir", cache, "--report", (d / "r.json").string()});
    ASSERT_EQ(r.code, 0);
    EXPECT_EQ(r.err, "warning: cache file " + file.string() +
                         ": checksum mismatch (the file is damaged or truncated); recomputing it\n");
    const auto j = read_json(d / "r.json");
    EXPECT_EQ(j["form_factor_cache"]["status"], "rebuilt");
    EXPECT_EQ(j["form_factor_cache"]["reason"], "checksum mismatch (the file is damaged or truncated)");
    fs::remove_all(d);
}

// Two processes on a cold cache: both finish with the same matrix, it is computed once (the
// other waits for the lock and loads it), and exactly one complete file remains.
TEST(CacheCli, ConcurrentProcessesOnAColdCache) {
    const fs::path d = fresh_dir("radiosa_cachecli_race");
    const std::string cache = (d / "c").string();
    const std::string cmd =
        std::string(RADIOSA_BINARY) + " formfactors " + kScene + " -p 12 -q --cache-dir " + cache;
    const std::string both = cmd + " --report " + (d / "1.json").string() + " & a=$!; " + cmd + " --report " +
                             (d / "2.json").string() + " & b=$!; wait $a && wait $b";
    ASSERT_EQ(std::system(("bash -c '" + both + "'").c_str()), 0);
    const auto j1 = read_json(d / "1.json"), j2 = read_json(d / "2.json");
    const std::string s1 = j1["form_factor_cache"]["status"], s2 = j2["form_factor_cache"]["status"];
    EXPECT_TRUE((s1 == "miss" && s2 == "hit") || (s1 == "hit" && s2 == "miss")) << s1 << " " << s2;
    EXPECT_EQ(j1["closure_max_error"], j2["closure_max_error"]);
    const auto files = files_in(cache);
    ASSERT_EQ(files.size(), 1u);  // no temporaries, no lock left
    EXPECT_EQ(files[0].extension(), ".rff");
    EXPECT_EQ(run({"cache", "verify", "--cache-dir", cache}).code, 0);
    fs::remove_all(d);
}

}  // namespace radiosa
