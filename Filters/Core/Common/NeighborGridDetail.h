// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core, private to Common/NeighborGrid*.cxx: what the grid's build, radius and k-nearest files share
// (constants, the neighbour order on sorted positions, the heap of candidates, the distance filter entry and
// the cell visitors that both kinds of query use).
#ifndef meshfree_NeighborGridDetail_h
#define meshfree_NeighborGridDetail_h

#include "Common/GridCell.h"
#include "Common/NeighborGrid.h"

#include <atomic>
#include <cmath>
#include <limits>

#if defined(__GNUC__)
#define MESHFREE_GRID_PREFETCH(address) __builtin_prefetch(address)
#else
#define MESHFREE_GRID_PREFETCH(address) ((void)0)
#endif

namespace meshfree
{
namespace grid_detail
{
inline constexpr Index MaxCellsPerAxis = Index(1) << 21;
inline constexpr Index ParallelThreshold = 16384; // smaller clouds are built on one thread
inline constexpr double Infinity = std::numeric_limits<double>::infinity();
inline constexpr double Pi = 3.14159265358979323846;
inline constexpr double FarCell = 1099511627776.0; // 2^40: query cell coordinates are clamped to +-this

inline bool IsFinite3(const double* p)
{
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

/// The neighbour order of Common/GridCell.h (distance, then x, y, z, then original index) on sorted positions:
/// (d, s) before (e, t). Only equal distances read the coordinates.
struct PositionOrder
{
  const double* Xyz;
  const Index* Order;

  bool operator()(double d, Index s, double e, Index t) const
  {
    return d < e || (d == e && GridPointBefore(this->Xyz + 3 * s, this->Order[s], this->Xyz + 3 * t, this->Order[t]));
  }
};

/// Max-heap on (dist2, ids) pairs (ids: sorted positions), largest in the neighbour order at the root.
template <class Less>
inline void SiftDown(double* dist2, Index* ids, Index root, Index count, const Less& before)
{
  const double d = dist2[root];
  const Index id = ids[root];
  for (;;)
  {
    Index child = 2 * root + 1;
    if (child >= count)
    {
      break;
    }
    if (child + 1 < count && before(dist2[child], ids[child], dist2[child + 1], ids[child + 1]))
    {
      ++child;
    }
    if (!before(d, id, dist2[child], ids[child]))
    {
      break;
    }
    dist2[root] = dist2[child];
    ids[root] = ids[child];
    root = child;
  }
  dist2[root] = d;
  ids[root] = id;
}

template <class Less>
inline void SiftUp(double* dist2, Index* ids, Index node, const Less& before)
{
  const double d = dist2[node];
  const Index id = ids[node];
  while (node > 0)
  {
    const Index parent = (node - 1) / 2;
    if (!before(dist2[parent], ids[parent], d, id))
    {
      break;
    }
    dist2[node] = dist2[parent];
    ids[node] = ids[parent];
    node = parent;
  }
  dist2[node] = d;
  ids[node] = id;
}

/// Turns a max-heap into an array sorted ascending in the neighbour order.
template <class Less>
inline void SortHeap(double* dist2, Index* ids, Index count, const Less& less)
{
  for (Index end = count - 1; end > 0; --end)
  {
    std::swap(dist2[0], dist2[end]);
    std::swap(ids[0], ids[end]);
    SiftDown(dist2, ids, 0, end, less);
  }
}

// ------------------------------------------------------------------------------ distance filters
// Filter(): for the sorted positions s in the given ranges, writes (squared distance to x, s) of the points
// with squared distance <= cut to dist2[] and pos[], and returns their number. The outputs need room for
// the ranges' total size + 8 entries; dist2 may be null (positions only). Distances are (dx * dx + dy * dy)
// + dz * dz in IEEE double precision, never fused into FMAs, in every variant: results are bit-identical
// whichever one runs (scalar, AVX2, AVX-512: Common/NeighborGridFilter.cxx).
using CellRange = NeighborGrid::CellRange;
using FilterFunction = int (*)(const double*, const CellRange*, int, const double*, double, double*, Index*);
/// The variant in use (NeighborGrid::SetVectorized).
extern std::atomic<FilterFunction> ActiveFilter;

inline int Filter(const double* xyz, const CellRange* ranges, int rangeCount, const double x[3], double cut,
  double* dist2, Index* pos)
{
  return ActiveFilter.load(std::memory_order_relaxed)(xyz, ranges, rangeCount, x, cut, dist2, pos);
}

/// Lower bounds on the distance from a query to the cells of the grid, per axis. The margin absorbs the
/// rounding of cell assignment and of the query's relative coordinates, so that a cell is never pruned
/// while holding a point at the pruning distance.
struct CellGaps
{
  const double* Rel;
  const Index* QueryCell;
  double Size;
  double Margin;

  double Squared(int axis, Index c) const
  {
    double gap = 0.0;
    if (c < this->QueryCell[axis])
    {
      gap = this->Rel[axis] - static_cast<double>(c + 1) * this->Size;
    }
    else if (c > this->QueryCell[axis])
    {
      gap = static_cast<double>(c) * this->Size - this->Rel[axis];
    }
    gap -= this->Margin;
    return gap > 0.0 ? gap * gap : 0.0;
  }
};

inline double GapMargin(const double rel[3], double size, const double extent[3])
{
  return GridGapMargin(rel, size, extent);
}
} // namespace grid_detail

/// Calls visit(range) for every non-empty cell that may hold points within `radius` of the query (the
/// cells of the box around it, less those whose box is farther); stops when visit returns false.
template <class Visit>
inline void NeighborGrid::VisitCells(const double rel[3], const Index cq[3], double radius, Visit&& visit) const
{
  const grid_detail::CellGaps gaps{ rel, cq, this->Size, grid_detail::GapMargin(rel, this->Size, this->Extent) };
  const double r2 = radius * radius;
  Index first[3], last[3];
  for (int a = 0; a < 3; ++a)
  {
    if (!GridAxisReach(rel[a], radius, gaps.Margin, this->InverseSize, this->GridDims[a], first + a, last + a))
    {
      return;
    }
  }
  const CellRange* cells = this->CellRanges.data();
  const Index nx = this->GridDims[0], ny = this->GridDims[1];
  double rowGaps[16]; // squared x gaps of the cells of a row, when the rows are short
  const bool shortRows = last[0] - first[0] < 16;
  for (Index i = first[0]; shortRows && i <= last[0]; ++i)
  {
    rowGaps[i - first[0]] = gaps.Squared(0, i);
  }
  for (Index k = first[2]; k <= last[2]; ++k)
  {
    const double gz = gaps.Squared(2, k);
    if (gz > r2)
    {
      continue;
    }
    for (Index j = first[1]; j <= last[1]; ++j)
    {
      const double gyz = gz + gaps.Squared(1, j);
      if (gyz > r2)
      {
        continue;
      }
      const CellRange* row = cells + nx * (j + ny * k);
      for (Index i = first[0]; i <= last[0]; ++i)
      {
        if (row[i].End > row[i].Begin &&
          gyz + (shortRows ? rowGaps[i - first[0]] : gaps.Squared(0, i)) <= r2 && !visit(row[i]))
        {
          return;
        }
      }
    }
  }
}

template <class Room, class Accept>
inline void NeighborGrid::FilterRadiusTo(const double x[3], double radius, Room&& room, Accept&& accept) const
{
  double rel[3];
  Index cq[3];
  if (!(radius >= 0.0) || !this->CellCoordinate(x, rel, cq))
  {
    return;
  }
  const double r2 = radius * radius;
  const double* xyz = this->Sorted.data();
  // Cell ranges are batched (neighbouring ranges merged) so that one filter call handles many cells.
  constexpr int MaxRanges = 32;
  CellRange ranges[MaxRanges];
  int rangeCount = 0;
  Index points = 0;
  auto flush = [&] {
    if (rangeCount > 0)
    {
      double* dist2 = nullptr;
      Index* pos = nullptr;
      room(points, dist2, pos);
      const int found = grid_detail::Filter(xyz, ranges, rangeCount, x, r2, dist2, pos);
      accept(found, dist2, pos);
    }
    rangeCount = 0;
    points = 0;
  };
  this->VisitCells(rel, cq, radius, [&](const CellRange& cell) {
    for (Index b = cell.Begin; b < cell.End;)
    {
      if (points == FilterBatch)
      {
        flush();
      }
      const Index e = std::min(cell.End, b + (FilterBatch - points));
      if (rangeCount > 0 && ranges[rangeCount - 1].End == b)
      {
        ranges[rangeCount - 1].End = e;
      }
      else
      {
        if (rangeCount == MaxRanges)
        {
          flush();
        }
        ranges[rangeCount++] = CellRange{ b, e };
      }
      points += e - b;
      b = e;
    }
    return true;
  });
  flush();
}

template <class Accept>
inline void NeighborGrid::FilterRadius(const double x[3], double radius, Accept&& accept) const
{
  double dist2[FilterBatch + 8];
  Index pos[FilterBatch + 8];
  this->FilterRadiusTo(
    x, radius,
    [&](Index, double*& d2, Index*& p) {
      d2 = dist2;
      p = pos;
    },
    accept);
}
} // namespace meshfree

#endif
