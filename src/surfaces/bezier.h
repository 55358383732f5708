#pragma once
// The `bezier` surface type: bicubic Bezier patches, from 16 inline control points or a file of
// patches (the Newell teapot's format). Rays meet them by subdivision and Newton's method inside
// the convex hull of the control points; nothing is ever replaced by triangles.
#include <array>
#include <string>
#include <vector>

#include "surfaces/surface.h"

namespace radiosa {

// P(s, t) = sum_ij B_i(t) B_j(s) cp[4 i + j] (B the cubic Bernstein polynomials): the control
// points are given row by row, s runs along a row and t from row to row; the front side is the one
// dP/ds x dP/dt points to. A row whose four points coincide is a pole (the teapot's lid and bottom).
class BezierSurface final : public Surface {
public:
    explicit BezierSurface(const std::array<Vec3, 16>& cp);
    Vec3 point(double s, double t) const override;
    void partials(double s, double t, Vec3* dPds, Vec3* dPdt) const override;
    std::optional<SurfaceHit> intersect(const Ray& ray, double t_min, double t_max,
                                        HitSide side) const override;
    // intersect()'s search stopped at the first crossing it finds: the same answer, as the
    // search takes the same cells in the same order up to there.
    bool blocks(const Ray& ray, double t_min, double t_max) const override;
    // |dP/ds x dP/dt| by adaptive Gauss-Legendre rules, to about 1e-14 relative.
    double area(double s0, double s1, double t0, double t1) const override;
    // From the control points of the sub-patch (convex hull property): never too small.
    BoundingSphere bound(double s0, double s1, double t0, double t1) const override;
    std::pair<double, double> linear_range(const Vec3& a, double s0, double s1, double t0,
                                           double t1) const override;
    bool chords_never_cross() const override { return false; }
    bool front_segments_escape() const override { return false; }
    bool sees_itself() const override { return true; }
    // The four boundary curves of the sub-patch, each a cubic Bezier curve.
    bool patch_contour(double s0, double s1, double t0, double t1,
                       std::vector<ContourPiece>* out) const override;
    // Proven from the sub-patch's control points: the central projection from every point x of
    // the hull is defined (all of it in front of x along one direction) and its Jacobian is a
    // P-matrix after a fixed change of sign, so by Gale and Nikaido's theorem the projection is
    // one to one on the rectangle. Each condition is a polynomial whose Bernstein coefficients
    // are affine in x: checked at the hull's points.
    int seen_once_from(std::span<const Vec3> from, double s0, double s1, double t0, double t1) const override;
    bool pole_at_t0() const override { return m_pole_t0; }
    bool pole_at_t1() const override { return m_pole_t1; }
    void write_key(ByteWriter& w) const override;
    // The front normal's direction at (s, t), also where the partials' cross product vanishes
    // (a collapsed edge): then the limit from inside the patch. Unit length.
    Vec3 unit_normal(double s, double t) const;
    // The control points of the sub-patch [s0,s1] x [t0,t1], in the same order.
    std::array<Vec3, 16> sub_patch(double s0, double s1, double t0, double t1) const;

private:
    // A sub-patch of the search tree: its parameter rectangle and its control points' box.
    struct Cell {
        double s0, s1, t0, t1;
        Vec3 lo, hi;
        int first_child = -1;  // its four halves in m_tree from here, or -1 (a leaf)
    };
    // Newton's method from the cell's centre: a crossing inside the cell within (t_min, t_max), one
    // at or before t_min (the ray starts on the surface there), one at or beyond t_max (the
    // segment ends on it there), or none found; a crossing that the end's rounding could be is
    // taken as the end (bezier.cpp). Elsewhere: a crossing within (t_min, t_max) on the patch
    // but outside the cell.
    enum class Newton { None, Hit, Elsewhere, Before, Beyond };
    Cell make_cell(double s0, double s1, double t0, double t1) const;
    Cell box_of(double s0, double s1, double t0, double t1, const std::array<Vec3, 16>& cp) const;
    static void quarter(const std::array<Vec3, 16>& cp, std::array<std::array<Vec3, 16>, 4>* out);
    void split(int cell, int levels);
    // The static tree from cell c (whose box the ray meets) down, then refine() below its leaves.
    // With `found`, the first crossing found sets it and ends the search (an occlusion test).
    void search(const Cell& c, const Ray& ray, double t_min, double* best, SurfaceHit* hit, HitSide side,
                bool* found) const;
    void refine(const Cell& c, const std::array<Vec3, 16>& cp, const Ray& ray, double t_min, double* best,
                SurfaceHit* hit, HitSide side, int depth, int max_depth, bool* found) const;
    Newton newton(const Cell& c, const Ray& ray, double t_min, double t_max, SurfaceHit* hit) const;
    // point() and partials() at once, the same bits.
    void point_and_partials(double s, double t, Vec3* p, Vec3* dPds, Vec3* dPdt) const;
    // The nearest crossing, or with `first` the first one the search finds.
    std::optional<SurfaceHit> crossing(const Ray& ray, double t_min, double t_max, HitSide side,
                                       bool first) const;

    std::array<Vec3, 16> m_cp;
    bool m_pole_t0 = false, m_pole_t1 = false;
    double m_size = 0.0;  // the control points' extent, for tolerances
    // The patch (m_tree[0]) halved in s and t five times over, down to 32 x 32 leaves: boxes tight
    // enough that Newton's method from a leaf's centre rarely fails; below them, halves are made
    // on demand from the leaf's control points.
    std::vector<Cell> m_tree;
};

// One patch per entry, in file order. The file: the number of patches, then one line of 16
// indices (1-based, comma- or space-separated) per patch, then the number of points, then one
// point per line (x, y, z). Bad data throws at its line.
std::vector<std::array<Vec3, 16>> read_bezier_file(const std::string& path);

}  // namespace radiosa
