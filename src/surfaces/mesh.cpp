// The `mesh` surface type: the faces of an OBJ file (read by tinyobjloader), each a flat surface of
// its own: triangles (triangle.cpp) and convex quads (quad.cpp); a convex face of more corners is
// cut into a fan of quads (and a last triangle) from its first corner. Faces must be planar and
// convex; the front side is the one the OBJ winding (counter-clockwise) faces.
#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "surfaces/quad.h"
#include "surfaces/registry.h"

namespace radiosa {

namespace {

// The 1-based line numbers of the file's face ("f") and vertex ("v") lines, in order: for messages.
struct ObjLines {
    std::vector<int> faces, vertices;
};

ObjLines obj_lines(const std::string& text) {
    ObjLines out;
    int no = 1;
    for (std::size_t at = 0; at < text.size(); ++no) {
        std::size_t end = text.find('\n', at);
        if (end == std::string::npos) end = text.size();
        std::size_t k = text.find_first_not_of(" \t", at);
        if (k < end && k + 1 < text.size() && (text[k + 1] == ' ' || text[k + 1] == '\t')) {
            if (text[k] == 'f') out.faces.push_back(no);
            if (text[k] == 'v') out.vertices.push_back(no);
        }
        at = end + 1;
    }
    return out;
}

// Checks one face (planar, strictly convex, finite) and adds its parts.
void add_face(const std::vector<Vec3>& v, const std::string& path, int line, int face,
              const std::string& name, std::optional<Rgb> rho, std::optional<Rgb> e,
              std::vector<SurfacePart>* parts) {
    const FileLoc where{path, line, 1};
    const std::string which = "mesh '" + name + "': face " + std::to_string(face);
    const int n = static_cast<int>(v.size());
    if (n < 3) throw Error(where, which + " has " + std::to_string(n) + " corners; a face needs at least 3");
    double size = 0.0;
    Vec3 newell(0.0), mid(0.0);
    for (int k = 0; k < n; ++k) {
        if (!std::isfinite(v[k].x) || !std::isfinite(v[k].y) || !std::isfinite(v[k].z))
            throw Error(where, which + " has a corner that is not a finite point");
        size = std::max(size, glm::length(v[(k + 1) % n] - v[k]));
        newell += glm::cross(v[k], v[(k + 1) % n]);
        mid += v[k] / double(n);
    }
    const double nlen = glm::length(newell);
    if (!(nlen > 1e-12 * size * size))
        throw Error(where, which + " is degenerate: its corners are collinear or coincide (remove it)");
    const Vec3 u = newell / nlen;
    for (int k = 0; k < n; ++k) {
        if (std::abs(glm::dot(v[k] - mid, u)) > 1e-6 * size)
            throw Error(where, which + " is not planar: corner " + std::to_string(k + 1) +
                                   " is off the plane of the others (triangulate it in the modeller)");
        const Vec3 a = v[(k + 1) % n] - v[k], b = v[(k + n - 1) % n] - v[k];
        if (glm::dot(glm::cross(a, b), u) <= 1e-9 * size * size)
            throw Error(where, which + " is not convex at corner " + std::to_string(k + 1) +
                                   " (or two corners coincide there); split it into convex faces");
    }
    const std::string base = std::to_string(face);
    if (n == 3) parts->push_back({base, make_triangle(v[0], v[1], v[2]), rho, e});
    if (n == 4) parts->push_back({base, std::make_shared<QuadSurface>(v[0], v[1], v[2], v[3]), rho, e});
    if (n <= 4) return;
    int piece = 0;
    for (int k = 1; k + 1 < n; k += 2, ++piece) {
        const std::string suffix = base + "." + std::to_string(piece);
        if (k + 2 < n)
            parts->push_back({suffix, std::make_shared<QuadSurface>(v[0], v[k], v[k + 1], v[k + 2]), rho, e});
        else
            parts->push_back({suffix, make_triangle(v[0], v[k], v[k + 1]), rho, e});
    }
}

std::optional<Rgb> material_colour(const tinyobj::real_t c[3], const std::string& what,
                                   const std::string& material, double max, const FileLoc& where) {
    Rgb v(c[0], c[1], c[2]);
    for (int k = 0; k < 3; ++k)
        if (!(v[k] >= 0.0 && v[k] <= max))
            throw Error(where, "material '" + material + "': " + what + " must be in [0, " +
                                   (max > 1.0 ? std::string("inf)") : std::string("1]")) + ", got " +
                                   fmt::format("{}", v[k]));
    return v;
}

// file: an OBJ file, relative to the scene file; materials: none (default) | mtl (each face's
// reflectance and emission from its material's Kd and Ke).
std::vector<SurfacePart> read_mesh(YamlMap& m, const std::string& name) {
    const YAML::Node f = m.required("file");
    const FileLoc where = loc_of(f, m.file());
    const std::string rel = yaml_string(f, m.file(), "file");
    const std::filesystem::path path = std::filesystem::path(m.file()).parent_path() / rel;
    bool use_mtl = false;
    if (auto mat = m.optional("materials")) {
        const std::string v = yaml_string(*mat, m.file(), "materials");
        if (v != "none" && v != "mtl")
            throw Error(loc_of(*mat, m.file()), "materials must be 'none' or 'mtl', got '" + v + "'");
        use_mtl = v == "mtl";
    }
    std::string text;
    try {
        text = read_input_file(path.string());
    } catch (const Error& e) {
        if (e.loc()) throw;
        throw Error(where, e.message() + " (file is relative to the scene file's folder)");
    }
    // tinyobjloader parses the text already read (one read of the file), and finds the .mtl files
    // beside it.
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    std::istringstream in(text);
    tinyobj::MaterialFileReader mtl_reader(path.parent_path().string() + "/");
    if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &mtl_reader, false, false) ||
        !err.empty())
        throw Error(FileLoc{path.string(), 0, 0}, "cannot read the OBJ file: " + err);
    if (use_mtl && materials.empty())
        throw Error(where, "materials: mtl, but '" + rel + "' names no material file that could be read (" +
                               warn + ")");
    const ObjLines lines = obj_lines(text);
    const auto& xyz = attrib.vertices;
    std::vector<SurfacePart> parts;
    int face = 0;
    for (const tinyobj::shape_t& shape : shapes) {
        std::size_t at = 0;
        for (std::size_t k = 0; k < shape.mesh.num_face_vertices.size(); ++k, ++face) {
            const int line = face < static_cast<int>(lines.faces.size()) ? lines.faces[face] : 0;
            std::vector<Vec3> v;
            for (unsigned c = 0; c < shape.mesh.num_face_vertices[k]; ++c) {
                const int i = shape.mesh.indices[at++].vertex_index;
                if (i < 0 || 3 * static_cast<std::size_t>(i) + 2 >= xyz.size())
                    throw Error(FileLoc{path.string(), line, 1},
                                "face " + std::to_string(face) + " names a vertex the file does not have");
                v.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
            }
            std::optional<Rgb> rho, e;
            const int mat = k < shape.mesh.material_ids.size() ? shape.mesh.material_ids[k] : -1;
            if (use_mtl && mat >= 0 && mat < static_cast<int>(materials.size())) {
                const tinyobj::material_t& mt = materials[mat];
                rho = material_colour(mt.diffuse, "Kd (reflectance)", mt.name, 1.0, where);
                e = material_colour(mt.emission, "Ke (emission)", mt.name, 1e300, where);
            }
            add_face(v, path.string(), line, face, name, rho, e, &parts);
        }
    }
    if (parts.empty()) throw Error(where, "mesh '" + name + "': '" + rel + "' has no faces");
    return parts;
}

}  // namespace

extern const SurfaceType kMeshType;
const SurfaceType kMeshType = {
    .name = "mesh",
    .key_id = 8,
    .keys = "file, materials",
    .read = nullptr,
    .example = {{"file", "box.obj"}},
    .variants = {{"file", "box_moved.obj"}, {"file", "box_turned.obj"}},
    .read_parts = read_mesh,
    .example_files = {{"box.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 2 3 4\nf 1 2 5\n"},
                      {"box_moved.obj",
                       "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1.5\nf 1 2 3 4\nf 1 2 5\n"},
                      {"box_turned.obj",
                       "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 4 3 2 1\nf 1 2 5\n"}},
};

}  // namespace radiosa
