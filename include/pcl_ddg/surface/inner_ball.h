#pragma once
/** \file
 * How thick the solid behind each vertex is: the radius of the largest empty ball that touches
 * the surface at the vertex from its inner side (the side opposite its normal).
 *
 * Shrinking balls (Ma, Bae, Choi and Ramanathan 2012, "3D medial axis point approximation using
 * nearest neighbors and the normal field"): start from a ball of radius r = the bounding-box
 * diagonal centred at c = p - r n (n the outward unit normal at p). While the vertex q nearest to c
 * lies strictly inside the ball, replace it by the ball through p and q that is still tangent at p:
 *
 *     |p - r' n - q|^2 = r'^2   =>   r' = |p - q|^2 / (2 n . (p - q))
 *
 * (q inside the ball means n . (p - q) > |p - q|^2 / (2 r) > 0, so r' < r: the radius only
 * shrinks). It stops when no vertex is inside. On a tube of radius a the result is a, on a sphere
 * its radius, on a plate half its thickness; only vertices are tested, so on a coarse mesh it can
 * exceed the true radius by the sagitta of an edge. A convex bump of height e on edges of length h
 * stops it at about h^2 / (2 e): noise reads as thin only where it is as deep as the part is thin.
 * A normal tilted by d radians lets the ball out between p and its nearest vertices unless
 * r <= R / (1 + 2 d R / h): the estimate is a few per cent low where R is a few edges (the thin
 * parts it is for), up to a fifth low on fine, gently curved surfaces.
 *
 * The outward side is the faces' orientation, turned over on each closed component that encloses
 * a negative volume (faces wound inward; with inconsistent winding or non-manifold edges the
 * faces' side is taken as it is). Exact doubles of p (scans repeat points) lie on every ball's
 * sphere and never stop it; a vertex a hair inside p does (r about half their distance): such a
 * degenerate spot is then kept nearly still, which on badly decimated meshes keeps their
 * near-coincident vertices from forming slivers. Vertices without a valid normal (no
 * non-degenerate triangle, or face normals that cancel) get +infinity, as does a vertex no other
 * vertex constrains. Vertices of no triangle take no part. Coordinates are taken
 * about the vertices' mean (scans sit far from the origin).
 */
#include <Eigen/Core>
#include <limits>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/positions_ref.h"

namespace pcl_ddg {

/**
 * The inner-ball radius of every vertex (see above); deterministic for any thread count. With
 * `largest` the balls start from that radius instead of the diagonal and a radius is reported as
 * at most it: min(largest, r), the same r wherever r < largest (1 - 1e-9) (a ball tangent at p is
 * empty exactly while its radius is at most r, and each shrink lands on a radius no smaller than
 * r, so the iteration ends on r from any start above it; a start within the emptiness test's
 * tolerance of r stops there). What a caller that only needs the thin parts
 * asks for: a ball as wide as the surface, centred far outside it, makes the nearest-vertex
 * search visit much of the tree (on a 1.15M-vertex torus, minutes).
 */
Eigen::VectorXd innerBallRadii(const MeshTopology& topology, const PositionsRef& positions,
                               double largest = std::numeric_limits<double>::infinity());

}  // namespace pcl_ddg
