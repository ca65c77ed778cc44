// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class meshfree::NeighborGrid
 * @brief The one spatial index of MeshFree: a uniform cell grid whose points are sorted by cell in
 *        Z-order (Morton order), with radius and k-nearest-neighbour queries at arbitrary positions.
 *
 * Build() copies the valid points (finite x, y and z) into one packed array (interleaved x, y, z) sorted
 * by the Morton code of their cell and, inside a cell, by position (x, then y, then z; exact duplicates by
 * original index), keeps the permutation back to the caller's numbering, and records for every cell (dense
 * array, indexed by cell) the range of sorted positions it holds. Queries stream through contiguous memory
 * cell by cell; consecutive sorted points are spatial neighbours, so loops over SortedOrder() are cache
 * friendly too.
 *
 * Order independence: the layout (hence the order in which radius queries list points and loops over the
 * sorted points sum) depends only on the set of positions, not on their input order; the k nearest and
 * every sorted result break distance ties by position (NeighborBefore()). Permuting the input changes only
 * which of several exactly coincident points comes first (by original index). SetCellsByPosition(false)
 * keeps the points of a cell in original index order instead (the SPH integrator's grid, whose particle
 * order is the solver's own and which the CUDA integrator rebuilds by a stable sort of the cell keys).
 *
 * Build is parallel (Common/Parallel.h), O(n): one pass for the bounds, one for the cell keys, an LSD radix sort of
 * packed (cell key, index) words, a gather of the coordinates, a pass for the cell ranges and one sorting each
 * cell's few points by position.
 *
 * Geometry
 * - Cells are cubes of edge CellSize() anchored at the minimum of the valid points' bounds; cell
 *   coordinates are computed relative to that minimum, so clouds far from the origin lose no precision.
 * - CellSize() is chosen for about GetPointsPerCell() points per cell (default 8) when Build() is given
 *   cellSize <= 0. An axis whose extent is smaller than a cell gets a single layer of cells, so flat (2D)
 *   and collinear clouds are handled automatically, and all-identical points end up in one cell.
 * - The number of cells is bounded by about 4 n (and 2^21 per axis); a cellSize that would need more
 *   cells is enlarged, and CellSize() reports the size actually used.
 * - Points with a NaN or infinite coordinate are left out of the structure; they are counted
 *   (NumberOfInvalidPoints()) and listed (InvalidPointIds()).
 * - Caveat of every uniform grid: a few far outliers make the bounds large and the cells coarse.
 *
 * Queries (all const, thread-safe, and allocation-free once the caller's buffers have grown)
 * - Distances are Euclidean in the caller's coordinates: d2 = (px-x)^2 + (py-y)^2 + (pz-z)^2, summed in
 *   that order in double precision (no FMA), so they equal a plain brute-force loop's bit for bit.
 * - FindWithinRadius() returns every valid point with d2 <= radius^2 (closed ball), unsorted (in cell
 *   order; FindWithinRadiusSorted() sorts them). A point of the cloud finds itself.
 * - FindKNearest() returns the k valid points that come first in the neighbour order (d2, then x, y, z,
 *   then original index: NeighborBefore()), sorted that way: which of several equidistant points is taken
 *   depends on their positions only, never on the input's order. It first guesses a radius from the
 *   local density (the k nearest lie within it when it holds at least k points) and filters the cells
 *   in reach with a vector kernel; when the guess fails (sparse or very uneven regions, queries far from
 *   the cloud, large k) it falls back to an exact search over shells of cells around the query, pruning
 *   every cell whose box is farther than the current k-th distance.
 * - A query position with a NaN or infinite coordinate, a NaN or negative radius, k <= 0 or an empty
 *   structure return nothing.
 *
 * Reference: the cell-sorted layout follows CompactNSearch (Bender et al., SPlisHSPlasH) and
 * vtkStaticPointLocator.
 */
#ifndef meshfree_NeighborGrid_h
#define meshfree_NeighborGrid_h

#include "Common/GridCell.h"
#include "Common/LargeArrays.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace meshfree
{
using Index = std::int64_t;

class NeighborGrid
{
public:
  /// Range [Begin, End) of sorted positions held by one cell.
  struct CellRange
  {
    Index Begin;
    Index End;
  };

  ///@{
  /// Builds the structure over n points given as interleaved x, y, z (stride 3). cellSize <= 0 picks
  /// the cell size automatically (about PointsPerCell points per cell on average). Returns false only
  /// when no point is valid; the structure is still usable then, and every query returns nothing.
  bool Build(const double* xyz, Index n, double cellSize = 0.0);
  /// Average occupancy targeted by the automatic cell size (default 8; used by the next Build()).
  void SetPointsPerCell(double pointsPerCell);
  double GetPointsPerCell() const { return this->PointsPerCell; }
  /// Whether the next Build() sorts the points of each cell by position (default) or keeps them in original
  /// index order (see the class comment).
  void SetCellsByPosition(bool byPosition) { this->CellsByPosition = byPosition; }
  /// A frame for the next Build()s: cells laid over `bounds` (xmin, xmax, ymin, ymax, zmin, zmax, holding every
  /// point given) and sized for `validPoints`, instead of the points' own bounds and count. A grid over part of a
  /// cloud (a process' piece and halo) framed by the whole cloud's bounds and count has the whole cloud's cells
  /// and Morton order, so its queries list the points they find exactly as the whole cloud's grid does.
  /// ClearFrame() returns to the points' own; GetFrame() gives the last Build()'s (bounds and valid points).
  void SetFrame(const double bounds[6], Index validPoints);
  void ClearFrame() { this->Framed = false; }
  void GetFrame(double bounds[6], Index& validPoints) const;
  bool GetCellsByPosition() const { return this->CellsByPosition; }
  ///@}

  /// The neighbour order of every query: (d2, p, id) comes before (e2, q, qid) when d2 < e2, or the distances
  /// are equal and p comes first by (x, y, z), or the positions are equal too and id < qid. Callers that
  /// select or sort neighbours themselves (e.g. among the points of a radius query) use it to agree with
  /// FindKNearest() and stay independent of the input's order. p and q are the points' coordinates.
  static bool NeighborBefore(double d2, const double* p, Index id, double e2, const double* q, Index qid)
  {
    return GridNeighborBefore(d2, p, id, e2, q, qid);
  }

  /// Distances are filtered with an AVX-512 or AVX2 kernel when the CPU has one (chosen at run time; results
  /// are bit-identical to the portable code). SetVectorized(false) forces the portable code for every grid,
  /// e.g. to compare the two; call it while no query runs. Returns whether the vector kernel is in use.
  static bool SetVectorized(bool enable);

  ///@{
  /// Sizes of the last Build(): NumberOfPoints() is n, the others split it into finite points and points
  /// with a NaN or infinite coordinate (whose original indices InvalidPointIds() lists, ascending).
  Index NumberOfPoints() const { return this->NumberOfInputPoints; }
  Index NumberOfValidPoints() const { return static_cast<Index>(this->Order.size()); }
  Index NumberOfInvalidPoints() const { return static_cast<Index>(this->InvalidIds.size()); }
  const std::vector<Index>& InvalidPointIds() const { return this->InvalidIds; }
  ///@}

  ///@{
  /// Dimension(): the number of axes along which the valid points have a non-zero extent (3 for a
  /// volume, 2 for a flat cloud, 1 for a cloud on a line parallel to an axis, 0 for one position).
  /// IsAxisFlat(a): whether axis a (0, 1, 2) has zero extent (relative to the largest one, 1e-10).
  int Dimension() const;
  bool IsAxisFlat(int axis) const;
  double CellSize() const { return this->Size; }
  /// Number of cells along x, y and z.
  void GetGridDimensions(Index dims[3]) const;
  /// Bounds (xmin, xmax, ymin, ymax, zmin, zmax) of the valid points; all zero when there are none.
  void GetBounds(double bounds[6]) const;
  ///@}

  /// All valid points within `radius` (distance <= radius) of x, an arbitrary position: their original
  /// indices and, if dist2 is given, their squared distances. Clears the outputs first; the order is the
  /// Morton order of the cells (unsorted by distance).
  void FindWithinRadius(const double x[3], double radius, std::vector<Index>& ids,
    std::vector<double>* dist2 = nullptr) const;
  /// As FindWithinRadius(), but gives sorted positions (indices into SortedPoints()/SortedOrder()) instead
  /// of original indices, and always the squared distances: callers that keep their per-point data in the
  /// sorted order read it contiguously.
  void FindWithinRadiusPositions(
    const double x[3], double radius, std::vector<Index>& positions, std::vector<double>& dist2) const;
  /// As FindWithinRadiusPositions(), filtered straight into the buffers (resized to the count; no copy through a
  /// scratch buffer, no fill when they grow).
  void FindWithinRadiusPositions(const double x[3], double radius, detail::Buffer<Index>& positions,
    detail::Buffer<double>& dist2) const;
  /// As FindWithinRadius(), sorted ascending in the neighbour order (NeighborBefore()).
  void FindWithinRadiusSorted(
    const double x[3], double radius, std::vector<Index>& ids, std::vector<double>& dist2) const;
  /// Number of valid points within `radius` of x (distance <= radius), without collecting them.
  Index CountWithinRadius(const double x[3], double radius) const;

  /// The k nearest valid points to x (all valid points when there are fewer than k), the first in the
  /// neighbour order (NeighborBefore()) and sorted that way. ids and dist2 must hold min(k,
  /// NumberOfValidPoints()) entries. Returns the number found.
  int FindKNearest(const double x[3], int k, Index* ids, double* dist2) const;
  /// As above; ids and dist2 are resized to the number found (their capacity is kept).
  int FindKNearest(const double x[3], int k, std::vector<Index>& ids, std::vector<double>& dist2) const;

  /// The k nearest neighbours of every input point (itself included, at distance 0), computed in
  /// parallel in Morton order, each query's radius guess taken from its predecessor's k-th distance.
  /// Row i (ids[i*k .. i*k+k), same for dist2) belongs to input point i; rows of invalid points, and the
  /// tail of rows when there are fewer than k valid points, hold -1 and +inf. Same results as
  /// FindKNearest() at each point.
  void FindKNearestForAllPoints(int k, std::vector<Index>& ids, std::vector<double>& dist2) const;

  /// The radius neighbours of every valid point at once, computed cell by cell in parallel: the candidate
  /// cells of a cell are gathered once into a contiguous buffer shared by all its points. Row i (ids
  /// [offsets[i], offsets[i + 1])) belongs to input point i and holds the original indices of the valid
  /// points with d2 <= radius^2, in the order FindWithinRadius() at point i returns them, without point i
  /// itself when excludeSelf is set. offsets gets NumberOfPoints() + 1 entries; rows of invalid points are
  /// empty, and a NaN or negative radius gives empty rows. Indices are 32-bit: NumberOfPoints() must be
  /// below 2^31 (otherwise every row is empty and false is returned).
  bool FindWithinRadiusForAllPoints(
    double radius, std::vector<Index>& offsets, std::vector<std::int32_t>& ids, bool excludeSelf = false) const;

  /// Exact duplicates: representative[i] (NumberOfPoints() entries) is the smallest original index of the
  /// valid points with exactly the same coordinates as point i (i itself when it has none; -1 for invalid
  /// points). Returns how many valid points are duplicates of a smaller index. O(n), parallel.
  Index FindDuplicates(std::vector<Index>& representative) const;

  ///@{
  /// The Morton-sorted layout. SortedOrder()[s] is the original index of the point at sorted position s
  /// (valid points only; cells in Morton order, the points of a cell by position or, with
  /// SetCellsByPosition(false), by original index); SortedPoints() holds their coordinates, interleaved x,
  /// y, z, in that order.
  /// Cells(): the sorted-position range of each cell (Begin == End when empty), indexed by
  /// i + nx * (j + ny * k) with GetGridDimensions() (nx, ny, nz).
  const std::vector<Index>& SortedOrder() const { return this->Order; }
  const double* SortedPoints() const { return this->Sorted.data(); }
  const CellRange* Cells() const { return this->CellRanges.data(); }
  ///@}
  /// Lets go of Build()'s sort scratch (16 bytes per point, kept so that a grid rebuilt every step, as SPH's, does
  /// not reallocate): for a grid built once. The grid stays as it is; a later Build() allocates it again.
  void ReleaseBuildScratch();

  ///@{
  /// The geometry Build() uses, for code that reproduces the grid elsewhere (the CUDA SPH integrator builds its
  /// cell keys on the device from bounds reduced there). ChooseCells: the cell edge, its inverse and the cells per
  /// axis for valid points whose bounds have the given extents (max - min per axis), as Build(xyz, n, cellSize)
  /// with PointsPerCell pointsPerCell picks them. MortonTables: spread[a][c] is the key contribution of cell
  /// coordinate c along axis a (a cell's sort key is spread[0][i] | spread[1][j] | spread[2][k]); returns the
  /// number of key bits. A point's cell along an axis is GridAxisCell (Common/GridCell.h) of its coordinate less
  /// the minimum of the bounds.
  static void ChooseCells(const double extent[3], double cellSize, Index validPoints, double pointsPerCell,
    double& cellEdge, double& inverseEdge, Index dims[3]);
  static int MortonTables(const Index dims[3], std::vector<std::uint64_t> spread[3]);
  ///@}

private:
  int GridDimension() const; // axes with more than one cell
  bool CellCoordinate(const double x[3], double rel[3], Index cell[3]) const;
  void ChooseGrid(double cellSize, Index validPoints);
  template <class Visit>
  void VisitCells(const double rel[3], const Index cell[3], double radius, Visit&& visit) const;
  /// The radius filter: batches of at most FilterBatch candidates, each filtered into the buffers room(candidates,
  /// dist2, pos) points to (room for candidates + 8 entries), then accept(found, dist2, pos).
  static constexpr Index FilterBatch = 248;
  template <class Room, class Accept>
  void FilterRadiusTo(const double x[3], double radius, Room&& room, Accept&& accept) const;
  template <class Accept>
  void FilterRadius(const double x[3], double radius, Accept&& accept) const;
  int NearestWithinEstimate(const double x[3], const double rel[3], const Index cell[3], int k,
    double cut, Index* ids, double* dist2) const;
  int NearestExact(const double x[3], const double rel[3], const Index cell[3], int k, Index* ids,
    double* dist2) const;
  template <class Best>
  int SearchNearest(const double x[3], const double rel[3], const Index cell[3], Best& best) const;

  double PointsPerCell = 8.0;
  bool CellsByPosition = true;
  bool Framed = false;
  double FrameBounds[6] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 };
  Index FramePoints = 0;
  Index FrameUsedPoints = 0; // the valid points the last Build() sized its cells for, and its bounds
  double FrameUsedBounds[6] = { 1.0, 0.0, 1.0, 0.0, 1.0, 0.0 };
  Index NumberOfInputPoints = 0;
  double Origin[3] = { 0.0, 0.0, 0.0 }; // minimum of the valid points' bounds
  double Extent[3] = { 0.0, 0.0, 0.0 };
  double Size = 1.0;
  double InverseSize = 1.0;
  Index GridDims[3] = { 1, 1, 1 };
  std::vector<Index> Order;
  std::vector<Index> InvalidIds;
  detail::Buffer<double> Sorted;
  detail::Buffer<CellRange> CellRanges;
  detail::Buffer<std::uint64_t> CellKeys; // build scratch (sort keys), kept so that rebuilds do not
  detail::Buffer<std::uint64_t> SortScratch; // reallocate
};
} // namespace meshfree

#endif
