#pragma once
// The surface types a scene file can name (`type: quad`, `type: sphere`, ...). Each type's file
// defines one SurfaceType; registry.cpp lists them. Adding a type is: its file, one line in
// registry.cpp, its tests and its section of docs/scene-format.md. A test walks this list and
// checks that each type's every parameter reaches the form-factor cache key.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "surfaces/surface.h"
#include "util/yaml_reader.h"

namespace radiosa {

// One key of a surface's mapping with a YAML value, e.g. {"radius", "1.5"}.
struct SurfaceKeyValue {
    std::string key;
    std::string value;
};

// One surface of an entry that makes several (a file of Bezier patches, a mesh's faces).
struct SurfacePart {
    std::string suffix;  // the part is named "<entry name>.<suffix>"; empty for an entry's only part
    std::shared_ptr<const Surface> shape;
    std::optional<Rgb> reflectance;  // replaces the entry's (a mesh material's Kd)
    std::optional<Rgb> emission;     // replaces the entry's (a mesh material's Ke)
};

struct SurfaceType {
    std::string name;      // the value of `type:` in scene files
    std::uint32_t key_id;  // hashed into cache keys; never reuse or renumber one
    std::string keys;      // the type's own keys, for messages: "center, radius, facing"
    // Reads and validates the type's own keys (the scene reader reads name, patches,
    // reflectance and emission) and builds the surface; bad values throw Error at their
    // file:line:col. `name` is the surface's name, for messages.
    std::shared_ptr<const Surface> (*read)(YamlMap& m, const std::string& name);
    // For the cache-key test: a valid set of the type's keys, and alternatives that each change
    // one parameter (a key of `example` given another value) and must change the key.
    std::vector<SurfaceKeyValue> example;
    std::vector<SurfaceKeyValue> variants;
    // Types whose entries make several surfaces read through this instead of `read` (which is
    // then nullptr); files they name are relative to the scene file's folder.
    std::vector<SurfacePart> (*read_parts)(YamlMap& m, const std::string& name) = nullptr;
    // For the cache-key test: files the example and variants name, {file name, contents}.
    std::vector<SurfaceKeyValue> example_files = {};
};

// Every registered type, in registration order.
const std::vector<const SurfaceType*>& surface_types();
// nullptr when no type has this name.
const SurfaceType* find_surface_type(std::string_view name);
// "quad, sphere": for messages.
std::string surface_type_names();

}  // namespace radiosa
