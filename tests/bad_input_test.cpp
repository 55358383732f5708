// Every kind of bad scene file named in docs/stability.md's table: exit code 1, one line on stderr
// with the file, line, column and the fix, and nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "cli_run.h"

namespace radiosa {

namespace fs = std::filesystem;

// One valid quad, for cases that add a key or a block around it.
const std::string kQuad =
    "surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\n"
    "    patches: [1, 1]\n    reflectance: [0, 0, 0]\n";

TEST(BadInput, EachCaseHasOneClearMessageAndWritesNothing) {
    struct Case {
        const char* what;
        std::string text;
        std::string message;  // '@' stands for the file's path
    };
    const std::vector<Case> cases = {
        {"empty file", std::string("", 0), "@:1:1: file is empty; expected a YAML mapping"},
        {"malformed YAML", std::string("surfaces: [\n", 12),
         "@:2:1: malformed YAML: end of sequence flow not found"},
        {"binary file", std::string("\0\1\2binary", 9), "@: file is binary, not YAML text"},
        {"missing surfaces", std::string("name: x\n", 8),
         "@:1:1: scene is missing the required key 'surfaces'"},
        {"missing reflectance",
         std::string("surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], "
                     "[0, 1, 0]]\n    patches: [1, 1]\n",
                     115),
         "@:2:5: surface #1 is missing the required key 'reflectance'"},
        {"unknown key (typo)",
         std::string(
             "surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, "
             "0]]\n    patches: [1, 1]\n    reflectance: [0.5, 0.5, 0.5]\n    emision: [1, 1, 1]\n",
             171),
         "@:7:5: unknown key 'emision' in surface #1 (allowed: name, type, corners | origin + edge_s + "
         "edge_t, patches, reflectance, emission, patch_emission, transform, two_sided, "
         "back_reflectance, back_emission)"},
        {"gauss_points out of range", std::string("form_factors:\n  gauss_points: 65\n") + kQuad,
         "@:2:17: gauss_points must be between 1 and 64, got 65"},
        {"gauss_points zero", std::string("form_factors:\n  gauss_points: 0\n") + kQuad,
         "@:2:17: gauss_points must be between 1 and 64, got 0"},
        {"tolerance too large", std::string("form_factors:\n  tolerance: 0.5\n") + kQuad,
         "@:2:14: tolerance must be in [1e-12, 0.1], got 0.5"},
        {"tolerance too small", std::string("form_factors:\n  tolerance: 1e-13\n") + kQuad,
         "@:2:14: tolerance must be in [1e-12, 0.1], got 1e-13"},
        {"solve tolerance out of range", std::string("solve:\n  tolerance: 0.5\n") + kQuad,
         "@:2:14: solve tolerance must be in [1e-12, 0.1] (relative to the largest radiosity of each "
         "channel), "
         "got 0.5"},
        {"solve tolerance with the fixed rule",
         std::string("form_factors:\n  gauss_points: 6\nsolve:\n  tolerance: 1e-6\n") + kQuad,
         "@:4:3: solve: a tolerance needs error-controlled form factors (their estimates bound the error); "
         "remove form_factors: gauss_points"},
        {"facing",
         std::string("surfaces:\n  - name: s\n    type: sphere\n    center: [0, 0, 0]\n    radius: 1\n"
                     "    facing: sideways\n    patches: [8, 4]\n    reflectance: [0, 0, 0]\n"),
         "@:6:13: facing must be 'outward' or 'inward', got 'sideways'"},
        {"three corners",
         std::string(
             "surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0]]\n"
             "    patches: [1, 1]\n    reflectance: [0, 0, 0]\n"),
         "@:4:14: corners must be a list of 4 points [[x,y,z], ...]"},
        {"patch_emission not a list", kQuad + "    patch_emission: 7\n",
         "@:7:21: patch_emission must be a list of {patch: [i, j], emission: [r, g, b]}"},
        {"patch_emission entry malformed",
         kQuad + "    patch_emission:\n      - {patch: [0], emission: [1, 1, 1]}\n",
         "@:8:17: patch must be a list of 2 integers [i, j] (0-based)"},
        {"unknown surface type",
         std::string(
             "surfaces:\n  - name: a\n    type: klein\n    patches: [1, 1]\n    reflectance: [0, 0, 0]\n"),
         "@:3:11: unknown surface type 'klein' (known: quad, sphere, disk, cylinder, cone, torus, bezier, "
         "triangle, mesh, sensor)"},
        {"wrong type",
         std::string("surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], "
                     "[0, 1, 0]]\n    patches: many\n    reflectance: [0.5, 0.5, 0.5]\n",
                     146),
         "@:5:14: patches must be a list of 2 integers [ns, nt], or one integer n"},
        {"NaN",
         std::string("surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], "
                     "[0, 1, 0]]\n    patches: [1, 1]\n    reflectance: [.nan, 0.5, 0.5]\n",
                     149),
         "@:6:19: reflectance[0] must be a finite number, got '.nan'"},
        {"infinity",
         std::string("surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, .inf, "
                     "0], [0, 1, 0]]\n    patches: [1, 1]\n    reflectance: [0.5, 0.5, 0.5]\n",
                     151),
         "@:4:41: corners[2][1] must be a finite number, got '.inf'"},
        {"negative radius",
         std::string("surfaces:\n  - name: s\n    type: sphere\n    center: [0, 0, 0]\n    radius: -2\n    "
                     "patches: [8, 4]\n    reflectance: [0, 0, 0]\n",
                     123),
         "@:5:13: radius must be > 0, got -2"},
        {"zero-size quad",
         std::string("surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [0, 0, 0], [0, 0, 0], "
                     "[0, 0, 0]]\n    patches: [1, 1]\n    reflectance: [0.5, 0.5, 0.5]\n",
                     148),
         "@:2:5: quad 'a' is degenerate: all corners coincide"},
        {"reflectance > 1",
         std::string("surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], "
                     "[0, 1, 0]]\n    patches: [1, 1]\n    reflectance: [0.5, 1.5, 0.5]\n",
                     148),
         "@:6:24: reflectance must be in [0, 1] (a surface cannot reflect more than it receives), got 1.5"},
        {"negative emission",
         std::string(
             "surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, "
             "0]]\n    patches: [1, 1]\n    reflectance: [0.5, 0.5, 0.5]\n    emission: [1, -1, 1]\n",
             173),
         "@:7:19: emission must be >= 0, got -1"},
        {"zero patches",
         std::string("surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], "
                     "[0, 1, 0]]\n    patches: [0, 1]\n    reflectance: [0.5, 0.5, 0.5]\n",
                     148),
         "@:5:15: patch count must be between 1 and 4096, got 0"},
        {"absurd patch count",
         std::string("surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], "
                     "[0, 1, 0]]\n    patches: [4000, 4000]\n    reflectance: [0.5, 0.5, 0.5]\n",
                     154),
         "@:2:5: the scene has more than 1000000 patches (use fewer patches)"},
        {"too many patches for the dense matrix",
         "surfaces:\n  - {name: a, type: quad, corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], "
         "patches: [100, 101],\n     reflectance: [0.5, 0.5, 0.5]}\n"
         "  - {name: b, type: quad, corners: [[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]], patches: [100, "
         "101],\n"
         "     reflectance: [0.5, 0.5, 0.5]}\n",
         "@: the scene has 20200 patches; the dense form-factor matrix stops at 20000 (3 GB here): use "
         "form_factors: {method: hierarchical} or --ff-method hierarchical"},
        {"duplicate surface name",
         std::string("surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], "
                     "[0, 1, 0]]\n    patches: [1, 1]\n    reflectance: [0.5, 0.5, 0.5]\n  - name: a\n    "
                     "type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\n    patches: "
                     "[1, 1]\n    reflectance: [0.5, 0.5, 0.5]\n",
                     286),
         "@:7:5: surface name 'a' is used twice; names must be unique"},
        {"unknown patch in patch_emission",
         std::string("surfaces:\n  - name: a\n    type: quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], "
                     "[0, 1, 0]]\n    patches: [1, 1]\n    reflectance: [0.5, 0.5, 0.5]\n    "
                     "patch_emission:\n      - patch: [3, 0]\n        emission: [1, 1, 1]\n",
                     218),
         "@:8:16: patch [3, 0] is outside surface 'a', which has patches [0..0, 0..0]"},
        {"gauss_points and tolerance",
         std::string("form_factors:\n  gauss_points: 6\n  tolerance: 1e-6\nsurfaces:\n  - name: a\n    type: "
                     "quad\n    corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\n    patches: [1, 1]\n "
                     "   reflectance: [0.5, 0.5, 0.5]\n",
                     198),
         "@:3:14: form_factors: give tolerance (error-controlled) or gauss_points (the paper's fixed rule), "
         "not both"},
    };
    const fs::path d = test::fresh_dir("radiosa_bad_input");
    const std::string file = (d / "case.yaml").string(), out = (d / "x.png").string();
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        std::ofstream(file, std::ios::binary | std::ios::trunc) << c.text;
        const test::CliRun r =
            test::run({"render", file, "-c", RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml", "-o", out,
                       "--no-cache", "--width", "8", "--height", "8"});
        std::string expected = "error: " + c.message + "\n";
        expected.replace(expected.find('@'), 1, file);
        EXPECT_EQ(r.code, 1);
        EXPECT_EQ(r.err, expected);
        EXPECT_FALSE(fs::exists(out));
    }
    // A 100 MB file is refused by its size, before it is read.
    {
        std::ofstream big(file, std::ios::binary | std::ios::trunc);
        const std::string block(1 << 20, '#');
        for (int k = 0; k < 100; ++k) big << block;
    }
    const test::CliRun r =
        test::run({"render", file, "-c", RADIOSA_SOURCE_DIR "/cameras/baranoski1991-a.yaml", "-o", out});
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.err, "error: " + file + ": file is 100 MiB; input files are limited to 16 MiB\n");
    fs::remove_all(d);
}

}  // namespace radiosa
