// MPI jobs end to end (mpirun --oversubscribe -np 2 and 3 on this machine): the matrix and the
// frames are identical to one process, a rank killed mid-job ends the job with nothing partial
// on disk, and bad input is reported once. Skipped in a build without MPI (-DRADIOSA_MPI=OFF).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <thread>

#include "cli_run.h"
#include "encode/features.h"

namespace radiosa {

namespace fs = std::filesystem;
using test::fresh_dir;
using test::read_bytes;
using test::read_json;

namespace {

#ifdef RADIOSA_MPIEXEC
const bool kMpi = true;
const std::string kMpiexec = RADIOSA_MPIEXEC;
#else
const bool kMpi = false;
const std::string kMpiexec;
#endif

const std::string kBinary = RADIOSA_BINARY;
const std::string kScene = RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml";

std::string mpirun(int ranks) {
    // Under AddressSanitizer (.ci/sanitize), no leak check for the ranks: Open MPI keeps memory
    // until exit in components it unloads at MPI_Finalize, so the reports cannot even be
    // attributed (let alone suppressed) by library. Every other process stays leak-checked.
    std::string env;
    if (const char* asan = std::getenv("ASAN_OPTIONS"))
        env = "ASAN_OPTIONS=" + std::string(asan) + ":detect_leaks=0 ";
    // As root (CI's containers) Open MPI wants to be told; more ranks than cores need --oversubscribe.
    return env + kMpiexec + (::geteuid() == 0 ? " --allow-run-as-root" : "") + " --oversubscribe -np " +
           std::to_string(ranks) + " " + kBinary;
}

int shell(const std::string& command) {
    const int status = std::system(("bash -c '" + command + "'").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string read_text(const fs::path& p) {
    std::ifstream in(p);
    return {std::istreambuf_iterator<char>(in), {}};
}

std::vector<fs::path> files_under(const fs::path& dir) {
    std::vector<fs::path> v;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) v.push_back(e.path());
    std::sort(v.begin(), v.end());
    return v;
}

// The files' names, one per line: what a failed check shows.
std::string listing(const std::vector<fs::path>& files) {
    std::string out;
    for (const fs::path& f : files) out += f.filename().string() + "\n";
    return out;
}

// `frames` frames at 24 fps of test::write_short_sequence.
fs::path write_sequence(const fs::path& dir, int frames) {
    return test::write_short_sequence(dir, 24, frames / 24.0);
}

// Leaves out lock files. Rank 0 removes its lock on the SIGTERM mpirun sends when a rank dies,
// but on a loaded machine mpirun's SIGKILL can come first (CI saw it); the file left is inert
// (the lock is an flock, released when its holder dies, and the next run takes it).
std::vector<fs::path> but_locks(std::vector<fs::path> files) {
    files.erase(std::remove_if(files.begin(), files.end(),
                               [](const fs::path& p) { return p.extension() == ".lock"; }),
                files.end());
    return files;
}

// Kills rank `rank` of the job whose command line contains `marker`, once `ready` exists.
// Returns false if it never appeared (the job ended first or never got there).
bool kill_rank_when(const std::string& marker, int rank, const std::function<bool()>& ready) {
    for (int k = 0; k < 600 && !ready(); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (!ready()) return false;
    const std::string cmd = "n=0; for p in $(pgrep -f " + marker +
                            "); do if grep -qa OMPI_COMM_WORLD_RANK=" + std::to_string(rank) +
                            " /proc/$p/environ 2>/dev/null; then kill -9 $p && n=$((n+1)); fi; "
                            "done; test $n -eq 1";
    return shell(cmd) == 0;
}

}  // namespace

TEST(Mpi, VersionSaysSo) {
    if (!kMpi) GTEST_SKIP() << "built with -DRADIOSA_MPI=OFF";
    const fs::path d = fresh_dir("radiosa_mpi_version");
    ASSERT_EQ(shell(kBinary + " --version > " + (d / "v.txt").string()), 0);
    EXPECT_NE(read_text(d / "v.txt").find("MPI: yes (Open MPI"), std::string::npos) << read_text(d / "v.txt");
    fs::remove_all(d);
}

// The same .npy, bit for bit, from one process, 2 ranks of one thread and 3 ranks of two, for
// both methods; the report says how many ranks there were.
TEST(Mpi, MatrixIdenticalToOneProcess) {
    if (!kMpi) GTEST_SKIP() << "built with -DRADIOSA_MPI=OFF";
    const fs::path d = fresh_dir("radiosa_mpi_matrix");
    for (const std::string method : {"--ff-tolerance 1e-7", "-p 7"}) {
        const std::string args = " formfactors " + kScene + " " + method + " --no-cache -q";
        ASSERT_EQ(shell(kBinary + args + " -m " + (d / "one.npy").string()), 0);
        ASSERT_EQ(shell(mpirun(2) + args + " --threads 1 -m " + (d / "two.npy").string() + " --report " +
                        (d / "two.json").string()),
                  0);
        ASSERT_EQ(shell(mpirun(3) + args + " --threads 2 -m " + (d / "three.npy").string()), 0);
        const auto one = read_bytes(d / "one.npy");
        ASSERT_GT(one.size(), 86u * 86u * 8u);
        EXPECT_EQ(one, read_bytes(d / "two.npy")) << method;
        EXPECT_EQ(one, read_bytes(d / "three.npy")) << method;
        EXPECT_EQ(read_json(d / "two.json")["ranks"], 2);
    }
    fs::remove_all(d);
}

// A sequence's MP4 and numbered PNGs from 3 ranks equal one process's, byte for byte, and
// frames were rendered by more than rank 0.
TEST(Mpi, FramesIdenticalToOneProcess) {
    if (!kMpi) GTEST_SKIP() << "built with -DRADIOSA_MPI=OFF";
    if (!kHasVideo) GTEST_SKIP() << "built with -DRADIOSA_VIDEO=OFF: no .mp4 output to compare";
    const fs::path d = fresh_dir("radiosa_mpi_frames");
    const fs::path seq = write_sequence(d, 24);
    const std::string args = " render --sequence " + seq.string() + " --width 128 --height 96 --threads 1 -q";
    fs::create_directories(d / "one");
    fs::create_directories(d / "three");
    ASSERT_EQ(
        shell(kBinary + args + " -o " + (d / "one/v.mp4").string() + " -o " + (d / "one/%02d.png").string()),
        0);
    ASSERT_EQ(shell(mpirun(3) + args + " -o " + (d / "three/v.mp4").string() + " -o " +
                    (d / "three/%02d.png").string() + " --report " + (d / "r.json").string()),
              0);
    const auto one = files_under(d / "one"), three = files_under(d / "three");
    ASSERT_EQ(one.size(), 25u);  // 24 frames and the video
    ASSERT_EQ(three.size(), one.size());
    for (std::size_t k = 0; k < one.size(); ++k) {
        EXPECT_EQ(one[k].filename(), three[k].filename());
        EXPECT_EQ(read_bytes(one[k]), read_bytes(three[k])) << three[k];
    }
    const auto j = read_json(d / "r.json");
    EXPECT_EQ(j["ranks"], 3);
    int elsewhere = 0;
    for (const auto& f : j["frames"]) elsewhere += f["rank"].get<int>() != 0;
    EXPECT_GT(elsewhere, 0);
    fs::remove_all(d);
}

// A rank killed while the matrix is computed (the lock file shows it is), and another while
// frames are written (the video's temporary shows it): the job fails, and neither a cache file,
// a lock, a video, a temporary nor a report is left.
TEST(Mpi, KilledRankLeavesNothingPartial) {
    if (!kMpi) GTEST_SKIP() << "built with -DRADIOSA_MPI=OFF";
    if (!kHasVideo) GTEST_SKIP() << "built with -DRADIOSA_VIDEO=OFF: no .mp4 output to compare";
    const fs::path d = fresh_dir("radiosa_mpi_killed");
    const fs::path out = d / "out", cache = d / "cache";
    fs::create_directories(out);
    const std::string marker = "radiosa_mpi_killed";
    auto has = [](const fs::path& dir, const std::string& pattern) {
        std::error_code ec;
        for (const auto& e : fs::directory_iterator(dir, ec))
            if (std::regex_search(e.path().filename().string(), std::regex(pattern))) return true;
        return false;
    };
    {  // while computing form factors
        const std::string job = mpirun(3) + " formfactors " + kScene +
                                " --ff-tolerance 1e-9 --threads 1 -q -m " + (out / "F.npy").string() +
                                " --report " + (out / "r.json").string() + " --cache-dir " + cache.string() +
                                " 2> " + (d / "err1.txt").string();
        std::thread killer([&] {
            EXPECT_TRUE(kill_rank_when(marker, 2, [&] { return has(cache, "\\.lock$"); }))
                << "rank 2 not killed: no lock seen, or not exactly one such process";
        });
        EXPECT_NE(shell(job), 0) << read_text(d / "err1.txt");
        killer.join();
        EXPECT_EQ(listing(files_under(out)), "") << read_text(d / "err1.txt");
        EXPECT_EQ(listing(but_locks(files_under(cache))), "") << read_text(d / "err1.txt");
    }
    {  // while writing frames (the matrix cached first, by one process)
        const fs::path seq = write_sequence(d, 240);
        ASSERT_EQ(shell(kBinary + " formfactors " + kScene + " -q --cache-dir " + cache.string()), 0);
        const std::string job = mpirun(3) + " render --sequence " + seq.string() +
                                " --width 320 --height 240 --threads 1 -q -o " + (out / "v.mp4").string() +
                                " --report " + (out / "r.json").string() + " --cache-dir " + cache.string() +
                                " 2> " + (d / "err2.txt").string();
        std::thread killer([&] {
            EXPECT_TRUE(kill_rank_when(marker, 1, [&] { return has(out, "\\.tmp"); }))
                << "rank 1 not killed: no temporary seen, or not exactly one such process";
        });
        EXPECT_NE(shell(job), 0) << read_text(d / "err2.txt");
        killer.join();
        EXPECT_EQ(listing(files_under(out)), "") << read_text(d / "err2.txt");
        // The complete matrix from before, nothing else.
        EXPECT_EQ(but_locks(files_under(cache)).size(), 1u) << listing(files_under(cache));
    }
    fs::remove_all(d);
}

// Bad input: one message, from rank 0, not one per rank; exit code 1.
TEST(Mpi, BadInputReportedOnce) {
    if (!kMpi) GTEST_SKIP() << "built with -DRADIOSA_MPI=OFF";
    const fs::path d = fresh_dir("radiosa_mpi_bad");
    std::ofstream(d / "bad.yaml") << "name: bad\nsurfaces:\n  - {name: s, type: sphere, center: [0, 0, 0], "
                                     "radius: -1, patches: [2, 2], reflectance: [0.5, 0.5, 0.5]}\n";
    EXPECT_EQ(
        shell(mpirun(3) + " formfactors " + (d / "bad.yaml").string() + " 2> " + (d / "err.txt").string()),
        1);
    const std::string err = read_text(d / "err.txt");
    const std::regex line("^error: .*bad\\.yaml:3:\\d+: radius must be > 0, got -1$", std::regex::multiline);
    EXPECT_EQ(std::distance(std::sregex_iterator(err.begin(), err.end(), line), std::sregex_iterator()), 1)
        << err;
    const std::regex any_error("error: ");
    EXPECT_EQ(std::distance(std::sregex_iterator(err.begin(), err.end(), any_error), std::sregex_iterator()),
              1)
        << err;
    fs::remove_all(d);
}

}  // namespace radiosa
