#include "formfactor/incremental.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include "formfactor/culling.h"
#include "geometry/scene_geometry.h"
#include "util/bytes.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace {

std::vector<std::uint8_t> key_bytes(const Surface& s) {
    ByteWriter w;
    s.write_key(w);
    return std::move(w.bytes());
}

bool same_patches(const SceneGeometry& a, const SceneGeometry& b) {
    if (a.surface_count() != b.surface_count() || a.patch_count() != b.patch_count()) return false;
    for (int k = 0; k < a.surface_count(); ++k)
        if (a.ns(k) != b.ns(k) || a.nt(k) != b.nt(k) || a.twin(k) != b.twin(k)) return false;
    return true;
}

struct Counts {
    long long moved = 0, shadowed = 0, unchanged = 0, entries = 0;
};

// Per row i, the j >= i to recompute.
std::vector<std::vector<int>> select_pairs(const SceneGeometry& from, const SceneGeometry& to,
                                           const std::vector<int>& moved_surfaces, bool everything,
                                           Counts* counts) {
    const int n = to.patch_count();
    std::vector<char> moved(static_cast<std::size_t>(to.surface_count()), 0);
    for (const int k : moved_surfaces) moved[static_cast<std::size_t>(k)] = 1;
    const Culling before(from), after(to);
    std::vector<std::vector<int>> rows(static_cast<std::size_t>(n));
    std::mutex merge;
    tbb::parallel_for(tbb::blocked_range<int>(0, n, 16), [&](const tbb::blocked_range<int>& r) {
        Counts local;
        std::vector<char> clear(static_cast<std::size_t>(to.surface_count()));
        for (int i = r.begin(); i != r.end(); ++i) {
            std::vector<int>& row = rows[static_cast<std::size_t>(i)];
            const bool moved_i = moved[static_cast<std::size_t>(to.patch(i).surface)] != 0;
            // Surfaces none of whose patches a moved surface can come between with i, proven
            // once for the whole surface (which would otherwise cost a test per pair).
            for (int b = 0; b < to.surface_count(); ++b) {
                char& c = clear[static_cast<std::size_t>(b)];
                c = moved_i || moved[static_cast<std::size_t>(b)] != 0 ? 0 : 1;
                for (const int k : moved_surfaces)
                    if (c && (before.can_block_any(i, b, k) || after.can_block_any(i, b, k))) c = 0;
            }
            for (int j = i; j < n; ++j) {
                bool redo =
                    everything || moved_i || moved[static_cast<std::size_t>(to.patch(j).surface)] != 0;
                if (redo) {
                    ++local.moved;
                } else if (!clear[static_cast<std::size_t>(to.patch(j).surface)] && !after.culled(i, j)) {
                    // Culled pairs depend on their own two patches only: zero before and after.
                    for (const int k : moved_surfaces)
                        if (before.can_block(i, j, k) || after.can_block(i, j, k)) {
                            redo = true;
                            ++local.shadowed;
                            break;
                        }
                }
                if (!redo) {
                    ++local.unchanged;
                    continue;
                }
                row.push_back(j);
                local.entries += i == j ? 1 : 2;
            }
        }
        std::lock_guard lock(merge);
        counts->moved += local.moved;
        counts->shadowed += local.shadowed;
        counts->unchanged += local.unchanged;
        counts->entries += local.entries;
    });
    return rows;
}

}  // namespace

FormFactors update_form_factors(const SceneGeometry& from_geometry, FormFactors&& from,
                                const SceneGeometry& to_geometry, const FormFactorOptions& options,
                                FormFactorUpdate* update) {
    const Stopwatch clock;
    if (!same_patches(from_geometry, to_geometry) || from.F.n != to_geometry.patch_count())
        throw std::invalid_argument("update_form_factors: the two geometries have different patches");
    *update = FormFactorUpdate{};
    std::vector<int> moved;
    for (int k = 0; k < to_geometry.surface_count(); ++k)
        if (&from_geometry.surface(k) != &to_geometry.surface(k) &&
            key_bytes(from_geometry.surface(k)) != key_bytes(to_geometry.surface(k)))
            moved.push_back(k);
    update->surfaces_moved = static_cast<int>(moved.size());
    const auto n = static_cast<long long>(to_geometry.patch_count());
    update->entries_total = n * n;
    // Tolerances (Culling::eps, the numeric path's smallest distance) scale with the scene's
    // extent: a move that changes it changes every pair's arithmetic.
    if (from_geometry.scale() != to_geometry.scale()) {
        update->full = true;
        update->reason = "the scene's extent changed";
    } else if (!options.culling) {
        update->full = true;
        update->reason = "culling is off: every surface is a possible blocker of every pair";
    }
    Counts counts;
    const Stopwatch select_clock;
    const std::vector<std::vector<int>> rows =
        select_pairs(from_geometry, to_geometry, moved, update->full, &counts);
    update->select_s = select_clock.seconds();
    update->pairs_moved = counts.moved;
    update->pairs_shadowed = counts.shadowed;
    update->pairs_unchanged = counts.unchanged;
    update->entries_recomputed = counts.entries;
    FormFactors ff = std::move(from);
    ff.options = options;
    ff.stats = FormFactorStats{};
    const Stopwatch compute_clock;
    const FormFactorRows computer(to_geometry, options);
    computer.compute_pairs(rows, &ff, &ff.stats);
    update->compute_s = compute_clock.seconds();
    update->stats = ff.stats;
    update->seconds = clock.seconds();
    ff.stats.seconds = update->seconds;
    return ff;
}

FormFactors update_form_factors(const SceneGeometry& from_geometry, const FormFactors& from,
                                const SceneGeometry& to_geometry, const FormFactorOptions& options,
                                FormFactorUpdate* update) {
    const Stopwatch clock;
    FormFactors copy = from;
    FormFactors ff = update_form_factors(from_geometry, std::move(copy), to_geometry, options, update);
    update->seconds = clock.seconds();
    ff.stats.seconds = update->seconds;
    return ff;
}

}  // namespace radiosa
