// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief Consistent orientation of estimated normals (NormalField from SurfaceNormals.h), in place.
 *
 * Propagation (the default; Hoppe et al. 1992): a minimum spanning tree of the symmetrised k-nearest graph
 * with edge cost 1 - |n_i . n_j| (Prim's algorithm with an indexed heap, O(E log n), memory O(n k)), grown
 * from the first point of each connected component; every point is flipped to agree with its tree parent,
 * so orientation travels across the flattest, least ambiguous edges. Each component is then turned
 * outward as a whole: sum_i n_i . (p_i - c) > 0, c its centroid (by the divergence theorem this is 3 x the
 * enclosed volume for a closed surface, so it is positive exactly when the normals point out; for an open
 * patch it picks the convex side). `Confidence` is |n_i . n_parent| (1 for the components' roots): below
 * 0.5 the orientation was ambiguous there (research/surface.md §4).
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
};

struct OrientationReport
{
  Index Components = 0;          // connected pieces of the neighbour graph
  Index FlippedComponents = 0;   // turned as a whole (outward or to the viewpoint)
  Index Ambiguous = 0;           // valid points with Confidence < 0.5
};

/// Orients field.Normals in place; `grid` is the one the field was estimated on (the propagation runs in its
/// Morton order, so that graph neighbours are near in memory). confidence gets one value per point (0 where
/// the normal is invalid).
OrientationReport OrientNormals(const NeighborGrid& grid, NormalField& field, const OrientationOptions& options,
  std::vector<double>& confidence);

} // namespace meshfree

#endif
