// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the neighbour grid's radius queries (one point, all points), duplicates and counts.
#include "Common/NeighborGrid.h"

#include "Common/NeighborGridDetail.h"
#include "Common/Parallel.h"

#include <algorithm>
#include <cmath>

namespace meshfree
{
using namespace grid_detail;

void NeighborGrid::FindWithinRadius(
  const double x[3], double radius, std::vector<Index>& ids, std::vector<double>* dist2) const
{
  ids.clear();
  if (dist2)
  {
    dist2->clear();
  }
  const Index* order = this->Order.data();
  this->FilterRadius(x, radius, [&](int found, const double* d2, const Index* pos) {
    for (int i = 0; i < found; ++i)
    {
      ids.push_back(order[pos[i]]);
    }
    if (dist2)
    {
      dist2->insert(dist2->end(), d2, d2 + found);
    }
  });
}

Index NeighborGrid::FindDuplicates(std::vector<Index>& representative) const
{
  detail::AssignLarge(representative, static_cast<size_t>(this->NumberOfInputPoints), Index(-1));
  if (this->Order.empty())
  {
    return 0; // no valid point: no cell ranges either
  }
  const Index cells = this->GridDims[0] * this->GridDims[1] * this->GridDims[2];
  const CellRange* ranges = this->CellRanges.data();
  const double* xyz = this->Sorted.data();
  const Index* order = this->Order.data();
  Index duplicates = 0;
  // Equal coordinates fall into one cell: sort each cell's points by (x, y, z, index) and group.
  PerThread<std::vector<Index>> posPerThread;
  duplicates = ParallelReduce(
    cells, 1024, Index(0),
    [&](Index begin, Index end) {
      std::vector<Index>& pos = posPerThread.Local();
      Index found = 0; // this block's duplicates
      for (Index c = begin; c < end; ++c)
      {
        const CellRange r = ranges[c];
        if (r.End <= r.Begin)
        {
          continue;
        }
        pos.clear();
        for (Index s = r.Begin; s < r.End; ++s)
        {
          pos.push_back(s);
        }
        std::sort(pos.begin(), pos.end(), [xyz, order](Index a, Index b) {
          for (int k = 0; k < 3; ++k)
          {
            if (xyz[3 * a + k] != xyz[3 * b + k])
            {
              return xyz[3 * a + k] < xyz[3 * b + k];
            }
          }
          return order[a] < order[b];
        });
        Index first = pos[0];
        representative[order[first]] = order[first];
        for (size_t j = 1; j < pos.size(); ++j)
        {
          const Index s = pos[j];
          const bool same = xyz[3 * s] == xyz[3 * first] && xyz[3 * s + 1] == xyz[3 * first + 1] &&
            xyz[3 * s + 2] == xyz[3 * first + 2];
          if (!same)
          {
            first = s;
          }
          representative[order[s]] = order[first];
          found += same ? 1 : 0;
        }
      }
      return found;
    },
    [](Index a, Index b) { return a + b; });
  return duplicates;
}

void NeighborGrid::FindWithinRadiusPositions(
  const double x[3], double radius, std::vector<Index>& positions, std::vector<double>& dist2) const
{
  positions.clear();
  dist2.clear();
  this->FilterRadius(x, radius, [&](int found, const double* d2, const Index* pos) {
    positions.insert(positions.end(), pos, pos + found);
    dist2.insert(dist2.end(), d2, d2 + found);
  });
}

void NeighborGrid::FindWithinRadiusPositions(
  const double x[3], double radius, detail::Buffer<Index>& positions, detail::Buffer<double>& dist2) const
{
  size_t count = 0;
  positions.clear();
  dist2.clear();
  this->FilterRadiusTo(
    x, radius,
    [&](Index candidates, double*& d2, Index*& pos) {
      const size_t room = count + static_cast<size_t>(candidates) + 8;
      if (positions.size() < room)
      {
        positions.resize(std::max(room, 2 * positions.size()));
        dist2.resize(positions.size());
      }
      d2 = dist2.data() + count;
      pos = positions.data() + count;
    },
    [&](int found, const double*, const Index*) { count += static_cast<size_t>(found); });
  positions.resize(count);
  dist2.resize(count);
}

void NeighborGrid::FindWithinRadiusSorted(
  const double x[3], double radius, std::vector<Index>& ids, std::vector<double>& dist2) const
{
  this->FindWithinRadiusPositions(x, radius, ids, dist2);
  const Index count = static_cast<Index>(ids.size());
  const PositionOrder order{ this->Sorted.data(), this->Order.data() };
  for (Index i = count / 2 - 1; i >= 0; --i) // heap sort: in place, no allocation
  {
    SiftDown(dist2.data(), ids.data(), i, count, order);
  }
  SortHeap(dist2.data(), ids.data(), count, order);
  for (Index& id : ids)
  {
    id = this->Order[id];
  }
}

Index NeighborGrid::CountWithinRadius(const double x[3], double radius) const
{
  Index count = 0;
  this->FilterRadius(x, radius, [&](int found, const double*, const Index*) { count += found; });
  return count;
}

bool NeighborGrid::FindWithinRadiusForAllPoints(
  double radius, std::vector<Index>& offsets, std::vector<std::int32_t>& ids, bool excludeSelf) const
{
  const Index n = this->NumberOfInputPoints;
  offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  // ids keeps its size until the end: resized then, only its growth is zero-filled (it is called every step of
  // a simulation, with lists of about the same length).
  const Index valid = static_cast<Index>(this->Order.size());
  if (n >= (Index(1) << 31))
  {
    ids.clear();
    return false;
  }
  if (valid == 0 || !(radius >= 0.0) || !std::isfinite(radius))
  {
    ids.clear();
    return true;
  }
  const double r2 = radius * radius;
  const double* xyz = this->Sorted.data();
  const Index* order = this->Order.data();
  const CellRange* cells = this->CellRanges.data();
  const Index nx = this->GridDims[0], ny = this->GridDims[1], nz = this->GridDims[2];
  const Index cellCount = nx * ny * nz;
  const int threads = MaxThreads();
  // Scratch of the calling thread kept between calls (repeated calls, e.g. every step of a simulation, then
  // neither allocate nor touch fresh pages): per sorted position, where its row lies in the buffer of the
  // loop slot that found it; per slot, its rows back to back and the query's candidate cells and positions.
  struct SlotScratch
  {
    detail::Buffer<std::int32_t> Rows;
    std::size_t Used = 0;          // Rows.size() is the capacity in use; rows are written branch-free past Used
    std::vector<CellRange> Ranges; // candidate cells of the current cell (neighbouring ranges merged)
    detail::Buffer<Index> Pos;     // the filter's outputs
  };
  thread_local detail::Buffer<Index> rowStart;
  thread_local detail::Buffer<std::int32_t> rowThread;
  thread_local std::vector<SlotScratch> slots;
  rowStart.resize(static_cast<std::size_t>(valid));
  rowThread.resize(static_cast<std::size_t>(valid));
  if (slots.size() < static_cast<std::size_t>(threads))
  {
    slots.resize(static_cast<std::size_t>(threads));
  }
  for (SlotScratch& slot : slots)
  {
    slot.Used = 0;
  }
  Index* rowStartData = rowStart.data();
  std::int32_t* rowThreadData = rowThread.data();
  SlotScratch* slotData = slots.data(); // thread_local names inside the loop's body would be the workers' own
  ParallelFor(
    cellCount, 64,
    [&](Index begin, Index end) {
      const int t = ThreadIndex();
      SlotScratch& slot = slotData[t];
      detail::Buffer<std::int32_t>& out = slot.Rows;
      std::size_t& used = slot.Used;
      std::vector<CellRange>& ranges = slot.Ranges;
      detail::Buffer<Index>& pos = slot.Pos;
      for (Index c = begin; c < end; ++c)
      {
        const CellRange own = cells[c];
        if (own.End <= own.Begin)
        {
          continue;
        }
        // The cells any of this cell's points can reach: the per-point range of VisitCells() for the box of
        // the cell's points, visited in the same (z, y, x) order, so every row keeps FindWithinRadius()'s order
        // (cells VisitCells() would prune hold no point within the radius).
        double lo[3], hi[3];
        for (int a = 0; a < 3; ++a)
        {
          lo[a] = hi[a] = xyz[3 * own.Begin + a] - this->Origin[a];
        }
        for (Index p = own.Begin + 1; p < own.End; ++p)
        {
          for (int a = 0; a < 3; ++a)
          {
            const double rel = xyz[3 * p + a] - this->Origin[a];
            lo[a] = std::min(lo[a], rel);
            hi[a] = std::max(hi[a], rel);
          }
        }
        const double margin =
          std::max(GapMargin(lo, this->Size, this->Extent), GapMargin(hi, this->Size, this->Extent));
        Index first[3], last[3];
        bool none = false;
        for (int a = 0; a < 3; ++a)
        {
          const double top = static_cast<double>(this->GridDims[a] - 1);
          const double low = std::floor((lo[a] - radius - margin) * this->InverseSize);
          const double high = std::floor((hi[a] + radius + margin) * this->InverseSize);
          none = none || low > top || high < 0.0;
          first[a] = low > 0.0 ? static_cast<Index>(low) : 0;
          last[a] = high < top ? static_cast<Index>(high) : this->GridDims[a] - 1;
        }
        ranges.clear();
        Index total = 0;
        for (Index k = first[2]; !none && k <= last[2]; ++k)
        {
          for (Index j = first[1]; j <= last[1]; ++j)
          {
            const CellRange* row = cells + nx * (j + ny * k);
            for (Index i = first[0]; i <= last[0]; ++i)
            {
              const CellRange range = row[i];
              if (range.End <= range.Begin)
              {
                continue;
              }
              total += range.End - range.Begin;
              if (!ranges.empty() && ranges.back().End == range.Begin)
              {
                ranges.back().End = range.End;
              }
              else
              {
                ranges.push_back(range);
              }
            }
          }
        }
        if (static_cast<Index>(pos.size()) < total + 8)
        {
          pos.resize(static_cast<std::size_t>(2 * total + 8));
        }
        for (Index p = own.Begin; p < own.End; ++p)
        {
          const int found = ranges.empty()
            ? 0
            : Filter(xyz, ranges.data(), static_cast<int>(ranges.size()), xyz + 3 * p, r2, nullptr, pos.data());
          if (out.size() < used + static_cast<std::size_t>(found))
          {
            out.resize(2 * (used + static_cast<std::size_t>(found)));
          }
          std::int32_t* row = out.data() + used;
          std::size_t m = 0;
          for (int q = 0; q < found; ++q) // branch-free: the count decides
          {
            row[m] = static_cast<std::int32_t>(order[pos[q]]);
            m += static_cast<std::size_t>(!(excludeSelf && pos[q] == p));
          }
          rowStartData[p] = static_cast<Index>(used);
          rowThreadData[p] = t;
          offsets[static_cast<std::size_t>(order[p]) + 1] = static_cast<Index>(m);
          used += m;
        }
      }
    },
    valid >= 4096 ? 0 : cellCount + 1);
  std::vector<const std::int32_t*> buffers(static_cast<std::size_t>(threads), nullptr);
  for (int t = 0; t < threads; ++t)
  {
    buffers[static_cast<std::size_t>(t)] = slots[static_cast<std::size_t>(t)].Rows.data();
  }
  for (Index i = 0; i < n; ++i)
  {
    offsets[static_cast<std::size_t>(i) + 1] += offsets[static_cast<std::size_t>(i)];
  }
  ids.resize(static_cast<std::size_t>(offsets[static_cast<std::size_t>(n)]));
  ParallelFor(
    valid, 1024,
    [&](Index begin, Index end) {
      for (Index p = begin; p < end; ++p)
      {
        const Index i = order[p];
        const std::int32_t* from = buffers[static_cast<std::size_t>(rowThreadData[p])] + rowStartData[p];
        std::copy(from, from + (offsets[static_cast<std::size_t>(i) + 1] - offsets[static_cast<std::size_t>(i)]),
          ids.begin() + offsets[static_cast<std::size_t>(i)]);
      }
    },
    4096);
  return true;
}
} // namespace meshfree
