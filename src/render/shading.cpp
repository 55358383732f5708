#include "render/shading.h"

namespace radiosa {

NodeRadiosity::NodeRadiosity(const SceneGeometry& geo, const std::vector<Rgb>& B, const std::vector<Rgb>& E)
    : m_geo(geo), m_E(E) {
    m_nodes.resize(geo.surface_count());
    for (int k = 0; k < geo.surface_count(); ++k) {
        const Surface& surf = geo.surface(k);
        const int ns = geo.ns(k), nt = geo.nt(k);
        auto patch_B = [&](int is, int it) {
            const int i = geo.patch_index(k, is, it);
            return B[i] - E[i];
        };
        auto& nodes = m_nodes[k];
        nodes.assign(static_cast<size_t>(ns + 1) * (nt + 1), Rgb(0.0));
        for (int b = 0; b <= nt; ++b)
            for (int a = 0; a <= ns; ++a) {
                Rgb sum(0.0);
                int count = 0;
                const bool pole = (b == 0 && surf.pole_at_t0()) || (b == nt && surf.pole_at_t1());
                if (pole) {
                    // The whole edge is one point: every patch of the adjacent row meets there.
                    const int it = b == 0 ? 0 : nt - 1;
                    for (int is = 0; is < ns; ++is, ++count) sum += patch_B(is, it);
                } else {
                    for (int da = -1; da <= 0; ++da)
                        for (int db = -1; db <= 0; ++db) {
                            int is = a + da;
                            int it = b + db;
                            if (surf.wraps_in_t())
                                it = (it + nt) % nt;  // the seam t = 0 = 1
                            else if (it < 0 || it >= nt)
                                continue;
                            if (surf.wraps_in_s())
                                is = (is + ns) % ns;  // the seam s = 0 = 1
                            else if (is < 0 || is >= ns)
                                continue;
                            sum += patch_B(is, it);
                            ++count;
                        }
                }
                nodes[static_cast<size_t>(b) * (ns + 1) + a] = sum / double(count);
            }
    }
}

const Rgb& NodeRadiosity::node(int k, int a, int b) const {
    return m_nodes[k][static_cast<size_t>(b) * (m_geo.ns(k) + 1) + a];
}

Rgb NodeRadiosity::shade(const Hit& h) const {
    // The patch's four nodes (a, b), (a + 1, b), (a, b + 1), (a + 1, b + 1), found once.
    const Patch& p = m_geo.patch(h.patch);
    const std::size_t stride = static_cast<std::size_t>(m_geo.ns(h.surface)) + 1;
    const Rgb* n0 = m_nodes[h.surface].data() + static_cast<std::size_t>(p.it) * stride + p.is;
    const Rgb* n1 = n0 + stride;
    const double u = h.u, v = h.v;
    return m_E[h.patch] + (1 - u) * (1 - v) * n0[0] + u * (1 - v) * n0[1] + u * v * n1[1] +
           (1 - u) * v * n1[0];
}

}  // namespace radiosa
