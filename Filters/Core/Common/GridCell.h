// Cell arithmetic of NeighborGrid as MESHFREE_HD functions: the grid's build and queries use them, and so does
// code that reproduces the grid on the CUDA device (cuda/SPHDevice.cu), which must assign every point to the same
// cell and visit the same cells.
#ifndef MeshFree_Common_GridCell_h
#define MeshFree_Common_GridCell_h

#include "Common/HostDevice.h"

#include <cmath>
#include <cstdint>

namespace meshfree
{

/// The order of the points a neighbour query returns, the same on the CPU and the device: ascending squared
/// distance d2; points at the same distance by position (x, then y, then z ascending), so that which of several
/// equidistant points is taken (the k-th nearest of a lattice point) and the order of the sums over them do not
/// depend on the input's order; exact duplicates (equal coordinates) by original index `id`, the only rule left
/// that does (equal positions: it matters only when coincident points carry different values).
template <class Id>
MESHFREE_HD inline bool GridPointBefore(const double* p, Id id, const double* q, Id qid)
{
  if (p[0] != q[0])
  {
    return p[0] < q[0];
  }
  if (p[1] != q[1])
  {
    return p[1] < q[1];
  }
  if (p[2] != q[2])
  {
    return p[2] < q[2];
  }
  return id < qid;
}

/// (d2, p, id) before (e2, q, qid) in the neighbour order (see GridPointBefore).
template <class Id>
MESHFREE_HD inline bool GridNeighborBefore(double d2, const double* p, Id id, double e2, const double* q, Id qid)
{
  return d2 < e2 || (d2 == e2 && GridPointBefore(p, id, q, qid));
}

/// Cell coordinate, along one axis, of a point at `rel` from the grid's origin, clamped into [0, dim).
MESHFREE_HD inline std::int64_t GridAxisCell(double rel, double inverseSize, std::int64_t dim)
{
  const double t = rel * inverseSize;
  if (!(t > 0.0))
  {
    return 0;
  }
  return t >= static_cast<double>(dim - 1) ? dim - 1 : static_cast<std::int64_t>(t);
}

/// The margin a radius query adds to its reach: it absorbs the rounding of the cell assignment and of the
/// query's relative coordinates rel (cell edge `size`, the points' extents `extent`).
MESHFREE_HD inline double GridGapMargin(const double rel[3], double size, const double extent[3])
{
  double scale = 0.0;
  const double values[6] = { fabs(rel[0]), fabs(rel[1]), fabs(rel[2]), extent[0], extent[1], extent[2] };
  for (int k = 0; k < 6; ++k)
  {
    scale = scale < values[k] ? values[k] : scale;
  }
  return 1e-9 * size + 1e-13 * scale;
}

/// The cells [first, last] along one axis that a radius query at rel (with `margin`) may reach; false when none.
MESHFREE_HD inline bool GridAxisReach(double rel, double radius, double margin, double inverseSize, std::int64_t dim,
  std::int64_t* first, std::int64_t* last)
{
  const double top = static_cast<double>(dim - 1);
  const double low = floor((rel - radius - margin) * inverseSize);
  const double high = floor((rel + radius + margin) * inverseSize);
  if (low > top || high < 0.0)
  {
    return false;
  }
  *first = low > 0.0 ? static_cast<std::int64_t>(low) : 0;
  *last = high < top ? static_cast<std::int64_t>(high) : dim - 1;
  return true;
}

/// A NeighborGrid as plain data, for code that walks its cells on the CUDA device: the geometry, the sorted
/// coordinates, the sorted order (original index of each sorted position) and the dense cell ranges, with
/// 32-bit positions (fewer than 2^31 points).
struct GridCellRange32
{
  std::int32_t Begin;
  std::int32_t End;
};

struct GridCells
{
  double Origin[3];
  double Extent[3];
  double Size;
  double Inverse;
  std::int64_t Dims[3];
  const double* Sorted;
  const std::int32_t* Order;
  const GridCellRange32* Cells;
  std::int64_t Count; ///< points; 0: an empty grid (no query finds anything)
};

/// Calls visit(s) for the sorted positions s of the points in the cells a radius query at x may reach
/// (NeighborGrid's reach, without its pruning of cells that hold no point within the radius), cells in (z, y, x)
/// order and the points of a cell in sorted order: among them, the points within the radius come in the order
/// NeighborGrid's radius queries and rows list them. The caller filters by distance.
template <class Visit>
MESHFREE_HD void GridForEachCandidate(const GridCells& g, const double* x, double radius, Visit&& visit)
{
  if (g.Count == 0)
  {
    return;
  }
  const double rel[3] = { x[0] - g.Origin[0], x[1] - g.Origin[1], x[2] - g.Origin[2] };
  const double margin = GridGapMargin(rel, g.Size, g.Extent);
  std::int64_t first[3], last[3];
  for (int a = 0; a < 3; ++a)
  {
    if (!GridAxisReach(rel[a], radius, margin, g.Inverse, g.Dims[a], first + a, last + a))
    {
      return;
    }
  }
  for (std::int64_t k = first[2]; k <= last[2]; ++k)
  {
    for (std::int64_t j = first[1]; j <= last[1]; ++j)
    {
      const GridCellRange32* row = g.Cells + g.Dims[0] * (j + g.Dims[1] * k);
      for (std::int64_t i = first[0]; i <= last[0]; ++i)
      {
        const GridCellRange32 cell = row[i];
        for (std::int32_t s = cell.Begin; s < cell.End; ++s)
        {
          visit(s);
        }
      }
    }
  }
}

} // namespace meshfree

#endif
