#include "app/cache_cmd.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "cache/cache_file.h"
#include "cache/link_file.h"
#include "util/error.h"
#include "util/text.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

enum class Kind { Matrix, Links, Leftover, Other };

// "<32 hex>.rff" is a matrix file, "<32 hex>.rhl" a file of hierarchical links;
// "<32 hex>.tmp<pid>-<8 hex>.rff" (or .rhl) a temporary left by a killed run; "<32 hex>.lock" a
// lock file.
Kind classify(const fs::path& p) {
    const std::string name = p.filename().string();
    auto all_of = [](std::string_view s, auto pred) {
        return std::all_of(s.begin(), s.end(), [&](char c) { return pred(static_cast<unsigned char>(c)); });
    };
    const auto hex = [](unsigned char c) { return std::isdigit(c) || (c >= 'a' && c <= 'f'); };
    if (name.size() < 32 || !all_of(std::string_view(name).substr(0, 32), hex)) return Kind::Other;
    const std::string_view rest = std::string_view(name).substr(32);
    if (rest == ".rff") return Kind::Matrix;
    if (rest == ".rhl") return Kind::Links;
    if (rest == ".lock") return Kind::Leftover;
    if (rest.starts_with(".tmp") && (rest.ends_with(".rff") || rest.ends_with(".rhl")) && rest.size() > 8 &&
        all_of(rest.substr(4, rest.size() - 8),
               [&](unsigned char c) { return std::isdigit(c) != 0 || c == '-' || hex(c); }))
        return Kind::Leftover;
    return Kind::Other;
}

// The cache directory must be one: a path that exists and is not a directory is an Error.
void check_cache_dir(const fs::path& dir) {
    std::error_code ec;
    const fs::file_status st = fs::status(dir, ec);
    if (fs::exists(st) && !fs::is_directory(st))
        throw Error(printable(dir.string()) +
                    ": the cache path is not a directory (give --cache-dir a directory)");
}

// Entries of the kinds given, by name, whatever their file type (never following a link).
std::vector<fs::path> entries(const fs::path& dir, std::initializer_list<Kind> kinds) {
    std::vector<fs::path> v;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
        if (std::find(kinds.begin(), kinds.end(), classify(e.path())) != kinds.end()) v.push_back(e.path());
    std::sort(v.begin(), v.end());
    return v;
}

bool is_links(const fs::path& p) { return classify(p) == Kind::Links; }

bool is_regular(const fs::path& p) {
    std::error_code ec;
    return fs::symlink_status(p, ec).type() == fs::file_type::regular;
}

std::string human_size(std::uintmax_t b) {
    if (b < 10 * 1024) return fmt::format("{} B", b);
    if (b < 10 * 1024 * 1024) return fmt::format("{:.0f} KiB", b / 1024.0);
    return fmt::format("{:.0f} MiB", b / (1024.0 * 1024.0));
}

std::string human_age(const fs::path& p) {
    std::error_code ec;
    const auto t = fs::last_write_time(p, ec);
    if (ec) return "?";
    const double s = std::chrono::duration<double>(fs::file_time_type::clock::now() - t).count();
    if (s < 120) return fmt::format("{:.0f} s", std::max(0.0, s));
    if (s < 7200) return fmt::format("{:.0f} min", s / 60);
    if (s < 172800) return fmt::format("{:.0f} h", s / 3600);
    return fmt::format("{:.0f} days", s / 86400);
}

}  // namespace

void cache_list(const fs::path& dir, std::ostream& out) {
    check_cache_dir(dir);
    const auto files = entries(dir, {Kind::Matrix, Kind::Links});
    const auto links = std::count_if(files.begin(), files.end(), is_links);
    out << "cache " << printable(dir.string()) << ": " << files.size() - links << " matrix file(s), " << links
        << " link file(s)\n";
    if (files.empty()) return;
    out << fmt::format("{:<32}  {:<6} {:<24} {:>8} {:>10} {:>9}\n", "key", "kind", "scene", "patches", "size",
                       "age");
    for (const auto& f : files) {
        std::error_code ec;
        const std::string size = is_regular(f) ? human_size(fs::file_size(f, ec)) : "-";
        try {
            const CacheFileInfo info = is_links(f) ? read_link_info(f) : read_cache_info(f);
            out << fmt::format("{:<32}  {:<6} {:<24} {:>8} {:>10} {:>9}\n", f.stem().string(),
                               is_links(f) ? "links" : "matrix", printable(info.scene_name), info.patches,
                               size, human_age(f));
        } catch (const CacheFileError& e) {
            out << fmt::format("{:<32}  unreadable: {}\n", f.stem().string(), printable(e.what()));
        }
    }
}

bool cache_verify(const fs::path& dir, std::ostream& out) {
    check_cache_dir(dir);
    const auto files = entries(dir, {Kind::Matrix, Kind::Links});
    int bad = 0;
    for (const auto& f : files) {
        const std::string name = printable(f.string());
        try {
            const CacheFileInfo info = is_links(f) ? verify_link_file(f) : verify_cache_file(f);
            if (info.key.hex() != f.stem().string())
                throw CacheFileError("holds key " + info.key.hex() + ", which does not match its file name");
            out << "ok   " << name << " (" << printable(info.scene_name) << ", " << info.patches
                << " patches, " << (is_links(f) ? std::to_string(info.links) + " " : "") << info.layout
                << (info.compression == "zstd" ? ", zstd" : "") << ")\n";
        } catch (const CacheFileError& e) {
            ++bad;
            out << "BAD  " << name << ": " << printable(e.what()) << "\n";
        }
    }
    for (const auto& f : entries(dir, {Kind::Other}))
        out << "skip " << printable(f.string()) << ": not a cache file name (not checked)\n";
    const auto leftovers = entries(dir, {Kind::Leftover});
    out << files.size() << " file(s) checked, " << bad << " bad";
    if (!leftovers.empty())
        out << "; " << leftovers.size() << " lock or temporary file(s) ('radiosa cache clear' removes them)";
    out << "\n";
    return bad == 0;
}

void cache_clear(const fs::path& dir, std::ostream& out) {
    check_cache_dir(dir);
    std::uintmax_t bytes = 0;
    int count = 0;
    for (const auto& f : entries(dir, {Kind::Matrix, Kind::Links, Kind::Leftover})) {
        std::error_code ec;
        const std::uintmax_t size = fs::file_size(f, ec);
        if (fs::remove(f, ec)) {
            ++count;
            bytes += ec ? 0 : size;
        }
    }
    out << "removed " << count << " file(s), " << human_size(bytes) << ", from " << printable(dir.string())
        << "\n";
}

}  // namespace radiosa
