#include "util/yaml_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace radiosa {

namespace {

// Scene and camera files are small; a larger file is almost certainly the wrong file, and
// reading it whole would waste memory before the first error could be reported.
constexpr std::uintmax_t kMaxInputBytes = 16u << 20;

FileLoc loc_of_mark(const YAML::Mark& mark, const std::string& file) {
    if (mark.line < 0) return FileLoc{file, 0, 0};
    return FileLoc{file, mark.line + 1, mark.column + 1};
}

std::string describe(const YAML::Node& node) {
    switch (node.Type()) {
        case YAML::NodeType::Map:
            return "a mapping";
        case YAML::NodeType::Sequence:
            return "a list";
        case YAML::NodeType::Null:
            return "nothing";
        case YAML::NodeType::Scalar:
            return "'" + node.Scalar() + "'";
        default:
            return "nothing";
    }
}

}  // namespace

FileLoc loc_of(const YAML::Node& node, const std::string& file) { return loc_of_mark(node.Mark(), file); }

YAML::Node load_yaml_string(const std::string& text, const std::string& filename) {
    if (text.find('\0') != std::string::npos)
        throw Error(FileLoc{filename, 0, 0}, "file is binary, not YAML text");
    YAML::Node root;
    try {
        root = YAML::Load(text);
    } catch (const YAML::Exception& e) {
        throw Error(loc_of_mark(e.mark, filename), "malformed YAML: " + e.msg);
    }
    if (!root || root.IsNull())
        throw Error(FileLoc{filename, 1, 1}, "file is empty; expected a YAML mapping");
    return root;
}

std::string read_input_file(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error(path + ": no such file");
    if (std::filesystem::is_directory(path, ec)) throw Error(path + ": is a directory, expected a file");
    // A device or a pipe (/dev/zero, a FIFO) could block or never end.
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": is not a regular file");
    const auto size = std::filesystem::file_size(path, ec);
    if (!ec && size > kMaxInputBytes)
        throw Error(FileLoc{path, 0, 0},
                    "file is " + std::to_string(size >> 20) + " MiB; input files are limited to 16 MiB");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot be read (permissions?)");
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

double yaml_number(const YAML::Node& node, const std::string& file, const std::string& what) {
    if (!node.IsScalar()) throw Error(loc_of(node, file), what + " must be a number, got " + describe(node));
    std::string s = node.Scalar();
    std::string lower = s;
    std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
    if (lower.find("nan") != std::string::npos || lower.find("inf") != std::string::npos)
        throw Error(loc_of(node, file), what + " must be a finite number, got '" + s + "'");
    const char* first = s.data();
    const char* last = s.data() + s.size();
    if (first != last && *first == '+') ++first;
    double value = 0.0;
    // from_chars is locale-independent, unlike streams or strtod.
    const auto [ptr, ec] = std::from_chars(first, last, value);
    if (ec == std::errc::result_out_of_range)
        throw Error(loc_of(node, file), what + " is out of the range of double: '" + s + "'");
    if (ec != std::errc() || ptr != last || !std::isfinite(value))
        throw Error(loc_of(node, file), what + " must be a number, got '" + s + "'");
    return value;
}

long long yaml_integer(const YAML::Node& node, const std::string& file, const std::string& what) {
    if (!node.IsScalar())
        throw Error(loc_of(node, file), what + " must be an integer, got " + describe(node));
    const std::string& s = node.Scalar();
    const char* first = s.data();
    const char* last = s.data() + s.size();
    if (first != last && *first == '+') ++first;
    long long value = 0;
    const auto [ptr, ec] = std::from_chars(first, last, value);
    if (ec != std::errc() || ptr != last)
        throw Error(loc_of(node, file), what + " must be an integer, got '" + s + "'");
    return value;
}

bool yaml_bool(const YAML::Node& node, const std::string& file, const std::string& what) {
    // Only true/false: YAML 1.1's yes/no/on/off are too easy to write by accident.
    if (node.IsScalar() && node.Scalar() == "true") return true;
    if (node.IsScalar() && node.Scalar() == "false") return false;
    throw Error(loc_of(node, file), what + " must be true or false, got " + describe(node));
}

std::string yaml_string(const YAML::Node& node, const std::string& file, const std::string& what) {
    if (!node.IsScalar() || node.Scalar().empty())
        throw Error(loc_of(node, file), what + " must be a non-empty string, got " + describe(node));
    return node.Scalar();
}

Vec3 yaml_vec3(const YAML::Node& node, const std::string& file, const std::string& what,
               const std::string& form) {
    if (!node.IsSequence() || node.size() != 3)
        throw Error(loc_of(node, file), what + " must be a list of 3 numbers " + form);
    Vec3 v;
    for (int k = 0; k < 3; ++k) v[k] = yaml_number(node[k], file, what + "[" + std::to_string(k) + "]");
    return v;
}

YamlMap::YamlMap(const YAML::Node& node, std::string file, std::string what)
    : m_node(node), m_file(std::move(file)), m_what(std::move(what)) {
    if (!node.IsMap())
        throw Error(loc_of(node, m_file),
                    m_what + " must be a mapping of keys to values, got " + describe(node));
    std::set<std::string> seen;
    for (const auto& kv : node) {
        const std::string key = kv.first.Scalar();
        if (!seen.insert(key).second)
            throw Error(loc_of(kv.first, m_file), "key '" + key + "' appears twice in " + m_what);
    }
}

bool YamlMap::has(const std::string& key) const {
    for (const auto& kv : m_node)
        if (kv.first.Scalar() == key) return true;
    return false;
}

FileLoc YamlMap::key_loc(const std::string& key) const {
    for (const auto& kv : m_node)
        if (kv.first.Scalar() == key) return loc_of(kv.first, m_file);
    return loc();
}

std::optional<YAML::Node> YamlMap::optional(const std::string& key) {
    m_used.insert(key);
    for (const auto& kv : m_node)
        if (kv.first.Scalar() == key) {
            if (kv.second.IsNull())
                throw Error(loc_of(kv.first, m_file), "key '" + key + "' in " + m_what + " has no value");
            return kv.second;
        }
    return std::nullopt;
}

YAML::Node YamlMap::required(const std::string& key) {
    auto node = optional(key);
    if (!node) throw Error(loc(), m_what + " is missing the required key '" + key + "'");
    return *node;
}

double YamlMap::number(const std::string& key) { return yaml_number(required(key), m_file, key); }

double YamlMap::number_or(const std::string& key, double fallback) {
    auto node = optional(key);
    return node ? yaml_number(*node, m_file, key) : fallback;
}

long long YamlMap::integer(const std::string& key) { return yaml_integer(required(key), m_file, key); }

long long YamlMap::integer_or(const std::string& key, long long fallback) {
    auto node = optional(key);
    return node ? yaml_integer(*node, m_file, key) : fallback;
}

bool YamlMap::boolean_or(const std::string& key, bool fallback) {
    auto node = optional(key);
    return node ? yaml_bool(*node, m_file, key) : fallback;
}

std::string YamlMap::string(const std::string& key) { return yaml_string(required(key), m_file, key); }

Vec3 YamlMap::vec3(const std::string& key) { return yaml_vec3(required(key), m_file, key); }

void YamlMap::reject_unknown_keys(const std::string& allowed_hint) const {
    for (const auto& kv : m_node) {
        const std::string key = kv.first.Scalar();
        if (!m_used.count(key))
            throw Error(loc_of(kv.first, m_file),
                        "unknown key '" + key + "' in " + m_what + " (allowed: " + allowed_hint + ")");
    }
}

}  // namespace radiosa
