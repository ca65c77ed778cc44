// SPDX-License-Identifier: BSD-3-Clause
#include "Common/NeighborGrid.h"

#include "Common/GridCell.h"

#include "Common/Parallel.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <utility>

#if defined(__GNUC__)
#define MESHFREE_GRID_PREFETCH(address) __builtin_prefetch(address)
#else
#define MESHFREE_GRID_PREFETCH(address) ((void)0)
#endif
#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#define MESHFREE_GRID_AVX512 1 // filter kernels for CPUs with AVX-512 or AVX2, chosen at run time
#endif

namespace meshfree
{
namespace
{
constexpr Index MaxCellsPerAxis = Index(1) << 21;
constexpr Index ParallelThreshold = 16384; // smaller clouds are built on one thread
constexpr double Infinity = std::numeric_limits<double>::infinity();
constexpr double Pi = 3.14159265358979323846;
constexpr double FarCell = 1099511627776.0; // 2^40: query cell coordinates are clamped to +-this

inline bool IsFinite3(const double* p)
{
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

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
void SiftDown(double* dist2, Index* ids, Index root, Index count, const Less& before)
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
void SiftUp(double* dist2, Index* ids, Index node, const Less& before)
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
void SortHeap(double* dist2, Index* ids, Index count, const Less& less)
{
  for (Index end = count - 1; end > 0; --end)
  {
    std::swap(dist2[0], dist2[end]);
    std::swap(ids[0], ids[end]);
    SiftDown(dist2, ids, 0, end, less);
  }
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

// ------------------------------------------------------------------------------ distance filters
// Filter(): for the sorted positions s in the given ranges, writes (squared distance to x, s) of the points
// with squared distance <= cut to dist2[] and pos[], and returns their number. The outputs need room for
// the ranges' total size + 8 entries; dist2 may be null (positions only). Distances are (dx * dx + dy * dy)
// + dz * dz in IEEE double precision, never fused into FMAs, in every variant: results are bit-identical
// whichever one runs.
using CellRange = NeighborGrid::CellRange;

/// The scalar kernel over sorted positions [begin, end), appending after `count` entries; returns the new count.
inline int FilterSpan(const double* xyz, Index begin, Index end, const double x[3], double cut, double* dist2,
  Index* pos, int count)
{
  for (Index s = begin; s < end; ++s) // branch-free: the count decides
  {
    const double* p = xyz + 3 * s;
    const double dx = p[0] - x[0], dy = p[1] - x[1], dz = p[2] - x[2];
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (dist2 != nullptr)
    {
      dist2[count] = d2;
    }
    pos[count] = s;
    count += d2 <= cut ? 1 : 0;
  }
  return count;
}

int FilterScalar(const double* xyz, const CellRange* ranges, int rangeCount, const double x[3], double cut,
  double* dist2, Index* pos)
{
  int count = 0;
  for (int r = 0; r < rangeCount; ++r)
  {
    count = FilterSpan(xyz, ranges[r].Begin, ranges[r].End, x, cut, dist2, pos, count);
  }
  return count;
}

#ifdef MESHFREE_GRID_AVX512
__attribute__((target("avx512f"))) int FilterAvx512(const double* xyz, const CellRange* ranges,
  int rangeCount, const double x[3], double cut, double* dist2, Index* pos)
{
  // Eight interleaved points (24 doubles in three registers) are split into x, y and z registers.
  const __m512i xLow = _mm512_set_epi64(0, 0, 15, 12, 9, 6, 3, 0);
  const __m512i xHigh = _mm512_set_epi64(13, 10, 5, 4, 3, 2, 1, 0);
  const __m512i yLow = _mm512_set_epi64(0, 0, 0, 13, 10, 7, 4, 1);
  const __m512i yHigh = _mm512_set_epi64(14, 11, 8, 4, 3, 2, 1, 0);
  const __m512i zLow = _mm512_set_epi64(0, 0, 0, 14, 11, 8, 5, 2);
  const __m512i zHigh = _mm512_set_epi64(15, 12, 9, 4, 3, 2, 1, 0);
  // Explicit rounding keeps the compiler from contracting multiply and add into an FMA.
  constexpr int Round = _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC;
  constexpr __mmask8 all = 0xFF;
  auto lanes = [](Index n) { return static_cast<__mmask8>(n >= 8 ? 0xFF : (n <= 0 ? 0 : (1u << n) - 1u)); };
  const __m512d qx = _mm512_set1_pd(x[0]), qy = _mm512_set1_pd(x[1]), qz = _mm512_set1_pd(x[2]);
  const __m512d limit = _mm512_set1_pd(cut);
  const __m512i step = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
  int count = 0;
  for (int r = 0; r < rangeCount; ++r)
  {
    const Index end = ranges[r].End;
    for (Index s = ranges[r].Begin; s < end; s += 8)
    {
      const Index values = 3 * (end - s);
      const double* p = xyz + 3 * s;
      const __m512d v0 = _mm512_maskz_loadu_pd(lanes(values), p);
      const __m512d v1 = _mm512_maskz_loadu_pd(lanes(values - 8), p + 8);
      const __m512d v2 = _mm512_maskz_loadu_pd(lanes(values - 16), p + 16);
      const __m512d px = _mm512_permutex2var_pd(_mm512_permutex2var_pd(v0, xLow, v1), xHigh, v2);
      const __m512d py = _mm512_permutex2var_pd(_mm512_permutex2var_pd(v0, yLow, v1), yHigh, v2);
      const __m512d pz = _mm512_permutex2var_pd(_mm512_permutex2var_pd(v0, zLow, v1), zHigh, v2);
      const __m512d dx = _mm512_sub_pd(px, qx), dy = _mm512_sub_pd(py, qy), dz = _mm512_sub_pd(pz, qz);
      const __m512d d2 = _mm512_add_pd(_mm512_add_pd(_mm512_maskz_mul_round_pd(all, dx, dx, Round),
                                         _mm512_maskz_mul_round_pd(all, dy, dy, Round)),
        _mm512_maskz_mul_round_pd(all, dz, dz, Round));
      const __mmask8 keep = _mm512_mask_cmp_pd_mask(lanes(end - s), d2, limit, _CMP_LE_OQ);
      if (dist2 != nullptr)
      {
        _mm512_storeu_pd(dist2 + count, _mm512_maskz_compress_pd(keep, d2));
      }
      const __m512i positions = _mm512_add_epi64(_mm512_set1_epi64(s), step);
      _mm512_storeu_si512(pos + count, _mm512_maskz_compress_epi64(keep, positions));
      count += __builtin_popcount(keep);
    }
  }
  return count;
}
#endif

#ifdef MESHFREE_GRID_AVX512
// AVX2 (no FMA in the target, so multiplies and adds stay separate): four interleaved points (12 doubles in
// three registers) are split into x, y and z registers by two blends and a lane permutation each; the kept
// lanes are written in order as in the scalar kernel (the outputs have room for 8 entries more).
__attribute__((target("avx2"))) int FilterAvx2(const double* xyz, const CellRange* ranges, int rangeCount,
  const double x[3], double cut, double* dist2, Index* pos)
{
  const __m256d qx = _mm256_set1_pd(x[0]), qy = _mm256_set1_pd(x[1]), qz = _mm256_set1_pd(x[2]);
  const __m256d limit = _mm256_set1_pd(cut);
  int count = 0;
  alignas(32) double d2s[4];
  for (int r = 0; r < rangeCount; ++r)
  {
    const Index end = ranges[r].End;
    Index s = ranges[r].Begin;
    for (; s + 4 <= end; s += 4)
    {
      const double* p = xyz + 3 * s;
      const __m256d v0 = _mm256_loadu_pd(p);     // x0 y0 z0 x1
      const __m256d v1 = _mm256_loadu_pd(p + 4); // y1 z1 x2 y2
      const __m256d v2 = _mm256_loadu_pd(p + 8); // z2 x3 y3 z3
      const __m256d px = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(v0, v1, 0x4), v2, 0x2), 0x6C);
      const __m256d py = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(v0, v1, 0x9), v2, 0x4), 0xB1);
      const __m256d pz = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(v0, v1, 0x2), v2, 0x9), 0xC6);
      const __m256d dx = _mm256_sub_pd(px, qx), dy = _mm256_sub_pd(py, qy), dz = _mm256_sub_pd(pz, qz);
      const __m256d d2 =
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), _mm256_mul_pd(dz, dz));
      const int keep = _mm256_movemask_pd(_mm256_cmp_pd(d2, limit, _CMP_LE_OQ));
      if (keep == 0)
      {
        continue;
      }
      _mm256_store_pd(d2s, d2);
      for (int lane = 0; lane < 4; ++lane) // branch-free: the mask decides
      {
        if (dist2 != nullptr)
        {
          dist2[count] = d2s[lane];
        }
        pos[count] = s + lane;
        count += (keep >> lane) & 1;
      }
    }
    count = FilterSpan(xyz, s, end, x, cut, dist2, pos, count);
  }
  return count;
}
#endif

using FilterFunction = int (*)(const double*, const CellRange*, int, const double*, double, double*, Index*);

FilterFunction VectorFilter()
{
#ifdef MESHFREE_GRID_AVX512
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f"))
  {
    return FilterAvx512;
  }
  if (__builtin_cpu_supports("avx2"))
  {
    return FilterAvx2;
  }
#endif
  return nullptr;
}

std::atomic<FilterFunction> ActiveFilter{ VectorFilter() ? VectorFilter() : FilterScalar };

inline int Filter(const double* xyz, const CellRange* ranges, int rangeCount, const double x[3], double cut,
  double* dist2, Index* pos)
{
  return ActiveFilter.load(std::memory_order_relaxed)(xyz, ranges, rangeCount, x, cut, dist2, pos);
}
} // namespace

bool NeighborGrid::SetVectorized(bool enable)
{
  const FilterFunction vector = VectorFilter();
  ActiveFilter.store(enable && vector ? vector : FilterScalar);
  return enable && vector;
}

void NeighborGrid::SetPointsPerCell(double pointsPerCell)
{
  this->PointsPerCell = pointsPerCell > 0.0 && std::isfinite(pointsPerCell) ? pointsPerCell : 8.0;
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
  for (int a = 0; a < 3; ++a)
  {
    this->Origin[a] = lo[a];
    this->Extent[a] = hi[a] - lo[a];
  }
  this->ChooseGrid(cellSize, m);

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

namespace
{
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

double GapMargin(const double rel[3], double size, const double extent[3])
{
  return GridGapMargin(rel, size, extent);
}

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

int NeighborGrid::GridDimension() const
{
  return (this->GridDims[0] > 1 ? 1 : 0) + (this->GridDims[1] > 1 ? 1 : 0) + (this->GridDims[2] > 1 ? 1 : 0);
}

/// Calls visit(range) for every non-empty cell that may hold points within `radius` of the query (the
/// cells of the box around it, less those whose box is farther); stops when visit returns false.
template <class Visit>
void NeighborGrid::VisitCells(const double rel[3], const Index cq[3], double radius, Visit&& visit) const
{
  const CellGaps gaps{ rel, cq, this->Size, GapMargin(rel, this->Size, this->Extent) };
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

template <class Accept>
void NeighborGrid::FilterRadius(const double x[3], double radius, Accept&& accept) const
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
  constexpr Index MaxPoints = 248;
  CellRange ranges[MaxRanges];
  int rangeCount = 0;
  Index points = 0;
  double dist2[MaxPoints + 8];
  Index pos[MaxPoints + 8];
  auto flush = [&] {
    if (rangeCount > 0)
    {
      const int found = Filter(xyz, ranges, rangeCount, x, r2, dist2, pos);
      accept(found, dist2, pos);
    }
    rangeCount = 0;
    points = 0;
  };
  this->VisitCells(rel, cq, radius, [&](const CellRange& cell) {
    for (Index b = cell.Begin; b < cell.End;)
    {
      if (points == MaxPoints)
      {
        flush();
      }
      const Index e = std::min(cell.End, b + (MaxPoints - points));
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
  representative.assign(static_cast<size_t>(this->NumberOfInputPoints), -1);
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
  std::vector<std::vector<Index>> posPerThread(MaxThreads());
  duplicates = ParallelReduce(
    cells, 1024, Index(0),
    [&](Index begin, Index end) {
      std::vector<Index>& pos = posPerThread[ThreadIndex()];
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
