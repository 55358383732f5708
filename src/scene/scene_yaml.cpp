// Reads and validates scene files. The format is documented in docs/scene-format.md.
#include <cmath>
#include <filesystem>

#include "scene/scene.h"
#include "surfaces/placed.h"
#include "surfaces/registry.h"
#include "util/yaml_reader.h"

namespace radiosa {

namespace {

Rgb read_rgb(const YAML::Node& node, const std::string& file, const std::string& what) {
    return yaml_vec3(node, file, what, "[r, g, b]");
}

Rgb read_reflectance(const YAML::Node& node, const std::string& file) {
    Rgb rho = read_rgb(node, file, "reflectance");
    for (int k = 0; k < 3; ++k)
        if (rho[k] < 0.0 || rho[k] > 1.0)
            throw Error(loc_of(node[k], file),
                        "reflectance must be in [0, 1] (a surface cannot reflect more than it "
                        "receives), got " +
                            node[k].Scalar());
    return rho;
}

Rgb read_emission(const YAML::Node& node, const std::string& file) {
    Rgb e = read_rgb(node, file, "emission");
    for (int k = 0; k < 3; ++k)
        if (e[k] < 0.0) throw Error(loc_of(node[k], file), "emission must be >= 0, got " + node[k].Scalar());
    return e;
}

// patches: [ns, nt], or n for [n, n].
void read_patches(YamlMap& m, SurfaceDesc& s) {
    const YAML::Node node = m.required("patches");
    if (!(node.IsSequence() && node.size() == 2) &&
        !(node.IsScalar() && !node.Scalar().empty() &&
          node.Scalar().find_first_not_of("+-0123456789") == std::string::npos))
        throw Error(loc_of(node, m.file()),
                    "patches must be a list of 2 integers [ns, nt], or one integer n");
    long long n[2];
    for (int k = 0; k < 2; ++k) {
        const YAML::Node v = node.IsScalar() ? node : node[k];
        n[k] = yaml_integer(v, m.file(),
                            node.IsScalar() ? "patches"
                            : k == 0        ? "patches[0] (ns)"
                                            : "patches[1] (nt)");
        if (n[k] < 1 || n[k] > kMaxPatchesPerAxis)
            throw Error(loc_of(v, m.file()), "patch count must be between 1 and " +
                                                 std::to_string(kMaxPatchesPerAxis) + ", got " + v.Scalar());
    }
    s.ns = static_cast<int>(n[0]);
    s.nt = static_cast<int>(n[1]);
}

void read_patch_emission(YamlMap& m, SurfaceDesc& s) {
    auto list = m.optional("patch_emission");
    if (!list) return;
    if (!list->IsSequence())
        throw Error(loc_of(*list, m.file()),
                    "patch_emission must be a list of {patch: [i, j], emission: [r, g, b]}");
    for (const auto& item : *list) {
        YamlMap pm(item, m.file(), "patch_emission entry");
        PatchEmission pe;
        pe.loc = pm.loc();
        const YAML::Node idx = pm.required("patch");
        if (!idx.IsSequence() || idx.size() != 2)
            throw Error(loc_of(idx, m.file()), "patch must be a list of 2 integers [i, j] (0-based)");
        const long long i = yaml_integer(idx[0], m.file(), "patch[0]");
        const long long j = yaml_integer(idx[1], m.file(), "patch[1]");
        if (i < 0 || i >= s.ns || j < 0 || j >= s.nt)
            throw Error(loc_of(idx, m.file()), "patch [" + std::to_string(i) + ", " + std::to_string(j) +
                                                   "] is outside surface '" + s.name +
                                                   "', which has patches [0.." + std::to_string(s.ns - 1) +
                                                   ", 0.." + std::to_string(s.nt - 1) + "]");
        for (const auto& other : s.patch_emission)
            if (other.is == i && other.it == j)
                throw Error(loc_of(idx, m.file()),
                            "patch [" + std::to_string(i) + ", " + std::to_string(j) + "] is given twice");
        pe.is = static_cast<int>(i);
        pe.it = static_cast<int>(j);
        pe.emission = read_emission(pm.required("emission"), m.file());
        pm.reject_unknown_keys("patch, emission");
        s.patch_emission.push_back(pe);
    }
}

// The keys every surface has; the type's own keys are read by its reader (surfaces/*.cpp). An
// entry may make several surfaces (a type's parts, "<name>.<part>"), and a two-sided surface
// becomes two: the surface as given and its back side, "<name>.back", right after it.
std::vector<SurfaceDesc> read_surface(const YAML::Node& node, const std::string& file, int index) {
    YamlMap m(node, file, "surface #" + std::to_string(index + 1));
    SurfaceDesc s;
    s.loc = m.loc();
    s.name = m.string("name");
    const YAML::Node type = m.required("type");
    const std::string t = yaml_string(type, file, "type");
    s.type = find_surface_type(t);
    if (!s.type)
        throw Error(loc_of(type, file),
                    "unknown surface type '" + t + "' (known: " + surface_type_names() + ", sensor)");
    read_patches(m, s);
    s.reflectance = read_reflectance(m.required("reflectance"), file);
    if (auto e = m.optional("emission")) s.emission = read_emission(*e, file);
    read_patch_emission(m, s);
    std::vector<SurfacePart> parts;
    if (s.type->read_parts)
        parts = s.type->read_parts(m, s.name);
    else
        parts.push_back(SurfacePart{"", s.type->read(m, s.name), std::nullopt, std::nullopt});
    if (parts.size() > 1 && !s.patch_emission.empty())
        throw Error(m.key_loc("patch_emission"),
                    "patch_emission needs a single surface, but '" + s.name + "' makes " +
                        std::to_string(parts.size()) +
                        " (give the emission to the whole entry, or to a material)");
    const bool two_sided = m.boolean_or("two_sided", false);
    Similarity xf;
    const auto transform = m.optional("transform");
    if (transform) xf = read_transform(*transform, file);
    for (const char* key : {"back_reflectance", "back_emission"})
        if (m.has(key) && !two_sided)
            throw Error(m.key_loc(key),
                        std::string(key) + " needs two_sided: true on surface '" + s.name + "'");
    std::optional<Rgb> back_rho, back_e;
    if (auto r = m.optional("back_reflectance")) back_rho = read_reflectance(*r, file);
    if (auto e = m.optional("back_emission")) back_e = read_emission(*e, file);
    m.reject_unknown_keys("name, type, " + s.type->keys +
                          ", patches, reflectance, emission, patch_emission, transform, two_sided, "
                          "back_reflectance, back_emission");
    std::vector<SurfaceDesc> out;
    for (const SurfacePart& part : parts) {
        SurfaceDesc d = s;
        if (!part.suffix.empty()) d.name += "." + part.suffix;
        if (part.reflectance) d.reflectance = *part.reflectance;
        if (part.emission) d.emission = *part.emission;
        d.shape = transform ? std::make_shared<PlacedSurface>(part.shape, xf, false) : part.shape;
        d.unplaced = part.shape;
        d.transform = xf;
        SurfaceDesc back = d;
        out.push_back(std::move(d));
        if (!two_sided) continue;
        back.name += ".back";
        back.emission = back_e.value_or(Rgb(0.0));
        back.patch_emission.clear();
        if (back_rho) back.reflectance = *back_rho;
        back.shape = std::make_shared<PlacedSurface>(part.shape, xf, true);
        back.back = true;
        out.push_back(std::move(back));
    }
    return out;
}

bool is_sensor(const YAML::Node& node) {
    return node.IsMap() && node["type"] && node["type"].IsScalar() && node["type"].Scalar() == "sensor";
}

// {name, type: sensor, position: [x, y, z], normal: [x, y, z] (non-zero, normalised)}.
SensorDesc read_sensor(const YAML::Node& node, const std::string& file, int index) {
    YamlMap m(node, file, "surface #" + std::to_string(index + 1));
    SensorDesc s;
    s.loc = m.loc();
    s.name = m.string("name");
    m.string("type");
    s.position = m.vec3("position");
    const YAML::Node nn = m.required("normal");
    const Vec3 n = yaml_vec3(nn, file, "normal");
    const double len = glm::length(n);
    if (!(len > 0.0) || !std::isfinite(len))
        throw Error(loc_of(nn, file), "normal must be a non-zero vector [x, y, z]");
    s.normal = n / len;
    m.reject_unknown_keys("name, type, position, normal");
    return s;
}

// A form-factor tolerance: a number in [1e-12, 0.1].
double read_tolerance(const YAML::Node& t, const std::string& file, const std::string& key) {
    const double v = yaml_number(t, file, key);
    if (!(v >= kMinFormFactorTolerance && v <= 0.1))
        throw Error(loc_of(t, file), key + " must be in [1e-12, 0.1], got " + t.Scalar());
    return v;
}

FormFactorSettings read_form_factor_settings(const YAML::Node& node, const std::string& file) {
    YamlMap m(node, file, "form_factors");
    FormFactorSettings f;
    std::string method;
    if (auto k = m.optional("method")) {
        method = yaml_string(*k, file, "method");
        if (method != "adaptive" && method != "gauss" && method != "hierarchical")
            throw Error(loc_of(*k, file),
                        "method must be adaptive, gauss or hierarchical, got '" + method + "'");
        f.hierarchical = method == "hierarchical";
        if (method == "gauss") f.gauss_points = 6;
    }
    if (auto p = m.optional("gauss_points")) {
        if (!method.empty() && method != "gauss")
            throw Error(loc_of(*p, file), "gauss_points belongs to method: gauss, not " + method);
        const long long v = yaml_integer(*p, file, "gauss_points");
        if (v < 1 || v > kMaxGaussPoints)
            throw Error(loc_of(*p, file), "gauss_points must be between 1 and " +
                                              std::to_string(kMaxGaussPoints) + ", got " + p->Scalar());
        f.gauss_points = static_cast<int>(v);
    }
    if (auto t = m.optional("tolerance")) {
        if (f.gauss_points && method == "gauss")
            throw Error(loc_of(*t, file), "form_factors: method gauss takes gauss_points, not tolerance");
        if (f.gauss_points)
            throw Error(loc_of(*t, file),
                        "form_factors: give tolerance (error-controlled) or gauss_points (the paper's "
                        "fixed rule), not both");
        f.tolerance = read_tolerance(*t, file, "tolerance");
    }
    if (auto t = m.optional("receiver_tolerance")) {
        if (!f.hierarchical)
            throw Error(loc_of(*t, file),
                        "receiver_tolerance belongs to method: hierarchical; add method: "
                        "hierarchical or remove it");
        // 0: off (by default it is on in scenes of up to 10,000 patches: docs/scale.md).
        const double v = yaml_number(*t, file, "receiver_tolerance");
        if (!valid_receiver_tolerance(v))
            throw Error(loc_of(*t, file),
                        "receiver_tolerance must be 0 (off) or in [1e-12, 0.1], got " + t->Scalar());
        f.receiver_tolerance = v;
        if (f.tolerance && *f.receiver_tolerance > *f.tolerance)
            throw Error(loc_of(*t, file), "receiver_tolerance must not exceed tolerance (" +
                                              m.optional("tolerance")->Scalar() + "), got " + t->Scalar());
    }
    if (auto k = m.optional("numeric_inner")) {
        const std::string v = yaml_string(*k, file, "numeric_inner");
        if (v != "rules" && v != "lines")
            throw Error(loc_of(*k, file), "numeric_inner must be rules or lines, got '" + v + "'");
        if (!method.empty() && method != "adaptive")
            throw Error(loc_of(*k, file), "numeric_inner belongs to method: adaptive, not " + method);
        if (f.gauss_points)
            throw Error(loc_of(*k, file), "numeric_inner belongs to method: adaptive, not to gauss_points");
        f.numeric_lines = v == "lines";
    }
    f.visibility = m.boolean_or("visibility", true);
    m.reject_unknown_keys("method, tolerance | gauss_points, receiver_tolerance, numeric_inner, visibility");
    return f;
}

SolveSettings read_solve_settings(const YAML::Node& node, const std::string& file) {
    YamlMap m(node, file, "solve");
    SolveSettings s;
    if (auto t = m.optional("tolerance")) {
        s.tolerance = yaml_number(*t, file, "tolerance");
        if (!(*s.tolerance >= kMinFormFactorTolerance && *s.tolerance <= 0.1))
            throw Error(loc_of(*t, file),
                        "solve tolerance must be in [1e-12, 0.1] (relative to the largest "
                        "radiosity of each channel), got " +
                            t->Scalar());
    }
    m.reject_unknown_keys("tolerance");
    return s;
}

}  // namespace

Scene parse_scene(const std::string& yaml_text, const std::string& filename) {
    const YAML::Node root = load_yaml_string(yaml_text, filename);
    YamlMap m(root, filename, "scene");
    Scene scene;
    scene.file = filename;
    scene.name = m.has("name") ? m.string("name") : std::filesystem::path(filename).stem().string();
    scene.closed = m.boolean_or("closed", true);
    if (auto ff = m.optional("form_factors")) scene.form_factors = read_form_factor_settings(*ff, filename);
    if (auto sv = m.optional("solve")) {
        scene.solve = read_solve_settings(*sv, filename);
        scene.solve_loc = loc_of(*sv, filename);
        if (scene.solve.tolerance && scene.form_factors.gauss_points)
            throw Error(scene.solve_loc,
                        "solve: a tolerance needs error-controlled form factors (their estimates "
                        "bound the error); remove form_factors: gauss_points");
    }
    const YAML::Node list = m.required("surfaces");
    m.reject_unknown_keys("name, closed, form_factors, solve, surfaces");
    if (!list.IsSequence() || list.size() == 0)
        throw Error(loc_of(list, filename), "surfaces must be a non-empty list of surfaces");
    long long total = 0;
    auto taken = [&](const std::string& name) {
        if (scene.find_surface(name) >= 0) return true;
        for (const SensorDesc& d : scene.sensors)
            if (d.name == name) return true;
        return false;
    };
    for (size_t i = 0; i < list.size(); ++i) {
        if (is_sensor(list[i])) {
            SensorDesc d = read_sensor(list[i], filename, static_cast<int>(i));
            if (taken(d.name))
                throw Error(d.loc, "surface name '" + d.name + "' is used twice; names must be unique");
            scene.sensors.push_back(std::move(d));
            continue;
        }
        for (SurfaceDesc& s : read_surface(list[i], filename, static_cast<int>(i))) {
            if (taken(s.name))
                throw Error(s.loc, "surface name '" + s.name + "' is used twice; names must be unique" +
                                       (s.name.ends_with(".back") ? " (a two-sided surface's back side is "
                                                                    "named <name>.back)"
                                                                  : ""));
            total += static_cast<long long>(s.ns) * s.nt;
            if (total > kMaxPatches)
                throw Error(s.loc, "the scene has more than " + std::to_string(kMaxPatches) +
                                       " patches (use fewer patches)");
            s.entry = static_cast<int>(i);
            if (!scene.surfaces.empty() && scene.surfaces.back().entry == s.entry &&
                scene.surfaces.back().name + ".back" == s.name) {
                s.twin = static_cast<int>(scene.surfaces.size()) - 1;
                scene.surfaces.back().twin = static_cast<int>(scene.surfaces.size());
            }
            scene.surfaces.push_back(std::move(s));
        }
    }
    if (scene.surfaces.empty())
        throw Error(loc_of(list, filename), "surfaces must hold at least one surface besides sensors");
    return scene;
}

Scene load_scene(const std::string& path) { return parse_scene(read_input_file(path), path); }

}  // namespace radiosa
