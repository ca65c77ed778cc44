// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the neighbour grid's distance filters (scalar, AVX2, AVX-512; chosen at run time, bit-identical).
#include "Common/NeighborGridDetail.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#define MESHFREE_GRID_AVX512 1 // filter kernels for CPUs with AVX-512 or AVX2, chosen at run time
#endif

namespace meshfree
{
namespace grid_detail
{
namespace
{
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
} // namespace

std::atomic<FilterFunction> ActiveFilter{ VectorFilter() ? VectorFilter() : FilterScalar };
} // namespace grid_detail

using namespace grid_detail;

bool NeighborGrid::SetVectorized(bool enable)
{
  const FilterFunction vector = VectorFilter();
  ActiveFilter.store(enable && vector ? vector : FilterScalar);
  return enable && vector;
}
} // namespace meshfree
