// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class meshfree::SparseContour
 * @brief Triangulates the zero set of an ImplicitField on a lattice, evaluating the field only in the cells
 *        the surface passes through (and their corners): cost grows with the surface's area, not with the
 *        volume of its bounding box.
 *
 * Lattice: corners origin + (i, j, k) * CellSize, 0 <= i, j, k < 2^21. Storage is sparse by blocks of 8^3
 * cells (splashsurf's idea, research/surface.md §1 "Contouring"): a block owns the 512 corners of its local
 * range and is allocated only when a cell that needs one of them is activated; blocks are found through a
 * hash map and hold dense arrays inside.
 *
 * Continuation: the caller gives seed cells (those holding data points). Every active cell has its 8 corners
 * evaluated; a cell whose 4 corners on a face do not all have the same sign is crossed by the surface through
 * that face, so the cell beyond the face is activated in the next round. Rounds stop when no crossing face
 * leads out of the active set: then every polygon edge on a face is matched by the neighbour's, and the mesh
 * is closed wherever the field is defined. Cells with an undefined corner produce nothing (an open boundary
 * there, counted by the caller).
 *
 * Polygons: the crossing points of a cell's edges are joined face by face into closed loops and each loop is
 * fanned into triangles (no case table). A face whose negative corners lie on one diagonal is ambiguous; it is
 * decided by the asymptotic decider of the bilinear interpolant on the face (Nielson & Hamann 1991): the
 * negative corners are joined when n0 n1 > p0 p1 (n the negative values, p the positive ones), an expression
 * both cells sharing the face evaluate to the same bits, so the two sides always agree. Zero counts as
 * positive (outside). Triangles are oriented with their normal towards the positive side.
 *
 * Crack-free and deterministic: a corner's value is computed once, by its owner block; a vertex (one per
 * crossing edge, at the linear zero of the edge's two corner values, kept at least ClampFraction of the edge
 * from either end so no triangle degenerates) is created once, by the block owning the edge's lower corner;
 * blocks and cells are processed in key order, so the output does not depend on the thread count.
 *
 * Distributed (a Distribution d): each process activates only the cells whose centre it owns
 * (Distribution::OwnsPosition); a crossed face that leads to another process' cell hands that cell over at the
 * start of the next round (every process gathers the handed-over keys and keeps its own), and the rounds go on
 * until no process has a fresh cell. The active set, and the round in which each cell joins it, are the serial
 * run's; a corner shared with another process' cell is evaluated on both sides from the same neighbours, to the
 * same bits, so the processes' meshes meet without cracks: their union is the serial mesh (seam vertices are
 * the same points on both sides).
 */
#ifndef meshfree_SparseContour_h
#define meshfree_SparseContour_h

#include "Common/Distribution.h"
#include "Common/NeighborGrid.h"
#include "Common/Progress.h"
#include "Surface/ImplicitField.h"

#include <cstdint>
#include <vector>

namespace meshfree
{

struct ContourOptions
{
  double CellSize = 1.0;
  double Origin[3] = { 0.0, 0.0, 0.0 }; // position of lattice corner (0, 0, 0)
  int MaximumRounds = 512;               // continuation rounds (each grows the active set by one layer)
  double ClampFraction = 1e-4;           // vertices stay this fraction of an edge away from its corners
};

/// A triangle mesh: points (x, y, z interleaved) and triangles (3 point indices each).
struct TriangleMesh
{
  std::vector<double> Points;
  std::vector<Index> Triangles;
  Index NumberOfPoints() const { return static_cast<Index>(this->Points.size() / 3); }
  Index NumberOfTriangles() const { return static_cast<Index>(this->Triangles.size() / 3); }
};

struct ContourReport
{
  Index Blocks = 0;
  Index ActiveCells = 0;
  Index EvaluatedCorners = 0;
  Index UndefinedCorners = 0;
  int Rounds = 0;
  bool RoundLimitReached = false;
  bool LatticeEdgeReached = false; // growth stopped at the lattice's range
  bool Aborted = false;
};

class SparseContour
{
public:
  /// Largest lattice coordinate a corner may have.
  static constexpr Index kMaximumCoordinate = (Index(1) << 21) - 1;

  /// Packs a cell's lattice coordinates (each in 0..kMaximumCoordinate) into one key.
  static std::uint64_t CellKey(Index i, Index j, Index k);
  /// Lattice coordinates of the cell holding x; false when x is outside the lattice's range or not finite.
  static bool CellOf(const double x[3], const ContourOptions& options, Index cell[3]);

  /// Contours `field` from the seed cells (keys from CellKey(); duplicates allowed). The mesh is replaced.
  /// Returns false when aborted (the mesh is then empty) or when the options are invalid. Distributed (d, see
  /// above; collective): seeds may be any process' cells, the mesh is this process' cells' triangles.
  bool Run(const ImplicitField& field, std::vector<std::uint64_t> seeds, const ContourOptions& options,
    TriangleMesh& mesh, ContourReport& report, const ProgressCallback& progress = ProgressCallback(),
    const Distribution* d = nullptr);
};

/// The triangles of one cell, as cell edges (their crossing points) and loop centres.
struct CellPolygons
{
  static constexpr int LoopCentre = 12; // vertex LoopCentre + l: the centroid of loop l's crossing points
  int TriangleCount = 0;
  int Triangles[36];
  int LoopCount = 0;
  int LoopLength[4];
  int LoopEdges[4][12];
};

/**
 * Triangulates one cell: corner c (bit 0: +x, bit 1: +y, bit 2: +z) has value v[c]. Each loop of crossing
 * points is fanned from a crossing point whose chords run through the cell's inside (never along a face, where
 * the neighbour's triangles lie); loops without such an apex (long loops around a tunnel) are fanned from
 * their centroid instead. Returns the number of triangles. Exposed for tests.
 */
int PolygonizeCell(const double v[8], CellPolygons& polygons);
/// The two corners of cell edge e (0..11), lower first; the edge runs along axis e / 4.
void CellEdgeCorners(int e, int& lower, int& upper);

} // namespace meshfree

#endif
