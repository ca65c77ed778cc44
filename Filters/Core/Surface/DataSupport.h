// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief How well the samples support each part of a reconstructed surface: the distance from every vertex to
 *        the nearest sample, the trimming of an open surface to its data's border, and the removal of pieces
 *        that no samples support (issue 23: "open data stay open, cleanly", "no stray pieces").
 *
 * - DistanceToData: per vertex, the distance to the nearest valid sample (0 on the data; it grows across a
 *   filled hole), so filled parts can be cut with a threshold, as Poisson users trim by density.
 * - TrimToData: an open surface keeps the triangles whose three vertices lie within their nearest sample's
 *   limit (SurfaceReconstruction.h: a few local spacings); the border then follows the data's border instead of
 *   running on for a fit's support past it (the fits extrapolate, and curl, wherever they still have enough
 *   neighbours).
 * - RemoveUnsupportedPieces: a connected piece of the mesh is kept when at least `minimumSamples` samples have
 *   their nearest vertex on it within their limit; fewer than a fit's neighbourhood cannot define a piece of
 *   surface (noise bubbles, shreds at a ragged border, a stray outlier's shell).
 */
#ifndef meshfree_DataSupport_h
#define meshfree_DataSupport_h

#include "Common/Distribution.h"
#include "Common/NeighborGrid.h"
#include "Surface/SparseContour.h"

#include <vector>

namespace meshfree
{

/// distance[v]: distance from vertex v to the nearest valid point of `grid`; nearest[v] its original index (-1
/// when the grid is empty, distance +inf).
/// Distributed (d, Common/Distribution.h; collective): the grid holds a process' points and halo; a vertex whose
/// nearest local point is farther than the local cloud is complete around it (Distribution::Complete) gets the
/// whole cloud's distance (the processes' own points searched for it) and nearest -1.
void DistanceToData(const NeighborGrid& grid, const std::vector<double>& vertices, std::vector<double>& distance,
  std::vector<Index>& nearest, const Distribution* d = nullptr);

/// Keeps the triangles with keep[t] != 0 and the vertices they use (in their order); every per-vertex array in
/// `attributes` (components per vertex given beside it) is compacted alike. Returns the triangles removed.
struct VertexAttribute
{
  std::vector<double>* Values;
  int Components;
};
Index KeepTriangles(TriangleMesh& mesh, const std::vector<unsigned char>& keep, const std::vector<VertexAttribute>& attributes);

/// Triangles to keep after trimming: those whose three vertices lie on the data. Vertex v (unit normal
/// normals[3 v]) lies on the data when distance[v] <= near[v], or when distance[v] <= limit[v] and the samples
/// within limit[v] surround it: the mean of their unit directions from v, projected on its tangent plane, is
/// shorter than OneSided (0 for samples all around; 2 / pi = 0.64 on the straight border of a uniform sampling,
/// towards 1 beyond it). Interior gaps of the sampling are kept, the fringe beyond the border is not. A gap the
/// limit bridges only part of the way (a stretch of vertices kept only as surrounded that borders a vertex off the
/// data) is opened back to the near limit, so the border runs within one local spacing of the samples instead of
/// up to the limit into the gap.
/// Distributed (d; collective): the mesh is a process' part (SparseContour.h); the stretches are the whole mesh's,
/// joined through the seam vertices within `band` (a lattice cell or more) of another process' region.
constexpr double OneSided = 0.6;
std::vector<unsigned char> TrimmedTriangles(const TriangleMesh& mesh, const std::vector<double>& normals,
  const NeighborGrid& grid, const std::vector<double>& distance, const std::vector<double>& near,
  const std::vector<double>& limit, const Distribution* d = nullptr, double band = 0.0);

/// Triangles to keep: those of pieces (connected through vertices) that at least `minimumSamples` samples
/// support (the best-supported piece is always kept). A sample (point s of `grid`, limit sampleLimit[s] in the grid's original order) supports the piece
/// of its nearest vertex when that vertex is within the limit. `pieces` and `removedPieces` receive the counts.
/// Distributed (d; collective): the mesh is a process' part of the whole (its lattice cells', SparseContour.h), the
/// grid its points and halo; pieces are the whole mesh's (joined across the processes through their seam
/// vertices, the same points on both sides), each own sample counts for the piece of its nearest vertex of the
/// whole mesh (the other processes' vertices near this process' region are gathered), and the counts and
/// decisions are the whole mesh's. The best-supported piece (ties: the one with the smallest vertex by (x, y, z))
/// is kept.
std::vector<unsigned char> SupportedPieces(const TriangleMesh& mesh, const NeighborGrid& grid,
  const std::vector<double>& sampleLimit, Index minimumSamples, Index& pieces, Index& removedPieces,
  const Distribution* d = nullptr);

/// Boundary edges (of one triangle) of the whole mesh. Distributed (d; collective): `mesh` is a process' part
/// (SparseContour.h); an edge on the seam between two parts is a boundary edge of both and of neither in the
/// whole: the parts' boundary edges within `band` (a lattice cell or more) of another process' region are gathered
/// and those found on two processes cancel. Every process gets the whole mesh's count.
Index BoundaryEdges(const TriangleMesh& mesh, double band, const Distribution* d = nullptr);

} // namespace meshfree

#endif
