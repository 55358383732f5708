#pragma once
// Running the command line in-process for the end-to-end tests, and their scratch directories.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "app/cli.h"

namespace radiosa::test {

struct CliRun {
    int code;
    std::string out, err;
};

inline CliRun run(std::vector<std::string> args) {
    args.insert(args.begin(), "radiosa");
    std::vector<const char*> argv;
    for (auto& a : args) argv.push_back(a.c_str());
    std::ostringstream out, err;
    const int code = run_cli(static_cast<int>(argv.size()), argv.data(), out, err);
    return {code, out.str(), err.str()};
}

// An empty directory under the system's temporary directory.
inline std::filesystem::path fresh_dir(const std::string& name) {
    const std::filesystem::path d = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    return d;
}

inline std::vector<std::uint8_t> read_bytes(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

inline void write_bytes(const std::filesystem::path& p, const std::vector<std::uint8_t>& b) {
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(b.data()), static_cast<long>(b.size()));
}

inline nlohmann::json read_json(const std::filesystem::path& p) {
    std::ifstream in(p);
    return nlohmann::json::parse(in);
}

inline const std::string kSeedScene = RADIOSA_SOURCE_DIR "/scenes/baranoski1991.yaml";

// dir/seq.yaml: the seed scene over `duration` seconds at `fps`, a quarter orbit while face 3
// dims and the ceiling patch lights up (events between 0.2 s and 0.8 s).
inline std::filesystem::path write_short_sequence(const std::filesystem::path& dir, double fps,
                                                  double duration) {
    const std::filesystem::path p = dir / "seq.yaml";
    std::ofstream(p) << "scene: " << kSeedScene << "\nfps: " << fps << "\nduration_s: " << duration << R"(
camera:
  keys:
    - {time_s: 0, distance: 6, theta_deg: 0, phi_deg: 85}
    - {time_s: 1, distance: 6, theta_deg: 90, phi_deg: 85}
events:
  - {time_s: [0.2, 0.8], surface: face3, emission: [0, 0, 0]}
  - {time_s: [0.2, 0.8], surface: face6, patch: [1, 1], emission: [7, 7, 7]}
)";
    return p;
}

}  // namespace radiosa::test
