// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the neighbour grid's build (bounds, cell size, Morton-ordered cells, points sorted into them)
// and its geometry. Queries: NeighborGridRadius.cxx, NeighborGridNearest.cxx; filters: NeighborGridFilter.cxx.
#include "Common/NeighborGrid.h"

#include "Common/NeighborGridDetail.h"
#include "Common/Parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace meshfree
{
using namespace grid_detail;
namespace
{
inline int BitWidth(std::uint64_t v)
{
  int bits = 0;
  for (; v != 0; v >>= 1)
  {
    ++bits;
  }
  return bits;
}

/// Cell coordinate, along one axis, of a point at `rel` from the origin, clamped into [0, dim).
inline Index AxisCell(double rel, double inverseSize, Index dim)
{
  return GridAxisCell(rel, inverseSize, dim);
}

/// First element of chunk c when [0, n) is cut into `chunks` contiguous chunks.
inline Index ChunkBegin(Index n, int c, int chunks)
{
  return static_cast<Index>((static_cast<long double>(n) * c) / chunks);
}

/// Sorts the points of one cell (sorted positions [begin, end), in original index order) by position
/// (GridPointBefore: x, y, z, then original index), moving their coordinates and original indices together.
using PointRecord = std::pair<std::array<double, 3>, Index>;
void SortCellByPosition(double* xyz, Index* order, Index begin, Index end, std::vector<PointRecord>& large)
{
  if (end - begin > 24) // rare: degenerate clouds
  {
    large.resize(static_cast<std::size_t>(end - begin));
    for (Index s = begin; s < end; ++s)
    {
      large[s - begin] = { { xyz[3 * s], xyz[3 * s + 1], xyz[3 * s + 2] }, order[s] };
    }
    std::sort(large.begin(), large.end(), [](const auto& p, const auto& q) {
      return GridPointBefore(p.first.data(), p.second, q.first.data(), q.second);
    });
    for (Index s = begin; s < end; ++s)
    {
      std::copy(large[s - begin].first.begin(), large[s - begin].first.end(), xyz + 3 * s);
      order[s] = large[s - begin].second;
    }
    return;
  }
  // Usually the x coordinates of a cell's points differ: then each point's rank is the number of smaller x, counted
  // without branches (a comparison sort's branches mispredict on such keys), and the points move once.
  const int count = static_cast<int>(end - begin);
  double xs[24];
  int rank[24];
  for (int i = 0; i < count; ++i)
  {
    xs[i] = xyz[3 * (begin + i)];
  }
  bool distinct = true, sorted = true;
  for (int i = 0; i < count; ++i)
  {
    int smaller = 0, equal = 0;
    for (int j = 0; j < count; ++j)
    {
      smaller += xs[j] < xs[i] ? 1 : 0;
      equal += xs[j] == xs[i] ? 1 : 0;
    }
    rank[i] = smaller;
    distinct = distinct && equal == 1;
    sorted = sorted && smaller == i;
  }
  if (distinct)
  {
    if (!sorted)
    {
      PointRecord moved[24];
      for (int i = 0; i < count; ++i)
      {
        const Index s = begin + i;
        moved[rank[i]] = { { xyz[3 * s], xyz[3 * s + 1], xyz[3 * s + 2] }, order[s] };
      }
      for (int i = 0; i < count; ++i)
      {
        std::copy(moved[i].first.begin(), moved[i].first.end(), xyz + 3 * (begin + i));
        order[begin + i] = moved[i].second;
      }
    }
    return;
  }
  for (Index s = begin + 1; s < end; ++s) // insertion sort
  {
    const double p[3] = { xyz[3 * s], xyz[3 * s + 1], xyz[3 * s + 2] };
    const Index id = order[s];
    Index t = s;
    for (; t > begin && GridPointBefore(p, id, xyz + 3 * (t - 1), order[t - 1]); --t)
    {
      std::copy(xyz + 3 * (t - 1), xyz + 3 * t, xyz + 3 * t);
      order[t] = order[t - 1];
    }
    if (t != s)
    {
      std::copy(p, p + 3, xyz + 3 * t);
      order[t] = id;
    }
  }
}

/// Stable parallel LSD radix sort of v[0, m) by bits [lowBit, lowBit + bits). v and scratch are swapped
/// as the passes go; on return v points to the sorted data.
void RadixSort(std::uint64_t*& v, std::uint64_t*& scratch, Index m, int lowBit, int bits, int chunks)
{
  if (bits <= 0 || m < 2)
  {
    return;
  }
  const int passes = (bits + 10) / 11;
  const int digitBits = (bits + passes - 1) / passes;
  const std::size_t buckets = std::size_t(1) << digitBits;
  const std::uint64_t mask = buckets - 1;
  std::vector<Index> offsets(buckets * chunks);
  for (int pass = 0; pass < passes; ++pass)
  {
    const int shift = lowBit + pass * digitBits;
    const std::uint64_t* in = v;
    std::uint64_t* out = scratch;
    ParallelFor(chunks, 1, [&](Index begin, Index end) {
      for (int c = static_cast<int>(begin); c < end; ++c)
      {
        Index* count = offsets.data() + buckets * c;
        std::fill(count, count + buckets, Index(0));
        for (Index i = ChunkBegin(m, c, chunks), e = ChunkBegin(m, c + 1, chunks); i < e; ++i)
        {
          ++count[(in[i] >> shift) & mask];
        }
      }
    });
    Index sum = 0;
    bool oneBucket = false;
    for (std::size_t b = 0; b < buckets; ++b)
    {
      Index inBucket = 0;
      for (int c = 0; c < chunks; ++c)
      {
        const Index count = offsets[buckets * c + b];
        offsets[buckets * c + b] = sum;
        sum += count;
        inBucket += count;
      }
      oneBucket = oneBucket || inBucket == m;
    }
    if (oneBucket) // every key has the same digit: the pass would copy
    {
      continue;
    }
    ParallelFor(chunks, 1, [&](Index begin, Index end) {
      for (int c = static_cast<int>(begin); c < end; ++c)
      {
        Index* next = offsets.data() + buckets * c;
        for (Index i = ChunkBegin(m, c, chunks), e = ChunkBegin(m, c + 1, chunks); i < e; ++i)
        {
          out[next[(in[i] >> shift) & mask]++] = in[i];
        }
      }
    });
    std::swap(v, scratch);
  }
}
} // namespace

void NeighborGrid::SetPointsPerCell(double pointsPerCell)
{
  this->PointsPerCell = pointsPerCell > 0.0 && std::isfinite(pointsPerCell) ? pointsPerCell : 8.0;
}

void NeighborGrid::SetFrame(const double bounds[6], Index validPoints)
{
  std::copy(bounds, bounds + 6, this->FrameBounds);
  this->FramePoints = std::max<Index>(validPoints, 1);
  this->Framed = bounds[0] <= bounds[1] && bounds[2] <= bounds[3] && bounds[4] <= bounds[5];
}

void NeighborGrid::GetFrame(double bounds[6], Index& validPoints) const
{
  std::copy(this->FrameUsedBounds, this->FrameUsedBounds + 6, bounds);
  validPoints = this->FrameUsedPoints;
}

bool NeighborGrid::Build(const double* xyz, Index n, double cellSize)
{
  if (xyz == nullptr || n < 0)
  {
    n = 0;
  }
  this->NumberOfInputPoints = n;
  this->Order.clear();
  this->InvalidIds.clear();
  this->Sorted.clear();
  this->CellRanges.clear();
  std::fill(this->Origin, this->Origin + 3, 0.0);
  std::fill(this->Extent, this->Extent + 3, 0.0);
  std::fill(this->GridDims, this->GridDims + 3, Index(1));
  this->Size = this->InverseSize = 1.0;
  this->FrameUsedPoints = this->Framed ? this->FramePoints : 0;
  if (this->Framed)
  {
    std::copy(this->FrameBounds, this->FrameBounds + 6, this->FrameUsedBounds);
  }
  if (n == 0)
  {
    return false;
  }

  // Pass 1: bounds and number of valid points, per chunk (pass 2 compacts with the same chunks). Chunks of at
  // least 32,768 points, several per thread so that running threads take a descheduled one's chunks; the
  // results do not depend on their number.
  const int chunks = n >= ParallelThreshold
    ? static_cast<int>(std::min<Index>(std::max<Index>(n / 32768, 1), 8 * static_cast<Index>(MaxThreads())))
    : 1;
  std::vector<Index> validBefore(chunks + 1, 0);
  std::vector<double> chunkBounds(6 * chunks);
  ParallelFor(chunks, 1, [&](Index begin, Index end) {
    for (int c = static_cast<int>(begin); c < end; ++c)
    {
      double lo[3] = { Infinity, Infinity, Infinity };
      double hi[3] = { -Infinity, -Infinity, -Infinity };
      Index valid = 0;
      for (Index i = ChunkBegin(n, c, chunks), e = ChunkBegin(n, c + 1, chunks); i < e; ++i)
      {
        const double* p = xyz + 3 * i;
        if (IsFinite3(p))
        {
          ++valid;
          for (int a = 0; a < 3; ++a)
          {
            lo[a] = std::min(lo[a], p[a]);
            hi[a] = std::max(hi[a], p[a]);
          }
        }
      }
      validBefore[c + 1] = valid;
      for (int a = 0; a < 3; ++a)
      {
        chunkBounds[6 * c + 2 * a] = lo[a];
        chunkBounds[6 * c + 2 * a + 1] = hi[a];
      }
    }
  });
  double lo[3] = { Infinity, Infinity, Infinity };
  double hi[3] = { -Infinity, -Infinity, -Infinity };
  for (int c = 0; c < chunks; ++c)
  {
    validBefore[c + 1] += validBefore[c];
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], chunkBounds[6 * c + 2 * a]);
      hi[a] = std::max(hi[a], chunkBounds[6 * c + 2 * a + 1]);
    }
  }
  const Index m = validBefore[chunks];
  if (m < n)
  {
    this->InvalidIds.reserve(n - m);
    for (Index i = 0; i < n; ++i)
    {
      if (!IsFinite3(xyz + 3 * i))
      {
        this->InvalidIds.push_back(i);
      }
    }
  }
  if (m == 0)
  {
    return false;
  }
  // The cells' box: the frame's when one is set (its bounds were copied above), else the valid points' own.
  for (int a = 0; a < 3 && !this->Framed; ++a)
  {
    this->FrameUsedBounds[2 * a] = lo[a];
    this->FrameUsedBounds[2 * a + 1] = hi[a];
  }
  for (int a = 0; a < 3; ++a)
  {
    this->Origin[a] = this->FrameUsedBounds[2 * a];
    this->Extent[a] = this->FrameUsedBounds[2 * a + 1] - this->FrameUsedBounds[2 * a];
  }
  this->FrameUsedPoints = this->Framed ? this->FramePoints : m;
  this->ChooseGrid(cellSize, this->FrameUsedPoints);

  // Compact Morton code of a cell = OR of one table entry per axis: bit l of the x, y and z cell
  // coordinates go to consecutive key bits (x lowest), skipping axes that have run out of bits. This
  // orders cells exactly as the usual 3D Morton code does, with no unused key bits.
  const Index* dims = this->GridDims;
  std::vector<std::uint64_t> spread[3];
  const int keyBits = MortonTables(dims, spread);
  const int idxBits = BitWidth(static_cast<std::uint64_t>(n - 1));
  const bool packed = keyBits + idxBits <= 64;
  const int keyShift = packed ? idxBits : 0;
  const std::uint64_t idxMask = packed ? (idxBits == 64 ? ~0ull : (1ull << idxBits) - 1) : 0;
  const double* origin = this->Origin;
  const double inverse = this->InverseSize;
  auto cellKey = [&](const double* p) {
    return spread[0][AxisCell(p[0] - origin[0], inverse, dims[0])] |
      spread[1][AxisCell(p[1] - origin[1], inverse, dims[1])] |
      spread[2][AxisCell(p[2] - origin[2], inverse, dims[2])];
  };

  // Pass 2: (key, original index) of every valid point, packed into one word when they fit.
  this->CellKeys.resize(m);
  this->SortScratch.resize(m);
  std::vector<std::pair<std::uint64_t, Index>> pairs(packed ? 0 : m);
  std::uint64_t* keys = this->CellKeys.data();
  ParallelFor(chunks, 1, [&](Index begin, Index end) {
    for (int c = static_cast<int>(begin); c < end; ++c)
    {
      Index out = validBefore[c];
      for (Index i = ChunkBegin(n, c, chunks), e = ChunkBegin(n, c + 1, chunks); i < e; ++i)
      {
        const double* p = xyz + 3 * i;
        if (IsFinite3(p))
        {
          if (packed)
          {
            keys[out++] = (cellKey(p) << keyShift) | static_cast<std::uint64_t>(i);
          }
          else
          {
            pairs[out++] = { cellKey(p), i };
          }
        }
      }
    }
  });
  if (packed)
  {
    std::uint64_t* scratch = this->SortScratch.data();
    RadixSort(keys, scratch, m, keyShift, keyBits, chunks);
    if (keys != this->CellKeys.data())
    {
      std::swap(this->CellKeys, this->SortScratch);
    }
  }
  else // more than ~5e8 points: a comparison sort of (key, index) pairs
  {
    std::sort(pairs.begin(), pairs.end());
  }

  // Gather the coordinates in sorted order; keep the cell key of each sorted position for the cells.
  detail::ReserveLarge(this->Order, static_cast<std::size_t>(m)); // a public std::vector: huge pages if fresh
  this->Order.resize(m);
  this->Sorted.resize(3 * m);
  keys = this->CellKeys.data();
  Index* order = this->Order.data();
  double* sorted = this->Sorted.data();
  // The gather's chunks start at the first point of a cell, so that each sorts its cells by position as it
  // completes them (while they are in cache).
  auto cellKeyOf = [&](Index s) { return packed ? keys[s] >> keyShift : pairs[s].first; };
  std::vector<Index> gatherBegin(static_cast<std::size_t>(chunks) + 1, m);
  gatherBegin[0] = 0;
  for (int c = 1; c < chunks; ++c)
  {
    Index b = std::max(ChunkBegin(m, c, chunks), gatherBegin[c - 1]);
    while (b < m && cellKeyOf(b) == cellKeyOf(b - 1))
    {
      ++b;
    }
    gatherBegin[c] = b;
  }
  const bool byPosition = this->CellsByPosition;
  ParallelFor(chunks, 1, [&](Index begin, Index end) {
    std::vector<PointRecord> large; // scratch of SortCellByPosition
    for (int c = static_cast<int>(begin); c < end; ++c)
    {
      Index cellBegin = gatherBegin[c];
      for (Index s = gatherBegin[c], e = gatherBegin[c + 1]; s < e; ++s)
      {
        Index i;
        if (packed)
        {
          i = static_cast<Index>(keys[s] & idxMask);
          keys[s] >>= keyShift;
          if (s + 16 < e) // the reads are random for a cloud in random order: fetch ahead
          {
            MESHFREE_GRID_PREFETCH(xyz + 3 * static_cast<Index>(keys[s + 16] & idxMask));
          }
        }
        else
        {
          i = pairs[s].second;
          keys[s] = pairs[s].first;
        }
        order[s] = i;
        sorted[3 * s] = xyz[3 * i];
        sorted[3 * s + 1] = xyz[3 * i + 1];
        sorted[3 * s + 2] = xyz[3 * i + 2];
        if (byPosition && (s + 1 == e || cellKeyOf(s + 1) != keys[s])) // the cell's last point
        {
          SortCellByPosition(sorted, order, cellBegin, s + 1, large);
          cellBegin = s + 1;
        }
      }
    }
  });

  // Cell ranges: a run of equal keys is one cell.
  const Index cellCount = dims[0] * dims[1] * dims[2];
  this->CellRanges.resize(cellCount);
  CellRange* cells = this->CellRanges.data();
  auto linearCell = [&](Index s) {
    const double* p = sorted + 3 * s;
    return AxisCell(p[0] - origin[0], inverse, dims[0]) +
      dims[0] *
      (AxisCell(p[1] - origin[1], inverse, dims[1]) + dims[1] * AxisCell(p[2] - origin[2], inverse, dims[2]));
  };
  const Index serialBelow = chunks > 1 ? 0 : std::max(cellCount, m) + 1;
  ParallelFor(
    cellCount, 16384,
    [&](Index begin, Index end) {
      for (Index c = begin; c < end; ++c)
      {
        cells[c] = CellRange{ 0, 0 };
      }
    },
    serialBelow);
  ParallelFor(
    m, 8192,
    [&](Index begin, Index end) {
      for (Index s = begin; s < end; ++s)
      {
        if (s == 0 || keys[s] != keys[s - 1])
        {
          cells[linearCell(s)].Begin = s;
        }
        if (s == m - 1 || keys[s] != keys[s + 1])
        {
          cells[linearCell(s)].End = s + 1;
        }
      }
    },
    serialBelow);
  return true;
}

void NeighborGrid::ReleaseBuildScratch()
{
  detail::Buffer<std::uint64_t>().swap(this->CellKeys);
  detail::Buffer<std::uint64_t>().swap(this->SortScratch);
}

int NeighborGrid::MortonTables(const Index dims[3], std::vector<std::uint64_t> spread[3])
{
  int axisBits[3];
  for (int a = 0; a < 3; ++a)
  {
    axisBits[a] = BitWidth(static_cast<std::uint64_t>(dims[a] - 1));
  }
  int keyBits = 0;
  std::vector<std::uint64_t> levelBit[3];
  for (int level = 0; level < 21; ++level)
  {
    for (int a = 0; a < 3; ++a)
    {
      if (level < axisBits[a])
      {
        levelBit[a].push_back(std::uint64_t(1) << keyBits++);
      }
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    spread[a].assign(dims[a], 0);
    for (Index i = 1; i < dims[a]; ++i) // table[i] = table[i without its lowest bit] | that bit
    {
      int low = 0;
      while (((i >> low) & 1) == 0)
      {
        ++low;
      }
      spread[a][i] = spread[a][i & (i - 1)] | levelBit[a][low];
    }
  }
  return keyBits;
}

void NeighborGrid::ChooseGrid(double cellSize, Index validPoints)
{
  ChooseCells(this->Extent, cellSize, validPoints, this->PointsPerCell, this->Size, this->InverseSize, this->GridDims);
}

void NeighborGrid::ChooseCells(const double e[3], double cellSize, Index validPoints, double pointsPerCell,
  double& cellEdge, double& inverseEdge, Index dims[3])
{
  std::fill(dims, dims + 3, Index(1));
  const double maxExtent = std::max({ e[0], e[1], e[2] });
  if (!std::isfinite(maxExtent)) // finite points whose extent overflows: one cell
  {
    cellEdge = std::numeric_limits<double>::max();
    inverseEdge = 0.0;
    return;
  }
  const double m = static_cast<double>(validPoints);
  double size = cellSize;
  if (!(size > 0.0) || !std::isfinite(size))
  {
    // Largest extents first; an axis shorter than one cell gets one layer and drops out of the volume.
    double sortedExtent[3] = { e[0], e[1], e[2] };
    std::sort(sortedExtent, sortedExtent + 3, [](double a, double b) { return a > b; });
    size = maxExtent;
    for (int dim = 3; dim >= 1; --dim)
    {
      if (!(sortedExtent[dim - 1] > 0.0))
      {
        continue;
      }
      double logVolume = 0.0;
      for (int a = 0; a < dim; ++a)
      {
        logVolume += std::log(sortedExtent[a]);
      }
      const double candidate = std::exp((logVolume + std::log(pointsPerCell / m)) / dim);
      if (candidate <= sortedExtent[dim - 1])
      {
        size = candidate;
        break;
      }
    }
  }
  // Bound the cells: at most 2^21 per axis (the key width) and about 4 per point in total.
  size = std::max(size, maxExtent / static_cast<double>(MaxCellsPerAxis - 2));
  const double maxCells = 4.0 * m + 64.0;
  for (int iteration = 0; iteration < 4096; ++iteration)
  {
    double cells = 1.0;
    for (int a = 0; a < 3; ++a)
    {
      cells *= std::floor(e[a] / size) + 1.0;
    }
    if (cells <= maxCells)
    {
      break;
    }
    size *= std::max(1.01, std::cbrt(cells / maxCells));
  }
  if (!(size > 0.0) || !std::isfinite(1.0 / size))
  {
    size = maxExtent > 0.0 ? maxExtent : 1.0;
  }
  cellEdge = size;
  inverseEdge = 1.0 / size;
  for (int a = 0; a < 3; ++a)
  {
    dims[a] = std::min<Index>(MaxCellsPerAxis, static_cast<Index>(std::floor(e[a] * inverseEdge)) + 1);
  }
}

int NeighborGrid::Dimension() const
{
  int dimension = 0;
  for (int a = 0; a < 3; ++a)
  {
    dimension += this->IsAxisFlat(a) ? 0 : 1;
  }
  return dimension;
}

bool NeighborGrid::IsAxisFlat(int axis) const
{
  const double maxExtent = std::max({ this->Extent[0], this->Extent[1], this->Extent[2] });
  return axis < 0 || axis > 2 || !(this->Extent[axis] > 1e-10 * maxExtent);
}

void NeighborGrid::GetGridDimensions(Index dims[3]) const
{
  std::copy(this->GridDims, this->GridDims + 3, dims);
}

void NeighborGrid::GetBounds(double bounds[6]) const
{
  for (int a = 0; a < 3; ++a)
  {
    bounds[2 * a] = this->Origin[a];
    bounds[2 * a + 1] = this->Origin[a] + this->Extent[a];
  }
}

bool NeighborGrid::CellCoordinate(const double x[3], double rel[3], Index cell[3]) const
{
  if (this->Order.empty() || !IsFinite3(x))
  {
    return false;
  }
  for (int a = 0; a < 3; ++a)
  {
    rel[a] = x[a] - this->Origin[a];
    const double t = std::floor(rel[a] * this->InverseSize);
    cell[a] = static_cast<Index>(t > FarCell ? FarCell : (t > -FarCell ? t : -FarCell));
  }
  return true;
}

int NeighborGrid::GridDimension() const
{
  return (this->GridDims[0] > 1 ? 1 : 0) + (this->GridDims[1] > 1 ? 1 : 0) + (this->GridDims[2] > 1 ? 1 : 0);
}
} // namespace meshfree
