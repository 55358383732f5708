#pragma once
// The cached hierarchical links (formfactor/hierarchy.h): the object the hierarchical method
// caches in place of the matrix, keyed, checked, written and locked like it (docs/cache.md).
// Only the links are stored: the nodes they join follow from the geometry and are rebuilt on
// load (cheap, O(N)), so a file cannot describe a tree other than the scene's.
//
// A file is named <key>.rhl. Layout, all little-endian:
//
//   header   magic "RADHL\r\n\x1a", u32 format version, u32 algorithm version, 16-byte key,
//            str scene name (u32 length <= 4096 + UTF-8), u64 patch count, u64 surface count,
//            u64 node count, u64 link count, u32 flags (bit 1: visibility tested, bit 2: the
//            scene is closed), u32 Gauss points per node parameter, f64 pair tolerance,
//            f64 link tolerance, u32 compression (0 none, 1 zstd),
//            u64 stored size of the link section, u64 its uncompressed size (56 x links)
//   table    as the matrix file's (surfaces, patches, the pairs' FormFactorStats counters), then
//            the hierarchy's counters as i64: leaf_links, node_pairs, kernel_samples, dropped
//   links    sorted by (receiver, source), each: u32 receiver, u32 source, f64 f, error, gs, gt,
//            cs, ct (Link); zstd-compressed as a whole when that saves a quarter
//   trailer  u64 XXH3-64 checksum of every preceding byte
#include <cstdint>
#include <filesystem>
#include <span>

#include "cache/cache_file.h"
#include "formfactor/hierarchy.h"

namespace radiosa {

inline constexpr std::uint32_t kLinkFormatVersion = 1;

// The key: what form_factor_key hashes (geometry, visibility, algorithm version) with the
// hierarchical method's settings (pair and link tolerances, Gauss points per node parameter).
CacheKey hierarchy_key(const Scene& scene, const FormFactorOptions& options);

// The hierarchy's own settings from the form-factor options.
HierarchyOptions hierarchy_options(const FormFactorOptions& options);

// Writes atomically, like write_cache_file; `options` are the ones the links were built with.
// Throws Error when it cannot be written.
void write_link_file(const std::filesystem::path& path, const CacheKey& key, const std::string& scene_name,
                     bool closed, const SceneGeometry& geometry, const FormFactorOptions& options,
                     const Hierarchy& h);

// Header only (`cache list`). Throws CacheFileError.
CacheFileInfo read_link_info(const std::filesystem::path& path);

// Reads and checks a file for this scene and request, in the matrix file's order (regular file,
// header, sizes, checksum, key, patch table), rebuilds the nodes from the geometry, reads every
// link against them (indices in range, strictly sorted, values finite, factors in [0, 1.01],
// estimates >= 0) and runs check_cache_links. Throws CacheFileError.
Hierarchy read_link_file(const std::filesystem::path& path, const CacheExpectation& expect,
                         CacheFileInfo* info = nullptr);
Hierarchy read_link_bytes(std::span<const std::uint8_t> bytes, const CacheExpectation& expect,
                          CacheFileInfo* info = nullptr);

// `cache verify`: every check that needs no scene (all but the patch table against a scene and
// the row sums, which need the nodes), streamed in bounded memory. Throws CacheFileError.
CacheFileInfo verify_link_file(const std::filesystem::path& path);
CacheFileInfo verify_link_bytes(std::span<const std::uint8_t> bytes);

// The sense checks of loaded (and freshly built) links: every patch's row sum at most 1 + 16 x
// its summed estimates (+1e-6), and for a closed scene within max(16 x estimates, 1 %) of 1
// (with visibility tested; without it rows of a closed scene exceed 1).
void check_cache_links(const Hierarchy& h, const FormFactorOptions& options, bool closed);

// The links for this scene from the cache, or built and stored: obtain_form_factors for the
// hierarchical method (same directory, lock, warnings and outcome).
Hierarchy obtain_hierarchy(const Scene& scene, const SceneGeometry& geometry,
                           const FormFactorOptions& options, const CacheSettings& settings,
                           const WarningSink& warn, CacheOutcome* outcome);

}  // namespace radiosa
