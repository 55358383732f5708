#pragma once
// Strict, located access to YAML documents for the scene and camera readers.
// Every value read keeps its place in the file so that errors can name file:line:col;
// unknown and duplicate keys are errors, so a typo never silently becomes a default.
#include <yaml-cpp/yaml.h>

#include <array>
#include <optional>
#include <set>
#include <string>

#include "util/error.h"
#include "util/math.h"

namespace radiosa {

// Reads an input file whole: a missing, unreadable or oversized file is an Error.
std::string read_input_file(const std::string& path);
// Parses a document; malformed YAML, an empty document, or binary data becomes an Error
// naming the file and position.
YAML::Node load_yaml_string(const std::string& text, const std::string& filename);

FileLoc loc_of(const YAML::Node& node, const std::string& file);

// Scalar conversions. `what` names the value in messages ("radius", "reflectance[1]").
double yaml_number(const YAML::Node& node, const std::string& file, const std::string& what);
long long yaml_integer(const YAML::Node& node, const std::string& file, const std::string& what);
bool yaml_bool(const YAML::Node& node, const std::string& file, const std::string& what);
std::string yaml_string(const YAML::Node& node, const std::string& file, const std::string& what);
// A list of exactly 3 finite numbers; `form` names them in messages ("[x, y, z]").
Vec3 yaml_vec3(const YAML::Node& node, const std::string& file, const std::string& what,
               const std::string& form = "[x, y, z]");

class YamlMap {
public:
    // Throws if `node` is not a mapping or repeats a key. `what` names it ("surface 'face1'").
    YamlMap(const YAML::Node& node, std::string file, std::string what);

    bool has(const std::string& key) const;
    // The value of a required key; a missing key is reported at the mapping's position.
    YAML::Node required(const std::string& key);
    // The value of an optional key, or an undefined node.
    std::optional<YAML::Node> optional(const std::string& key);

    double number(const std::string& key);
    double number_or(const std::string& key, double fallback);
    long long integer(const std::string& key);
    long long integer_or(const std::string& key, long long fallback);
    bool boolean_or(const std::string& key, bool fallback);
    std::string string(const std::string& key);
    Vec3 vec3(const std::string& key);

    // Reports the first key that no getter asked for.
    void reject_unknown_keys(const std::string& allowed_hint) const;

    const std::string& file() const { return m_file; }
    const std::string& what() const { return m_what; }
    FileLoc loc() const { return loc_of(m_node, m_file); }
    FileLoc key_loc(const std::string& key) const;

private:
    YAML::Node m_node;
    std::string m_file;
    std::string m_what;
    std::set<std::string> m_used;
};

}  // namespace radiosa
