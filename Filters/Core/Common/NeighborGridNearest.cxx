// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the neighbour grid's k-nearest queries (one point, all points): an estimate of the radius
// holding k points, then an exact search over the cells nearest first, ties in the neighbour order.
#include "Common/NeighborGrid.h"

#include "Common/NeighborGridDetail.h"
#include "Common/Parallel.h"

#include <algorithm>
#include <cmath>

namespace meshfree
{
using namespace grid_detail;
namespace
{
/// Radius of the ball holding `count` points at `density` points per unit of length^dimension.
double BallRadius(double count, double density, int dimension)
{
  const double measure = count / density; // 2r, pi r^2, 4/3 pi r^3
  return dimension == 1 ? 0.5 * measure
                        : (dimension == 2 ? std::sqrt(measure / Pi) : std::cbrt(measure * 0.75 / Pi));
}

/// Candidates of one k-nearest search (on the stack: no allocation in a query).
struct Candidates
{
  static constexpr int Capacity = 256;
  static constexpr int MaxRanges = 64;
  double Dist2[Capacity + 8];
  Index Ids[Capacity + 8]; // sorted positions
  double SortedDist2[Capacity];
  Index SortedIds[Capacity];
  int Bucket[Capacity];
  int Start[2 * Capacity + 1];
  int Count = 0;

  /// Sorts the first k candidates (0 <= Dist2 <= cut) in the neighbour order into SortedDist2/SortedIds: a
  /// counting sort into 2n buckets by Dist2 / cut (for points spread evenly in a ball, at most about 1.5
  /// per bucket on average), then an insertion sort that only fixes the order inside the buckets that
  /// hold the first k. Unlike a comparison sort of random keys (or a heap), few branches mispredict.
  void Sort(double cut, int k, const PositionOrder& before)
  {
    const int n = this->Count;
    const int buckets = 2 * n;
    std::fill(this->Start, this->Start + buckets + 1, 0);
    const double scale = cut > 0.0 && std::isfinite(cut) ? 1.0 / cut : 0.0;
    for (int i = 0; i < n; ++i)
    {
      const double u = std::min(1.0, this->Dist2[i] * scale); // (distance / cut radius)^2
      this->Bucket[i] = std::min(buckets - 1, static_cast<int>(u * buckets));
      ++this->Start[this->Bucket[i] + 1];
    }
    int limit = 0; // the end of the bucket holding the k-th candidate
    for (int b = 0; b < buckets; ++b)
    {
      this->Start[b + 1] += this->Start[b];
      limit = limit < k ? this->Start[b + 1] : limit;
    }
    for (int i = 0; i < n; ++i)
    {
      const int slot = this->Start[this->Bucket[i]]++;
      this->SortedDist2[slot] = this->Dist2[i];
      this->SortedIds[slot] = this->Ids[i];
    }
    for (int i = 1; i < limit; ++i)
    {
      const double d = this->SortedDist2[i];
      const Index id = this->SortedIds[i];
      int j = i;
      for (; j > 0 && before(d, id, this->SortedDist2[j - 1], this->SortedIds[j - 1]); --j)
      {
        this->SortedDist2[j] = this->SortedDist2[j - 1];
        this->SortedIds[j] = this->SortedIds[j - 1];
      }
      this->SortedDist2[j] = d;
      this->SortedIds[j] = id;
    }
  }
};

/// The best k candidates so far, kept sorted ascending in a small local array (small k: an insertion
/// moves a few entries, and no final sort is needed).
struct SortedBest
{
  static constexpr int Capacity = 48;
  struct Entry
  {
    double Dist2;
    Index Pos; // sorted position
  };
  Entry Best[Capacity];
  double* Dist2;
  Index* Ids;
  PositionOrder Before;
  int K;
  int Count = 0;
  double Worst = Infinity; // k-th squared distance once k candidates are known

  SortedBest(double* dist2, Index* ids, const PositionOrder& order, int k)
    : Dist2(dist2)
    , Ids(ids)
    , Before(order)
    , K(k)
  {
  }

  void Offer(double d2, Index s)
  {
    if (d2 > this->Worst)
    {
      return;
    }
    int slot = this->Count;
    if (slot == this->K)
    {
      if (d2 == this->Worst && !this->Before(d2, s, d2, this->Best[slot - 1].Pos))
      {
        return;
      }
      --slot;
    }
    else
    {
      ++this->Count;
    }
    for (; slot > 0 && this->Before(d2, s, this->Best[slot - 1].Dist2, this->Best[slot - 1].Pos); --slot)
    {
      this->Best[slot] = this->Best[slot - 1];
    }
    this->Best[slot] = Entry{ d2, s };
    if (this->Count == this->K)
    {
      this->Worst = this->Best[this->K - 1].Dist2;
    }
  }
  int Finish()
  {
    for (int i = 0; i < this->Count; ++i)
    {
      this->Dist2[i] = this->Best[i].Dist2;
      this->Ids[i] = this->Before.Order[this->Best[i].Pos];
    }
    return this->Count;
  }
};

/// The best k candidates so far in a max-heap (large k), sorted when the search ends.
struct HeapBest
{
  double* Dist2;
  Index* Ids; // sorted positions until Finish()
  PositionOrder Before;
  int K;
  int Count = 0;
  double Worst = Infinity;

  void Offer(double d2, Index s)
  {
    if (d2 > this->Worst)
    {
      return;
    }
    if (this->Count < this->K)
    {
      this->Dist2[this->Count] = d2;
      this->Ids[this->Count] = s;
      SiftUp(this->Dist2, this->Ids, this->Count++, this->Before);
    }
    else if (this->Before(d2, s, this->Dist2[0], this->Ids[0]))
    {
      this->Dist2[0] = d2;
      this->Ids[0] = s;
      SiftDown(this->Dist2, this->Ids, 0, this->K, this->Before);
    }
    if (this->Count == this->K)
    {
      this->Worst = this->Dist2[0];
    }
  }
  int Finish()
  {
    SortHeap(this->Dist2, this->Ids, this->Count, this->Before);
    for (int i = 0; i < this->Count; ++i)
    {
      this->Ids[i] = this->Before.Order[this->Ids[i]];
    }
    return this->Count;
  }
};

/// The 27 cells around the query's cell, nearest first for a query in the corner of its cell nearest
/// to the cells marked 1 (1: towards the query's nearer face, 2: away from it).
constexpr signed char NearFirstBlock[27][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 },
  { 1, 1, 0 }, { 1, 0, 1 }, { 0, 1, 1 }, { 1, 1, 1 }, { 2, 0, 0 }, { 0, 2, 0 }, { 0, 0, 2 }, { 1, 2, 0 },
  { 2, 1, 0 }, { 1, 0, 2 }, { 2, 0, 1 }, { 0, 1, 2 }, { 0, 2, 1 }, { 2, 1, 1 }, { 1, 2, 1 }, { 1, 1, 2 },
  { 2, 2, 0 }, { 2, 0, 2 }, { 0, 2, 2 }, { 2, 2, 1 }, { 2, 1, 2 }, { 1, 2, 2 }, { 2, 2, 2 } };
} // namespace

int NeighborGrid::NearestWithinEstimate(const double x[3], const double rel[3], const Index cq[3], int k,
  double cut, Index* ids, double* dist2) const
{
  const int dimension = this->GridDimension();
  const Index* dims = this->GridDims;
  if (dimension == 0 || k > Candidates::Capacity)
  {
    return -1;
  }
  if (!(cut > 0.0)) // estimate from the density of the (up to) 3 x 3 cells around the query's cell in z
  {
    Index points = 0, blockCells = 0;
    Index lo[3], hi[3];
    for (int a = 0; a < 3; ++a)
    {
      if (cq[a] < 0 || cq[a] >= dims[a])
      {
        return -1;
      }
      lo[a] = a == 2 ? cq[a] : std::max<Index>(0, cq[a] - 1);
      hi[a] = a == 2 ? cq[a] : std::min(dims[a] - 1, cq[a] + 1);
    }
    for (Index kz = lo[2]; kz <= hi[2]; ++kz)
    {
      for (Index jy = lo[1]; jy <= hi[1]; ++jy)
      {
        const CellRange* row = this->CellRanges.data() + dims[0] * (jy + dims[1] * kz);
        for (Index ix = lo[0]; ix <= hi[0]; ++ix)
        {
          points += row[ix].End - row[ix].Begin;
          ++blockCells;
        }
      }
    }
    if (points == 0)
    {
      return -1;
    }
    const double h = this->Size;
    const double cellMeasure = dimension == 1 ? h : (dimension == 2 ? h * h : h * h * h);
    const double density = static_cast<double>(points) / (static_cast<double>(blockCells) * cellMeasure);
    const double radius = 1.12 * BallRadius(k, density, dimension); // about 1.4 k points in 3D
    cut = radius * radius;
  }
  // All points within sqrt(cut); when there are at least k, the k nearest are among them.
  const double* xyz = this->Sorted.data();
  Candidates c;
  CellRange ranges[Candidates::MaxRanges];
  for (int attempt = 0; attempt < 2; ++attempt)
  {
    int rangeCount = 0;
    Index points = 0;
    bool overflow = false;
    this->VisitCells(rel, cq, std::sqrt(cut), [&](const CellRange& cell) {
      points += cell.End - cell.Begin;
      if (rangeCount > 0 && ranges[rangeCount - 1].End == cell.Begin)
      {
        ranges[rangeCount - 1].End = cell.End;
      }
      else if (rangeCount < Candidates::MaxRanges)
      {
        ranges[rangeCount++] = cell;
      }
      else
      {
        overflow = true;
      }
      overflow = overflow || points > Candidates::Capacity;
      return !overflow;
    });
    if (overflow)
    {
      return -1;
    }
    c.Count = Filter(xyz, ranges, rangeCount, x, cut, c.Dist2, c.Ids);
    if (c.Count >= k)
    {
      c.Sort(cut, k, PositionOrder{ xyz, this->Order.data() });
      std::copy(c.SortedDist2, c.SortedDist2 + k, dist2);
      for (int i = 0; i < k; ++i)
      {
        ids[i] = this->Order[c.SortedIds[i]];
      }
      return k;
    }
    cut *= dimension == 3 ? 1.5874 : (dimension == 2 ? 2.0 : 4.0); // twice the expected count
  }
  return -1;
}

template <class Best>
int NeighborGrid::SearchNearest(const double x[3], const double rel[3], const Index cq[3], Best& best) const
{
  const CellGaps gaps{ rel, cq, this->Size, GapMargin(rel, this->Size, this->Extent) };
  const double* points = this->Sorted.data();
  const CellRange* cells = this->CellRanges.data();
  const Index* dims = this->GridDims;
  auto scanCell = [&](const CellRange& cell) {
    for (Index s = cell.Begin; s < cell.End; ++s)
    {
      const double* p = points + 3 * s;
      const double dx = p[0] - x[0], dy = p[1] - x[1], dz = p[2] - x[2];
      best.Offer(dx * dx + dy * dy + dz * dz, s);
    }
  };

  // Shells of cells at Chebyshev distance s from the query's cell, restricted to the grid.
  Index firstShell = 0, lastShell = 0;
  for (int a = 0; a < 3; ++a)
  {
    firstShell = std::max({ firstShell, -cq[a], cq[a] - (dims[a] - 1) });
    lastShell = std::max({ lastShell, cq[a], dims[a] - 1 - cq[a] });
  }
  if (firstShell <= 1) // shells 0 and 1, nearest cells first
  {
    Index step[3];
    double gap[3][3]; // squared gaps of the cells cq, cq + step and cq - step, per axis
    for (int a = 0; a < 3; ++a)
    {
      step[a] = rel[a] - static_cast<double>(cq[a]) * this->Size < 0.5 * this->Size ? -1 : 1;
      gap[a][0] = 0.0;
      gap[a][1] = gaps.Squared(a, cq[a] + step[a]);
      gap[a][2] = gaps.Squared(a, cq[a] - step[a]);
    }
    for (const auto& offset : NearFirstBlock)
    {
      Index c[3];
      bool inside = true;
      for (int a = 0; a < 3; ++a)
      {
        c[a] = cq[a] + (offset[a] == 0 ? 0 : (offset[a] == 1 ? step[a] : -step[a]));
        inside = inside && c[a] >= 0 && c[a] < dims[a];
      }
      if (inside && gap[0][offset[0]] + gap[1][offset[1]] + gap[2][offset[2]] <= best.Worst)
      {
        scanCell(cells[c[0] + dims[0] * (c[1] + dims[1] * c[2])]);
      }
    }
    firstShell = 2;
  }
  for (Index s = firstShell; s <= lastShell; ++s)
  {
    if (best.Worst < Infinity) // stop when the whole shell is farther than the k-th distance
    {
      double nearest = Infinity;
      for (int a = 0; a < 3; ++a)
      {
        if (cq[a] - s >= 0 && cq[a] - s < dims[a])
        {
          nearest = std::min(nearest, gaps.Squared(a, cq[a] - s));
        }
        if (cq[a] + s >= 0 && cq[a] + s < dims[a])
        {
          nearest = std::min(nearest, gaps.Squared(a, cq[a] + s));
        }
      }
      if (nearest > best.Worst)
      {
        break;
      }
    }
    const Index z0 = std::max<Index>(0, cq[2] - s), z1 = std::min(dims[2] - 1, cq[2] + s);
    const Index y0 = std::max<Index>(0, cq[1] - s), y1 = std::min(dims[1] - 1, cq[1] + s);
    const Index x0 = std::max<Index>(0, cq[0] - s), x1 = std::min(dims[0] - 1, cq[0] + s);
    for (Index kz = z0; kz <= z1; ++kz)
    {
      const double gz = gaps.Squared(2, kz);
      if (gz > best.Worst)
      {
        continue;
      }
      const bool zFace = kz == cq[2] - s || kz == cq[2] + s;
      for (Index jy = y0; jy <= y1; ++jy)
      {
        const double gyz = gz + gaps.Squared(1, jy);
        if (gyz > best.Worst)
        {
          continue;
        }
        const CellRange* row = cells + dims[0] * (jy + dims[1] * kz);
        if (zFace || jy == cq[1] - s || jy == cq[1] + s)
        {
          for (Index ix = x0; ix <= x1; ++ix)
          {
            if (gyz + gaps.Squared(0, ix) <= best.Worst)
            {
              scanCell(row[ix]);
            }
          }
        }
        else // inside the shell's box: only its two x faces belong to the shell
        {
          if (cq[0] - s == x0 && gyz + gaps.Squared(0, x0) <= best.Worst)
          {
            scanCell(row[x0]);
          }
          if (cq[0] + s == x1 && gyz + gaps.Squared(0, x1) <= best.Worst)
          {
            scanCell(row[x1]);
          }
        }
      }
    }
  }
  return best.Finish();
}

int NeighborGrid::NearestExact(
  const double x[3], const double rel[3], const Index cq[3], int k, Index* ids, double* dist2) const
{
  const PositionOrder order{ this->Sorted.data(), this->Order.data() };
  if (k <= SortedBest::Capacity)
  {
    SortedBest best(dist2, ids, order, k);
    return this->SearchNearest(x, rel, cq, best);
  }
  HeapBest best{ dist2, ids, order, k };
  return this->SearchNearest(x, rel, cq, best);
}

int NeighborGrid::FindKNearest(const double x[3], int k, Index* ids, double* dist2) const
{
  double rel[3];
  Index cq[3];
  if (k <= 0 || ids == nullptr || dist2 == nullptr || !this->CellCoordinate(x, rel, cq))
  {
    return 0;
  }
  k = static_cast<int>(std::min<Index>(k, this->NumberOfValidPoints()));
  const int found = this->NearestWithinEstimate(x, rel, cq, k, 0.0, ids, dist2);
  return found >= 0 ? found : this->NearestExact(x, rel, cq, k, ids, dist2);
}

int NeighborGrid::FindKNearest(
  const double x[3], int k, std::vector<Index>& ids, std::vector<double>& dist2) const
{
  const Index room = std::min<Index>(std::max(k, 0), this->NumberOfValidPoints());
  ids.resize(room);
  dist2.resize(room);
  const int count = room > 0 ? this->FindKNearest(x, k, ids.data(), dist2.data()) : 0;
  ids.resize(count);
  dist2.resize(count);
  return count;
}

void NeighborGrid::FindKNearestForAllPoints(
  int k, std::vector<Index>& ids, std::vector<double>& dist2) const
{
  const Index n = this->NumberOfInputPoints;
  if (k <= 0)
  {
    ids.clear();
    dist2.clear();
    return;
  }
  ids.resize(n * k);
  dist2.resize(n * k);
  Index* idRows = ids.data();
  double* distRows = dist2.data();
  auto pad = [&](Index row, int from) {
    std::fill(idRows + row * k + from, idRows + (row + 1) * k, Index(-1));
    std::fill(distRows + row * k + from, distRows + (row + 1) * k, Infinity);
  };
  for (const Index invalid : this->InvalidIds)
  {
    pad(invalid, 0);
  }
  const Index m = this->NumberOfValidPoints();
  const int wanted = static_cast<int>(std::min<Index>(k, m));
  const double* xyz = this->Sorted.data();
  const Index* order = this->Order.data();
  // In Morton order consecutive queries are neighbours: the previous k-th distance, slightly enlarged,
  // is a good first cut for the next query.
  ParallelFor(
    m, 1024,
    [&](Index begin, Index end) {
      double cut = 0.0;
      for (Index s = begin; s < end; ++s)
      {
        const double* x = xyz + 3 * s;
        double rel[3];
        Index cq[3];
        this->CellCoordinate(x, rel, cq);
        Index* rowIds = idRows + order[s] * k;
        double* rowDist2 = distRows + order[s] * k;
        int found = this->NearestWithinEstimate(x, rel, cq, wanted, cut, rowIds, rowDist2);
        if (found < 0)
        {
          found = this->NearestExact(x, rel, cq, wanted, rowIds, rowDist2);
        }
        cut = found > 0 ? 1.25 * rowDist2[found - 1] : 0.0;
        pad(order[s], found);
      }
    },
    4096);
}
} // namespace meshfree
