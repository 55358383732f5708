#pragma once
// The on-disk form-factor matrix: its key, its file format, the checks every load makes, and
// the compute-or-load policy (docs/cache.md).
//
// A cache file is named <key>.rff, where the key is a 128-bit XXH3 hash of the canonical bytes
// of exactly what determines the matrix (see form_factor_key). Layout, all little-endian:
//
//   header   magic "RADFF\r\n\x1a", u32 format version, u32 algorithm version, 16-byte key,
//            str scene name (u32 length <= 4096 + UTF-8), u64 patch count, u64 surface count,
//            u32 element type (1 = float64), u32 matrix layout (0 dense, 1 CSR),
//            u32 compression (0 none, 1 zstd), u32 flags (bit 0: error estimates present,
//            bit 1: visibility tested, bit 2: the scene is closed), u32 method (0 fixed Gauss
//            rule, 1 adaptive), u32 gauss points, f64 tolerance,
//            u64 stored size of the matrix section, u64 its uncompressed size
//   table    per surface: str name, u32 ns, u32 nt
//            per patch:   u32 surface, u32 is, u32 it, f64 area
//            the FormFactorStats counters as i64, in for_each_counter order
//            (no timings: equal inputs give byte-identical files)
//   matrix   dense: N*N f64 row-major; CSR: (N+1) u64 row starts, nnz u32 columns, nnz f64 values;
//            then, when flagged, N*N f64 error estimates; zstd-compressed as a whole when flagged
//   trailer  u64 XXH3-64 checksum of every preceding byte
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <span>
#include <stdexcept>
#include <string>

#include "formfactor/form_factor.h"
#include "util/warnings.h"

namespace radiosa {

struct Scene;
class SceneGeometry;

inline constexpr std::uint32_t kCacheFormatVersion = 5;

struct CacheKey {
    std::array<std::uint8_t, 16> bytes{};
    std::string hex() const;
    bool operator==(const CacheKey&) const = default;
};

// Hash of each surface's type and key bytes (in scene order) and subdivision, the form-factor
// method and its settings, visibility, the element precision and kFormFactorAlgorithmVersion.
// Names, reflectance, emission, camera, image and thread settings are deliberately left out.
CacheKey form_factor_key(const Scene& scene, const FormFactorOptions& options);

// What a cache file says about itself in its header.
struct CacheFileInfo {
    std::uint32_t format_version = 0;
    std::uint32_t algorithm_version = 0;
    CacheKey key;
    std::string scene_name;
    std::uint64_t patches = 0;
    std::uint64_t surfaces = 0;
    std::string layout;       // "dense" or "csr"; "links" for hierarchical links (link_file.h)
    std::string compression;  // "none" or "zstd"
    bool has_error_estimates = false;
    FormFactorOptions options;  // method, tolerance or gauss points, visibility
    bool closed = false;
    std::uint64_t nodes = 0, links = 0;  // hierarchical links only
};

// A cache file that cannot be used; what() is the reason, one line.
struct CacheFileError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// What a file must be to serve a scene and a request: its key, patch table, method, settings
// and closedness; the scene fixes the largest matrix a load may allocate.
struct CacheExpectation {
    CacheKey key;
    const SceneGeometry* geometry = nullptr;
    FormFactorOptions options;
    bool closed = false;
};

// Writes atomically (exclusive temporary, then rename). Throws Error when it cannot be written.
// Chooses the smaller of the dense and CSR layouts, and compresses with zstd when that saves at
// least a quarter of the bytes.
void write_cache_file(const std::filesystem::path& path, const CacheKey& key, const std::string& scene_name,
                      bool closed, const SceneGeometry& geometry, const FormFactors& ff);

// Header only (`cache list`). Throws CacheFileError.
CacheFileInfo read_cache_info(const std::filesystem::path& path);

// Reads and checks a file for this scene and request: a regular file only (never a FIFO, device,
// directory or link), the header before anything else, every size against the file's and the
// scene's before allocating, the checksum, the key, the patch table, then the sense checks of
// check_cache_matrix. Throws CacheFileError.
FormFactors read_cache_file(const std::filesystem::path& path, const CacheExpectation& expect,
                            CacheFileInfo* info = nullptr);
FormFactors read_cache_bytes(std::span<const std::uint8_t> bytes, const CacheExpectation& expect,
                             CacheFileInfo* info = nullptr);

// `cache verify`: every check that needs no scene (all but the patch table against a scene and
// reciprocity), streaming the file in bounded memory whatever it claims. Throws CacheFileError.
CacheFileInfo verify_cache_file(const std::filesystem::path& path);
CacheFileInfo verify_cache_bytes(std::span<const std::uint8_t> bytes);

// The sense checks a loaded matrix must pass (docs/cache.md, "Checks on every load"); throws
// CacheFileError naming the first that fails. Also run on every freshly computed matrix before
// it is stored, so that a file this build wrote always loads.
void check_cache_matrix(const FormFactors& ff, const FormFactorOptions& options, bool closed);

// ---- the policy: where the cache lives and how a run uses it ----

// How a run computes a matrix it does not find: in this process (empty), or shared out among
// the ranks of an MPI job (src/distribute/form_factors.h).
using ComputeFormFactors =
    std::function<FormFactors(const Scene&, const SceneGeometry&, const FormFactorOptions&)>;

struct CacheSettings {
    bool enabled = true;
    ComputeFormFactors compute;        // empty: compute_form_factors here
    std::ostream* progress = nullptr;  // links being built show a progress bar here (a terminal)
    std::filesystem::path dir;         // empty: default_cache_dir()
    double lock_timeout_s = 600.0;     // give up waiting for another process's lock after this long
};

// $RADIOSA_CACHE_DIR if set and not empty, else "out/cache".
std::filesystem::path default_cache_dir();

enum class CacheStatus { Off, Hit, Miss, Rebuilt };
const char* cache_status_name(CacheStatus s);

struct CacheOutcome {
    CacheStatus status = CacheStatus::Off;
    std::string reason;      // why an existing file was rebuilt, or why nothing was written
    std::string file;        // the cache file used or written ("" when off)
    std::string key;         // hex
    double load_s = 0.0;     // reading (and checking) the file, hit or not
    double compute_s = 0.0;  // computing the matrix
    double write_s = 0.0;    // writing the file
    double wait_s = 0.0;     // waiting for another process computing the same matrix
    bool written = false;
};

// Loads the matrix for this scene and these options from the cache, or computes it and stores
// it. Damaged, stale, foreign or implausible files, and special files in their place, are
// reported through `warn` (one line each) and rebuilt; an unwritable cache is reported and the
// run goes on. Concurrent processes computing the same key serialise on a lock file, so the
// matrix is computed once; a lock held longer than settings.lock_timeout_s is an Error.
FormFactors obtain_form_factors(const Scene& scene, const SceneGeometry& geometry,
                                const FormFactorOptions& options, const CacheSettings& settings,
                                const WarningSink& warn, CacheOutcome* outcome);

// The matrix from the cache when a file for this key is there and passes every check; nothing
// is computed, written or locked, and a damaged file is left for obtain_form_factors to rebuild
// (outcome->reason says why it was not used). A moving sequence's geometry states use it: they
// are updated incrementally when not found, and not stored (docs/sequences.md).
std::optional<FormFactors> find_cached_form_factors(const Scene& scene, const SceneGeometry& geometry,
                                                    const FormFactorOptions& options,
                                                    const CacheSettings& settings, CacheOutcome* outcome);

}  // namespace radiosa
