// The hierarchical links' cache file (layout in link_file.h): written, read against a scene, and
// verified without one. The checks mirror the matrix file's (cache_file.cpp, cache_verify.cpp).
#include "cache/link_file.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "cache/cache_format.h"
#include "geometry/scene_geometry.h"
#include "scene/scene.h"
#include "util/bytes.h"
#include "util/error.h"

namespace radiosa {

namespace fs = std::filesystem;
using namespace cache_format;

namespace {

constexpr char kLinkMagic[8] = {'R', 'A', 'D', 'H', 'L', '\r', '\n', '\x1a'};
constexpr std::uint64_t kLinkBytes = 56;  // two u32 and six f64
constexpr int kHierarchyCounters = 4;     // leaf_links, node_pairs, kernel_samples, dropped

struct LinkHeader {
    Header h;
    std::uint32_t samples = 0;
};

double bounded_tolerance(double t, const char* what) {
    if (!(t >= 1e-12 && t <= 0.1)) throw CacheFileError(std::string("implausible ") + what + " tolerance");
    return t;
}

void read_counts(ByteReader& in, LinkHeader& lh) {
    CacheFileInfo& info = lh.h.info;
    info.patches = in.u64();
    info.surfaces = in.u64();
    info.nodes = in.u64();
    info.links = in.u64();
    if (info.patches == 0 || info.patches > static_cast<std::uint64_t>(kMaxPatches) || info.surfaces == 0 ||
        info.surfaces > info.patches)
        throw CacheFileError("implausible patch count " + std::to_string(info.patches));
    // Each surface's tree over its n patches has 2 n - 1 nodes.
    if (info.nodes != 2 * info.patches - info.surfaces)
        throw CacheFileError("implausible node count " + std::to_string(info.nodes));
    if (info.links > info.nodes * info.nodes)
        throw CacheFileError("implausible link count " + std::to_string(info.links));
}

LinkHeader read_link_header(ByteReader& in) {
    if (std::memcmp(in.take(sizeof kLinkMagic), kLinkMagic, sizeof kLinkMagic) != 0)
        throw CacheFileError("not a radiosa hierarchical-link cache file (wrong magic bytes)");
    LinkHeader lh;
    CacheFileInfo& info = lh.h.info;
    info.format_version = in.u32();
    if (info.format_version != kLinkFormatVersion)
        throw CacheFileError("link file format version " + std::to_string(info.format_version) +
                             ", this build reads " + std::to_string(kLinkFormatVersion));
    info.algorithm_version = in.u32();
    if (info.algorithm_version != kFormFactorAlgorithmVersion)
        throw CacheFileError("computed by form-factor algorithm version " +
                             std::to_string(info.algorithm_version) + ", this build is version " +
                             std::to_string(kFormFactorAlgorithmVersion));
    std::memcpy(info.key.bytes.data(), in.take(16), 16);
    if (in.peek_u32() > kMaxName) throw CacheFileError("implausible scene name length");
    info.scene_name = in.str();
    read_counts(in, lh);
    const std::uint32_t flags = in.u32();
    lh.samples = in.u32();
    const double pair_tol = bounded_tolerance(in.f64(), "pair");
    const double link_tol = bounded_tolerance(in.f64(), "link");
    lh.h.compression = in.u32();
    lh.h.stored = in.u64();
    lh.h.raw = in.u64();
    lh.h.length = in.pos();
    if (flags & ~(kFlagVisibility | kFlagClosed))
        throw CacheFileError("unknown flags " + std::to_string(flags));
    if (lh.samples < 2 || lh.samples > 8)
        throw CacheFileError("implausible Gauss points per node " + std::to_string(lh.samples));
    if (lh.h.compression > kCompressZstd)
        throw CacheFileError("unknown compression " + std::to_string(lh.h.compression));
    if (lh.h.raw != kLinkBytes * info.links)
        throw CacheFileError("link section size disagrees with the link count");
    info.options = FormFactorOptions::hierarchical(link_tol, (flags & kFlagVisibility) != 0);
    info.options.tolerance = pair_tol;
    info.closed = (flags & kFlagClosed) != 0;
    info.layout = "links";
    info.compression = lh.h.compression == kCompressZstd ? "zstd" : "none";
    info.has_error_estimates = true;
    return lh;
}

LinkHeader read_link_source_header(const Source& src) {
    return parse_head(src, [](ByteReader& in) { return read_link_header(in); });
}

// The sizes against each other and the file's, before anything else is read.
void check_link_sizes(const Header& h, std::uint64_t size) {
    if (h.compression == kCompressNone && h.stored != h.raw)
        throw CacheFileError("uncompressed link section sizes disagree");
    if (h.compression == kCompressZstd && h.stored > h.raw + h.raw / 64 + 1024)
        throw CacheFileError("compressed link section is larger than its content could need");
    const std::uint64_t body = size - h.length;
    const std::uint64_t min_table = min_table_size(h) + 8 * kHierarchyCounters;
    if (h.stored > body || min_table + 8 > body - h.stored)
        throw CacheFileError("file is truncated (" + std::to_string(size) +
                             " bytes, the header promises more)");
    if (body - h.stored - 8 > max_table_size(h) + 8 * kHierarchyCounters)
        throw CacheFileError("file is " + std::to_string(size) + " bytes, more than its header accounts for");
}

// Every link, checked as it is read: nodes in range, strictly sorted by (receiver, source),
// finite values, factors in [0, 1.01] (a factor may exceed 1 by its estimate, checked on rows
// later), estimates >= 0. Appended to `out`'s links when given, a link between two patches to
// its pair links (its slopes must then be 0).
void read_links(SectionStream& s, std::uint64_t nodes, std::uint64_t count, Hierarchy* out) {
    std::uint64_t prev_r = 0, prev_s = 0;
    for (std::uint64_t k = 0; k < count; ++k) {
        Link l;
        const std::uint32_t r = s.u32(), q = s.u32();
        l.f = s.f64(), l.error = s.f64();
        // The slopes are single-precision values, written as f64.
        for (float* slope : {&l.gs, &l.gt, &l.cs, &l.ct}) *slope = static_cast<float>(s.f64());
        const std::string at = "link " + std::to_string(k);
        if (r >= nodes || q >= nodes) throw CacheFileError(at + " joins a node out of range");
        if (k > 0 && (r < prev_r || (r == prev_r && q <= prev_s)))
            throw CacheFileError(at + " is out of order (links are sorted by receiver, then source)");
        if (!(l.f >= 0.0 && l.f <= 1.01)) throw CacheFileError(at + " has a factor outside [0, 1]");
        if (!(l.error >= 0.0 && std::isfinite(l.error)))
            throw CacheFileError(at + " has an estimate that is not a finite number >= 0");
        if (!std::isfinite(l.gs) || !std::isfinite(l.gt) || !std::isfinite(l.cs) || !std::isfinite(l.ct))
            throw CacheFileError(at + " has a slope that is not a finite number");
        prev_r = r, prev_s = q;
        l.receiver = static_cast<int>(r), l.source = static_cast<int>(q);
        if (!out) continue;
        if (out->nodes[r].leaf() && out->nodes[q].leaf()) {
            if (l.gs != 0.0f || l.gt != 0.0f || l.cs != 0.0f || l.ct != 0.0f)
                throw CacheFileError(at + " joins two patches but has slopes");
            out->pair_links.push_back({l.receiver, l.source, l.f, l.error});
        } else {
            out->links.push_back(l);
        }
    }
}

// Both kinds of links in one sequence sorted by (receiver, source), as the file holds them.
class LinkMerge {
public:
    explicit LinkMerge(const Hierarchy& h) : m_h(h) {}
    std::size_t remaining() const { return m_h.links.size() - m_a + m_h.pair_links.size() - m_b; }
    Link next() {
        const bool take_pair = m_a == m_h.links.size() || (m_b < m_h.pair_links.size() &&
                                                           link_before(m_h.pair_links[m_b], m_h.links[m_a]));
        if (!take_pair) return m_h.links[m_a++];
        const PairLink& p = m_h.pair_links[m_b++];
        return Link{p.receiver, p.source, p.f, p.error};
    }

private:
    const Hierarchy& m_h;
    std::size_t m_a = 0, m_b = 0;
};

// The links still in `merge` serialized into dst while they fit: two u32 and six f64 each.
std::size_t link_bytes(LinkMerge& merge, std::uint8_t* dst, std::size_t cap) {
    ByteWriter m;
    const std::size_t count = std::min(cap / kLinkBytes, merge.remaining());
    m.bytes().reserve(count * kLinkBytes);
    for (std::size_t k = 0; k < count; ++k) {
        const Link l = merge.next();
        m.u32(static_cast<std::uint32_t>(l.receiver));
        m.u32(static_cast<std::uint32_t>(l.source));
        for (const double v : {l.f, l.error, double(l.gs), double(l.gt), double(l.cs), double(l.ct)})
            m.f64(v);
    }
    std::memcpy(dst, m.bytes().data(), m.bytes().size());
    return m.bytes().size();
}

void write_link_header(ByteWriter& w, const CacheKey& key, const std::string& scene_name, bool closed,
                       const SceneGeometry& g, const FormFactorOptions& options, const Hierarchy& h) {
    w.raw(kLinkMagic, sizeof kLinkMagic);
    w.u32(kLinkFormatVersion);
    w.u32(kFormFactorAlgorithmVersion);
    w.raw(key.bytes.data(), 16);
    w.str(capped_name(scene_name));
    w.u64(static_cast<std::uint64_t>(g.patch_count()));
    w.u64(static_cast<std::uint64_t>(g.surface_count()));
    w.u64(h.nodes.size());
    w.u64(static_cast<std::uint64_t>(h.link_count()));
    w.u32((options.visibility ? kFlagVisibility : 0) | (closed ? kFlagClosed : 0));
    w.u32(static_cast<std::uint32_t>(h.options.samples));
    w.f64(options.tolerance);
    w.f64(h.options.tolerance);
}

void check_expectation(const LinkHeader& lh, const CacheExpectation& expect) {
    const CacheFileInfo& info = lh.h.info;
    if (info.key != expect.key)
        throw CacheFileError("holds key " + info.key.hex() + ", not this scene's " + expect.key.hex() +
                             " (a file from another scene or settings)");
    const SceneGeometry& g = *expect.geometry;
    if (info.patches != static_cast<std::uint64_t>(g.patch_count()) ||
        info.surfaces != static_cast<std::uint64_t>(g.surface_count()))
        throw table_mismatch(std::to_string(info.patches) + " patches on " + std::to_string(info.surfaces) +
                             " surfaces, the scene has " + std::to_string(g.patch_count()) + " on " +
                             std::to_string(g.surface_count()));
    const FormFactorOptions& o = info.options;
    const FormFactorOptions& want = expect.options;
    if (want.method != FormFactorMethod::Hierarchical || o.visibility != want.visibility ||
        o.tolerance != want.tolerance || o.link_tolerance != want.link_tolerance ||
        static_cast<int>(lh.samples) != hierarchy_options(want).samples)
        throw CacheFileError("was computed " + describe(o) + ", visibility " + (o.visibility ? "on" : "off") +
                             "; this run asks for " + describe(want) + ", visibility " +
                             (want.visibility ? "on" : "off"));
    if (info.closed != expect.closed)
        throw CacheFileError(std::string("says the scene is ") + (info.closed ? "closed" : "open") +
                             "; this scene is " + (expect.closed ? "closed" : "open"));
}

void read_hierarchy_counters(ByteReader& in, HierarchyStats* st) {
    for (long long* v : {&st->leaf_links, &st->node_pairs, &st->kernel_samples, &st->dropped}) {
        *v = in.i64();
        if (*v < 0) throw CacheFileError("table holds a negative counter");
    }
}

Hierarchy read_source(const Source& src, const CacheExpectation& expect, CacheFileInfo* info_out) {
    const LinkHeader lh = read_link_source_header(src);
    const Header& h = lh.h;
    check_expectation(lh, expect);
    check_link_sizes(h, src.size());
    Hierarchy hier = hierarchy_nodes(*expect.geometry, hierarchy_options(expect.options));
    if (h.info.nodes != hier.nodes.size()) throw table_mismatch("the node count differs");
    // Streamed, never the whole file in memory beside its links: the checksum first, then the
    // table, then the links chunk by chunk.
    check_checksum(src);
    const std::vector<std::uint8_t> table =
        src.read_vector(h.length, static_cast<std::size_t>(src.size() - 8 - h.stored - h.length));
    ByteReader in(table.data(), table.size());
    std::vector<double> areas(h.info.patches);
    read_patch_table(in, h, *expect.geometry, &areas, &hier.leaf_stats);
    read_hierarchy_counters(in, &hier.stats);
    if (in.remaining() != 0) throw CacheFileError("link section does not start where the table ends");
    SectionStream s(src, h.stored, h.raw, h.compression == kCompressZstd, "link");
    // The links held once (no doubling vector, no shrinking copy): both kinds reserve room for
    // every link, and the part one kind leaves untouched is never resident. A damaged count
    // reserves no more than 64 times what the stored bytes hold (zstd packs links about 2 to 3
    // times) before the reading stops it.
    const auto room = static_cast<std::size_t>(
        std::min<std::uint64_t>(h.info.links, h.stored * 64 / kLinkBytes + (1u << 20)));
    hier.links.reserve(room);
    hier.pair_links.reserve(room);
    read_links(s, h.info.nodes, h.info.links, &hier);
    s.finish();
    index_links(&hier);
    check_cache_links(hier, expect.options, h.info.closed);
    if (info_out) *info_out = h.info;
    return hier;
}

CacheFileInfo verify_source(const Source& src) {
    const LinkHeader lh = read_link_source_header(src);
    check_link_sizes(lh.h, src.size());
    check_checksum(src);
    check_table(src, lh.h, kHierarchyCounters);
    SectionStream s(src, lh.h.stored, lh.h.raw, lh.h.compression == kCompressZstd, "link");
    read_links(s, lh.h.info.nodes, lh.h.info.links, nullptr);
    s.finish();
    return lh.h.info;
}

template <class F>
auto guarded(std::uint64_t size, F&& f) {
    try {
        return f();
    } catch (const ByteReader::Truncated&) {
        throw CacheFileError("file is truncated (" + std::to_string(size) + " bytes)");
    }
}

}  // namespace

HierarchyOptions hierarchy_options(const FormFactorOptions& options) {
    HierarchyOptions ho;
    ho.tolerance = options.link_tolerance;
    ho.receiver_tolerance = options.receiver_tolerance;
    return ho;
}

CacheKey hierarchy_key(const Scene& scene, const FormFactorOptions& options) {
    ByteWriter w;
    w.str("radiosa hierarchical links");
    w.u32(kLinkFormatVersion);
    w.u32(kHierarchyAlgorithmVersion);
    w.raw(form_factor_key(scene, FormFactorOptions::adaptive(options.tolerance, options.visibility))
              .bytes.data(),
          16);
    w.f64(options.link_tolerance);
    w.u32(static_cast<std::uint32_t>(hierarchy_options(options).samples));
    // Absent at 0: the keys of earlier builds stay valid.
    if (options.receiver_tolerance > 0.0) {
        w.str("receiver tolerance");
        w.f64(options.receiver_tolerance);
    }
    return hash_key(w.bytes());
}

void write_link_file(const fs::path& path, const CacheKey& key, const std::string& scene_name, bool closed,
                     const SceneGeometry& geometry, const FormFactorOptions& options, const Hierarchy& h) {
    // Streamed: a large scene's links are gigabytes, and a whole uncompressed copy of them (or
    // even a compressed one) beside the links themselves would set the run's peak memory.
    const std::uint64_t raw_size = static_cast<std::uint64_t>(h.link_count()) * kLinkBytes;
    const auto head = [&](std::uint64_t stored) {
        ByteWriter w;
        write_link_header(w, key, scene_name, closed, geometry, options, h);
        w.u32(kCompressZstd);
        w.u64(stored);
        w.u64(raw_size);
        write_table(w, geometry, h.leaf_stats);
        for (const long long v :
             {h.stats.leaf_links, h.stats.node_pairs, h.stats.kernel_samples, h.stats.dropped})
            w.i64(v);
        return std::move(w.bytes());
    };
    LinkMerge merge(h);
    commit_streamed(path, raw_size, head,
                    [&](std::uint8_t* dst, std::size_t cap) { return link_bytes(merge, dst, cap); });
}

CacheFileInfo read_link_info(const fs::path& path) {
    const FileSource src(path);
    const LinkHeader lh = read_link_source_header(src);
    check_link_sizes(lh.h, src.size());
    return lh.h.info;
}

Hierarchy read_link_bytes(std::span<const std::uint8_t> bytes, const CacheExpectation& expect,
                          CacheFileInfo* info) {
    return guarded(bytes.size(), [&] { return read_source(MemorySource(bytes), expect, info); });
}

Hierarchy read_link_file(const fs::path& path, const CacheExpectation& expect, CacheFileInfo* info) {
    const FileSource src(path);
    return guarded(src.size(), [&] { return read_source(src, expect, info); });
}

CacheFileInfo verify_link_bytes(std::span<const std::uint8_t> bytes) {
    return guarded(bytes.size(), [&] { return verify_source(MemorySource(bytes)); });
}

CacheFileInfo verify_link_file(const fs::path& path) {
    const FileSource src(path);
    return guarded(src.size(), [&] { return verify_source(src); });
}

void check_cache_links(const Hierarchy& h, const FormFactorOptions& options, bool closed) {
    std::vector<double> node_err(h.nodes.size(), 0.0);
    h.for_each_link(
        [&](int receiver, int, double error) { node_err[static_cast<std::size_t>(receiver)] += error; });
    CacheFileInfo info;
    info.options = FormFactorOptions::adaptive(options.tolerance, options.visibility);
    info.closed = closed;
    check_rows(h.row_sums(), h.to_patches(std::move(node_err)), info);
}

}  // namespace radiosa
