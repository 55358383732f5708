// Reads and validates scene files. The format is documented in README.md ("Scene files").
#include <cmath>
#include <filesystem>

#include "scene/scene.h"
#include "scene/yaml_reader.h"

namespace radiosa {

int Scene::patch_count() const {
    int n = 0;
    for (const auto& s : surfaces) n += s.ns * s.nt;
    return n;
}

int Scene::find_surface(const std::string& name) const {
    for (size_t i = 0; i < surfaces.size(); ++i)
        if (surfaces[i].name == name) return static_cast<int>(i);
    return -1;
}

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
                        "receives), got " + node[k].Scalar());
    return rho;
}

Rgb read_emission(const YAML::Node& node, const std::string& file) {
    Rgb e = read_rgb(node, file, "emission");
    for (int k = 0; k < 3; ++k)
        if (e[k] < 0.0)
            throw Error(loc_of(node[k], file), "emission must be >= 0, got " + node[k].Scalar());
    return e;
}

void read_patches(YamlMap& m, SurfaceDesc& s) {
    const YAML::Node node = m.required("patches");
    if (!node.IsSequence() || node.size() != 2)
        throw Error(loc_of(node, m.file()), "patches must be a list of 2 integers [ns, nt]");
    long long n[2];
    for (int k = 0; k < 2; ++k) {
        n[k] = yaml_integer(node[k], m.file(), k == 0 ? "patches[0] (ns)" : "patches[1] (nt)");
        if (n[k] < 1 || n[k] > kMaxPatchesPerAxis)
            throw Error(loc_of(node[k], m.file()),
                        "patch count must be between 1 and " + std::to_string(kMaxPatchesPerAxis) +
                            ", got " + node[k].Scalar());
    }
    s.ns = static_cast<int>(n[0]);
    s.nt = static_cast<int>(n[1]);
}

void read_patch_emission(YamlMap& m, SurfaceDesc& s) {
    auto list = m.optional("patch_emission");
    if (!list) return;
    if (!list->IsSequence())
        throw Error(loc_of(*list, m.file()), "patch_emission must be a list of {patch: [i, j], emission: [r, g, b]}");
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
            throw Error(loc_of(idx, m.file()),
                        "patch [" + std::to_string(i) + ", " + std::to_string(j) + "] is outside surface '" +
                            s.name + "', which has patches [0.." + std::to_string(s.ns - 1) + ", 0.." +
                            std::to_string(s.nt - 1) + "]");
        for (const auto& other : s.patch_emission)
            if (other.is == i && other.it == j)
                throw Error(loc_of(idx, m.file()), "patch [" + std::to_string(i) + ", " +
                                                       std::to_string(j) + "] is given twice");
        pe.is = static_cast<int>(i);
        pe.it = static_cast<int>(j);
        pe.emission = read_emission(pm.required("emission"), m.file());
        pm.reject_unknown_keys("patch, emission");
        s.patch_emission.push_back(pe);
    }
}

// A quad must be planar and strictly convex, or its bilinear map folds over itself.
void validate_quad(const SurfaceDesc& s, const FileLoc& where) {
    const auto& c = s.corners;
    double size = 0.0;
    for (int k = 0; k < 4; ++k) size = std::max(size, glm::length(c[(k + 1) % 4] - c[k]));
    if (!(size > 0.0)) throw Error(where, "quad '" + s.name + "' is degenerate: all corners coincide");
    // The plane normal from the corner with the strongest turn: the diagonals' cross product
    // would vanish for a crossed (bow-tie) quad and misreport it as collinear.
    Vec3 n(0.0);
    for (int k = 0; k < 4; ++k) {
        const Vec3 nk = glm::cross(c[(k + 1) % 4] - c[k], c[(k + 3) % 4] - c[k]);
        if (glm::length(nk) > glm::length(n)) n = nk;
    }
    const double nlen = glm::length(n);
    if (nlen <= 1e-12 * size * size)
        throw Error(where, "quad '" + s.name + "' is degenerate: its corners are collinear");
    const Vec3 u = n / nlen;
    const Vec3 mid = 0.25 * (c[0] + c[1] + c[2] + c[3]);
    for (int k = 0; k < 4; ++k)
        if (std::abs(glm::dot(c[k] - mid, u)) > 1e-9 * size)
            throw Error(where, "quad '" + s.name + "' is not planar: corner " + std::to_string(k) +
                                   " is off the plane of the others (split it into planar quads)");
    for (int k = 0; k < 4; ++k) {
        const Vec3 a = c[(k + 1) % 4] - c[k];
        const Vec3 b = c[(k + 3) % 4] - c[k];
        if (glm::dot(glm::cross(a, b), u) <= 1e-9 * size * size)
            throw Error(where, "quad '" + s.name + "' is degenerate or not convex at corner " +
                                   std::to_string(k) + " (list the corners in order around the quad)");
    }
}

void read_quad(YamlMap& m, SurfaceDesc& s) {
    if (m.has("corners")) {
        if (m.has("origin") || m.has("edge_s") || m.has("edge_t"))
            throw Error(m.key_loc("corners"), "quad '" + s.name + "': give either corners or origin + edge_s + edge_t, not both");
        const YAML::Node list = m.required("corners");
        if (!list.IsSequence() || list.size() != 4)
            throw Error(loc_of(list, m.file()), "corners must be a list of 4 points [[x,y,z], ...]");
        for (int k = 0; k < 4; ++k)
            s.corners[k] = yaml_vec3(list[k], m.file(), "corners[" + std::to_string(k) + "]");
    } else if (m.has("origin") || m.has("edge_s") || m.has("edge_t")) {
        const Vec3 o = m.vec3("origin");
        const Vec3 es = m.vec3("edge_s");
        const Vec3 et = m.vec3("edge_t");
        s.corners = {o, o + es, o + es + et, o + et};
    } else {
        throw Error(m.loc(), "quad '" + s.name + "' needs corners, or origin + edge_s + edge_t");
    }
    validate_quad(s, m.loc());
}

void read_sphere(YamlMap& m, SurfaceDesc& s) {
    s.center = m.vec3("center");
    const YAML::Node r = m.required("radius");
    s.radius = yaml_number(r, m.file(), "radius");
    if (!(s.radius > 0.0))
        throw Error(loc_of(r, m.file()), "radius must be > 0, got " + r.Scalar());
    if (auto facing = m.optional("facing")) {
        const std::string f = yaml_string(*facing, m.file(), "facing");
        if (f == "outward") s.inward = false;
        else if (f == "inward") s.inward = true;
        else throw Error(loc_of(*facing, m.file()), "facing must be 'outward' or 'inward', got '" + f + "'");
    }
}

SurfaceDesc read_surface(const YAML::Node& node, const std::string& file, int index) {
    YamlMap m(node, file, "surface #" + std::to_string(index + 1));
    SurfaceDesc s;
    s.loc = m.loc();
    s.name = m.string("name");
    const YAML::Node type = m.required("type");
    const std::string t = yaml_string(type, file, "type");
    read_patches(m, s);
    s.reflectance = read_reflectance(m.required("reflectance"), file);
    if (auto e = m.optional("emission")) s.emission = read_emission(*e, file);
    read_patch_emission(m, s);
    if (t == "quad") {
        s.type = SurfaceType::Quad;
        read_quad(m, s);
        m.reject_unknown_keys("name, type, corners | origin + edge_s + edge_t, patches, reflectance, emission, patch_emission");
    } else if (t == "sphere") {
        s.type = SurfaceType::Sphere;
        read_sphere(m, s);
        m.reject_unknown_keys("name, type, center, radius, facing, patches, reflectance, emission, patch_emission");
    } else {
        throw Error(loc_of(type, file), "unknown surface type '" + t + "' (known: quad, sphere)");
    }
    return s;
}

FormFactorSettings read_form_factor_settings(const YAML::Node& node, const std::string& file) {
    YamlMap m(node, file, "form_factors");
    FormFactorSettings f;
    if (auto p = m.optional("gauss_points")) {
        const long long v = yaml_integer(*p, file, "gauss_points");
        if (v < 1 || v > kMaxGaussPoints)
            throw Error(loc_of(*p, file), "gauss_points must be between 1 and " +
                                              std::to_string(kMaxGaussPoints) + ", got " + p->Scalar());
        f.gauss_points = static_cast<int>(v);
    }
    if (auto t = m.optional("tolerance")) {
        if (f.gauss_points > 0)
            throw Error(loc_of(*t, file), "form_factors: give tolerance (error-controlled) or gauss_points (the paper's "
                                          "fixed rule), not both");
        f.tolerance = yaml_number(*t, file, "tolerance");
        if (!(f.tolerance >= kMinFormFactorTolerance && f.tolerance <= 0.1))
            throw Error(loc_of(*t, file), "tolerance must be in [1e-12, 0.1], got " + t->Scalar());
    }
    f.visibility = m.boolean_or("visibility", true);
    m.reject_unknown_keys("tolerance | gauss_points, visibility");
    return f;
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
    const YAML::Node list = m.required("surfaces");
    m.reject_unknown_keys("name, closed, form_factors, surfaces");
    if (!list.IsSequence() || list.size() == 0)
        throw Error(loc_of(list, filename), "surfaces must be a non-empty list of surfaces");
    long long total = 0;
    for (size_t i = 0; i < list.size(); ++i) {
        SurfaceDesc s = read_surface(list[i], filename, static_cast<int>(i));
        if (scene.find_surface(s.name) >= 0)
            throw Error(s.loc, "surface name '" + s.name + "' is used twice; names must be unique");
        total += static_cast<long long>(s.ns) * s.nt;
        if (total > kMaxPatches)
            throw Error(s.loc, "the scene has more than " + std::to_string(kMaxPatches) +
                                   " patches; the dense form-factor matrix would need " +
                                   std::to_string(total * total * 8 / 1000000000) +
                                   " GB or more (use fewer patches)");
        scene.surfaces.push_back(std::move(s));
    }
    return scene;
}

Scene load_scene(const std::string& path) {
    return parse_scene(read_input_file(path), path);
}

}  // namespace radiosa
