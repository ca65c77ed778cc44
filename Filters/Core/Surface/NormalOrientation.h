// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief Consistent orientation of estimated normals (NormalField from SurfaceNormals.h), in place.
 *
 * Propagation (the default; Hoppe et al. 1992), in two levels so that it runs in parallel and gives the same
 * result whatever the split of the cloud among processes:
 * 1. Blocks: cubes of 4 x the median distance to the NeighborCount-th neighbour (about ten spacings), laid over
 *    the grid's frame (the whole cloud's bounds). Inside each block (blocks in parallel), a minimum spanning tree
 *    of the symmetrised k-nearest graph's edges within the block, cost 1 - |n_i . n_j| (Prim's algorithm with a
 *    bucket queue), grown from the block's first point in the grid's order, over edges whose normals agree up to
 *    sign within 45 degrees; every point is flipped to agree with its tree parent, so orientation travels across
 *    the flattest, least ambiguous edges. Each tree is a node.
 * 2. Nodes: every graph edge between two nodes votes n_i . n_j - 2 (n_i . e)(n_j . e) / |e|^2, e = p_j - p_i with
 *    its components along the normals shrunk by the noise (the agreement of two normals on one circular arc
 *    through both points: n_i . n_j along a gently curved surface, about +1 across a sharp ridge whose faces'
 *    normals are nearly opposite; NormalOrientation.cxx, ArcAgreement), rounded to 2^-24, so that the votes' sums
 *    are exact in any order; a maximum spanning forest of the summed votes (Kruskal, strongest first, ties by the
 *    nodes' keys) turns each node relative to its tree's root: the strongest agreement or disagreement decides,
 *    and hundreds of edges vote across a block's face where Prim's single edge could fall on an ambiguous pair.
 *    Links of fewer than about ten agreeing edges' votes are weak: the strong ones are joined first, and a piece
 *    they make of at least 2,000 points whose own flux decides its side (an anchor: |sum n . (x - c)| at least a
 *    quarter of N x its rms radius; not a flat face) is turned on its own (below); the weak links then join the
 *    rest, never two anchors (a large part of a scan reached only across a sparse strip is not turned by one
 *    doubtful vote there; a small piece follows its strongest link).
 * Each connected piece (a tree of nodes) is then turned outward as a whole: sum_i n_i . (p_i - c) > 0, c its
 * centroid (by the divergence theorem this is 3 x the enclosed volume for a closed surface, so it is positive
 * exactly when the normals point out; for an open patch it picks the convex side); a tree holding an anchor as
 * that anchor's own flux asks. `Confidence` is
 * |n_i . n_parent| (1 for the blocks' roots): below 0.5 the orientation was ambiguous there (research/surface.md
 * §4). Distributed (OrientationOptions::Processes): each process orients the blocks that hold one of its own
 * points (its halo holds the rest of them: Shortfall reports a block beyond it), the nodes' votes and sums are
 * gathered (a few values per block), and every process solves the same node forest. Only the pieces' flux
 * sums (decisions on their sign) depend on the summation order.
 * Sharp features (NormalField::JetNormals, SurfaceNormals.cxx's SharpFeatures): where points near a crease took a
 * neighbour's normal, the propagation runs over the jets' own normals (a donor near a ridge is often the other
 * face's, and propagating over it tied the faces wrongly), then each donor normal is turned to agree with its
 * point's oriented one.
 * Viewpoint: every component is turned towards a viewpoint as a whole (sum_i n_i . (v - p_i) > 0); the
 * propagation still decides within it, so non-star-shaped objects stay consistent.
 * Reference: each normal is flipped to agree with a given normal (e.g. a scan's normals of poor quality or
 * of unknown length); Confidence = |n_i . r_i| / |r_i|.
 */
#ifndef meshfree_NormalOrientation_h
#define meshfree_NormalOrientation_h

#include "Surface/SurfaceNormals.h"

#include <vector>

namespace meshfree
{

enum class OrientationMode
{
  Propagation = 0,
  Viewpoint = 1,
  Reference = 2
};

struct OrientationOptions
{
  OrientationMode Mode = OrientationMode::Propagation;
  double Viewpoint[3] = { 0.0, 0.0, 0.0 };
  const double* Reference = nullptr; // 3 per point (Mode Reference)
  const Distribution* Processes = nullptr; // a cloud split among processes (SurfaceNormals.h's NormalOptions)
};

struct OrientationReport
{
  Index Components = 0;          // connected pieces of the neighbour graph
  Index FlippedComponents = 0;   // turned as a whole (outward or to the viewpoint)
  Index Ambiguous = 0;           // valid points with Confidence < 0.5 (of the whole cloud)
  double Shortfall = -HUGE_VAL;  // distributed: Shortfall() of the blocks the propagation read (<= 0: complete)
};

/// Orients field.Normals in place; `grid` is the one the field was estimated on (the propagation runs in its
/// Morton order, so that graph neighbours are near in memory). confidence gets one value per point (0 where
/// the normal is invalid).
OrientationReport OrientNormals(const NeighborGrid& grid, NormalField& field, const OrientationOptions& options,
  std::vector<double>& confidence);

} // namespace meshfree

#endif
