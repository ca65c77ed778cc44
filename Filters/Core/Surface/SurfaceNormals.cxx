// SPDX-License-Identifier: BSD-3-Clause
// PCA normals over a density- and noise-adapted neighbourhood (SurfaceNormals.h).
#include "Surface/SurfaceNormals.h"

#include "Common/Distribution.h"
#include "Common/GridCell.h"
#include "Common/LargeArrays.h"
#include "Common/LocalFit.h"
#include "Common/Parallel.h"
#include "Common/Statistics.h"

#include <Eigen/Dense>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#define MESHFREE_NORMALS_AVX2 1 // the fits' sums with AVX2, chosen at run time (SetNormalKernelsVectorized)
#endif

namespace meshfree
{

namespace
{
constexpr double Pi = 3.141592653589793238462643383279502884;
// The normals' jets (EstimateNormalRadius): the noise's tilt per slope they accept (radians), how far they reach
// relative to the radius of curvature, the most neighbours a radius may hold on average, and the most a jet uses.
constexpr double NormalTilt = 0.0025;
constexpr double CurvatureReach = 0.9;
constexpr double MaxNeighbors = 1000.0;
constexpr size_t MaxFit = 256;
constexpr size_t FramePoints = 64; // the jet's frame (its PCA) from this many of them
// Sharp features (SharpFeatures): a jet misfitting its neighbours by more than FlagMisfit x the noise and
// FlagFloor x its radius reaches across a crease.
constexpr double FlagMisfit = 1.25;
constexpr double FlagFloor = 0.01;
// A single point's jet is flagged from FlagSignificance standard errors of its misfit above the noise on (the rms
// of n fitted points scatters by about 1 / sqrt(2 n), relative), where that is below FlagMisfit: a 256-point jet
// from 1.155 x the noise.
constexpr double FlagSignificance = 3.5;
constexpr double MaxCrossing = 0.2;
// A jet's local noise (LocalNoise): the misfit over the neighbours within half its radius, from this many of them.
constexpr size_t LocalNoiseMinimum = 16;
constexpr double NoiseAgreement = 1.5; // the jets' noise at most this many times the PCA spread's (thin parts)
constexpr double MaxTurn = 0.2; // radians: the most the curvature may turn the normal between a point and its donor
constexpr Index SamplePoints = 2048; // the scale's sample (CloudSample: by a hash of the positions)
// The wide jets' thinned clouds (BuildThinnedClouds): floor(n / ThinTarget) of them when the normals' radius holds
// on average n >= 2 ThinTarget points; a point whose thinned neighbourhood holds fewer than ThinFloor (a sparse
// region) fits over the whole cloud's.
constexpr double ThinTarget = 250.0;
constexpr size_t ThinFloor = MaxFit / 2;
constexpr size_t MaxThinFit = 320; // a thinned list (evenly spread already) is fitted whole up to this many

struct LocalPCA
{
  double Normal[3] = { 0.0, 0.0, 0.0 };
  double Eigenvalues[3] = { 0.0, 0.0, 0.0 }; // ascending, in world units squared
  double Residual = 0.0; // distance from the point to its neighbourhood's plane
  bool Valid = false;
};

/// The k nearest neighbours of x at a nonzero distance (exact duplicates of x are not neighbours: they add
/// nothing to the sampling), preceded by x's duplicates (itself included). Returns how many were found in
/// all; kth gets the distance to the k-th distinct one (or the farthest found).
int NearestDistinct(const NeighborGrid& grid, const double x[3], int k, std::vector<Index>& ids,
  std::vector<double>& d2, double& kth)
{
  int want = k + 1;
  for (;;)
  {
    const int found = grid.FindKNearest(x, want, ids, d2);
    int zeros = 0;
    while (zeros < found && d2[zeros] == 0.0)
    {
      ++zeros;
    }
    if (found < want || found - zeros >= k || want > (1 << 16))
    {
      kth = found > zeros ? std::sqrt(d2[std::min(found, zeros + k) - 1]) : 0.0;
      return found;
    }
    want = zeros + k;
  }
}

#if defined(__GNUC__)
/// Two doubles side by side (GCC/Clang vector extension): lane-wise IEEE arithmetic, the same bits as two scalars.
typedef double Pair __attribute__((vector_size(16)));
#else
struct Pair
{
  double Lane[2];
  double operator[](int i) const { return this->Lane[i]; }
  Pair& operator+=(const Pair& b)
  {
    this->Lane[0] += b.Lane[0];
    this->Lane[1] += b.Lane[1];
    return *this;
  }
};
inline Pair operator+(const Pair& a, const Pair& b)
{
  return Pair{ { a.Lane[0] + b.Lane[0], a.Lane[1] + b.Lane[1] } };
}
inline Pair operator*(double a, const Pair& b)
{
  return Pair{ { a * b.Lane[0], a * b.Lane[1] } };
}
inline Pair operator*(const Pair& a, const Pair& b)
{
  return Pair{ { a.Lane[0] * b.Lane[0], a.Lane[1] * b.Lane[1] } };
}
#endif

/// The first and second moments of the points sorted + 3 idx[m] (m < count) in coordinates shifted to x and scaled
/// by inv: m1 = sum d, m2 = sum (xx, xy, xz, yy, yz, zz), each summed in the points' order.
void CovarianceSums(const double* sorted, const Index* idx, size_t count, const double x[3], double inv, double m1[3],
  double m2[6])
{
  // The sums in pairs (Pair: each lane one sum's products and additions, in the points' order).
  Pair m1xy = { 0.0, 0.0 }, m2xx_xy = m1xy, m2xz_yz = m1xy, m2yy_zz = m1xy;
  double m1z = 0.0;
  for (size_t m = 0; m < count; ++m)
  {
    const double* p = sorted + 3 * idx[m];
    const double d0 = (p[0] - x[0]) * inv, d1 = (p[1] - x[1]) * inv, d2 = (p[2] - x[2]) * inv;
    const Pair xy = { d0, d1 }, yz = { d1, d2 };
    m1xy += xy;
    m1z += d2;
    m2xx_xy += d0 * xy;
    m2xz_yz += d2 * xy;
    m2yy_zz += yz * yz;
  }
  m1[0] = m1xy[0];
  m1[1] = m1xy[1];
  m1[2] = m1z;
  const double sums[6] = { m2xx_xy[0], m2xx_xy[1], m2xz_yz[0], m2yy_zz[0], m2xz_yz[1], m2yy_zz[1] };
  std::copy(sums, sums + 6, m2);
}

#ifdef MESHFREE_NORMALS_AVX2
/// CovarianceSums with AVX2 (no FMA in the target: every product and sum is rounded as in the portable code, and
/// each lane sums in the points' order, so the bits are the same): d = (d0, d1, d2, 0) in one register.
__attribute__((target("avx2"))) void CovarianceSumsAvx2(const double* sorted, const Index* idx, size_t count,
  const double x[3], double inv, double m1[3], double m2[6])
{
  const __m256i three = _mm256_set_epi64x(0, -1, -1, -1);
  const __m256d origin = _mm256_maskload_pd(x, three), scale = _mm256_set1_pd(inv);
  __m256d first = _mm256_setzero_pd(), second = first, rest = first;
  for (size_t m = 0; m < count; ++m)
  {
    const __m256d d = _mm256_mul_pd(_mm256_sub_pd(_mm256_maskload_pd(sorted + 3 * idx[m], three), origin), scale);
    first = _mm256_add_pd(first, d);
    // (d0 d0, d0 d1, d0 d2, d1 d1) and (d1 d2, d2 d2, 0, 0).
    second = _mm256_add_pd(second,
      _mm256_mul_pd(_mm256_permute4x64_pd(d, 0x40), _mm256_permute4x64_pd(d, 0x64)));
    rest = _mm256_add_pd(rest, _mm256_mul_pd(_mm256_permute4x64_pd(d, 0xF9), _mm256_permute4x64_pd(d, 0xFA)));
  }
  alignas(32) double a[4], b[4], c[4];
  _mm256_store_pd(a, first);
  _mm256_store_pd(b, second);
  _mm256_store_pd(c, rest);
  for (int k = 0; k < 3; ++k)
  {
    m1[k] = a[k];
  }
  const double sums[6] = { b[0], b[1], b[2], b[3], c[0], c[1] };
  std::copy(sums, sums + 6, m2);
}
#endif

/// A hint that the cache line of p will be written soon (no effect on results).
inline void PrefetchForWrite(const void* p)
{
#if defined(__GNUC__)
  __builtin_prefetch(p, 1, 3);
#else
  (void)p;
#endif
}

/// Whether the fits' sums use the AVX2 kernels (SetNormalKernelsVectorized).
bool CpuHasAvx2()
{
#ifdef MESHFREE_NORMALS_AVX2
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}
std::atomic<bool> VectorKernels{ CpuHasAvx2() };

/// The mean offset (mean[3]) and the covariance's eigen-decomposition of the `count` points sorted + 3 idx[m], in
/// coordinates shifted to x and scaled by inv (|d| <= 1): one pass of first and second moments,
/// C = E[d d^T] - E[d] E[d]^T. False when the points span no plane (collinear or coincident: the closed-form
/// solver's eigenvalues are accurate to ~1e-9 of the largest, so a relative width below 1e-3 counts as a line).
bool ScaledCovariance(const double* sorted, const Index* idx, size_t count, const double x[3], double inv,
  double mean[3], Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>& eig)
{
  double m1[3], m2[6]; // xx xy xz yy yz zz
#ifdef MESHFREE_NORMALS_AVX2
  if (VectorKernels.load(std::memory_order_relaxed))
  {
    CovarianceSumsAvx2(sorted, idx, count, x, inv, m1, m2);
  }
  else
#endif
  {
    CovarianceSums(sorted, idx, count, x, inv, m1, m2);
  }
  const double w = 1.0 / static_cast<double>(count);
  for (int a = 0; a < 3; ++a)
  {
    mean[a] = m1[a] * w;
  }
  Eigen::Matrix3d C;
  C(0, 0) = m2[0] * w - mean[0] * mean[0];
  C(0, 1) = C(1, 0) = m2[1] * w - mean[0] * mean[1];
  C(0, 2) = C(2, 0) = m2[2] * w - mean[0] * mean[2];
  C(1, 1) = m2[3] * w - mean[1] * mean[1];
  C(1, 2) = C(2, 1) = m2[4] * w - mean[1] * mean[2];
  C(2, 2) = m2[5] * w - mean[2] * mean[2];
  eig.computeDirect(C);
  const Eigen::Vector3d l = eig.eigenvalues();
  return l(1) > 1e-6 * l(2) && l(2) > 0.0 && std::isfinite(l(2));
}

/// PCA of the points at sorted positions pos[0..count) of `sorted`, about their centroid, in coordinates
/// shifted to x and scaled by 1/scale (the noise estimate of the fits' radius, CloudScale::Radius).
LocalPCA PrincipalAxes(const double* sorted, const Index* pos, size_t count, const double x[3], double scale)
{
  LocalPCA out;
  if (count < 3 || !(scale > 0.0))
  {
    return out;
  }
  const double inv = 1.0 / scale;
  double m1[3];
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  if (!ScaledCovariance(sorted, pos, count, x, inv, m1, eig))
  {
    return out;
  }
  const Eigen::Vector3d l = eig.eigenvalues();
  Eigen::Vector3d n = eig.eigenvectors().col(0).normalized();
  // The distance from the point to the plane through the centroid.
  out.Residual = std::fabs(n(0) * m1[0] + n(1) * m1[1] + n(2) * m1[2]) * scale;
  for (int a = 0; a < 3; ++a)
  {
    out.Normal[a] = n(a);
    out.Eigenvalues[a] = std::max(0.0, l(a)) * scale * scale;
  }
  out.Valid = n.allFinite();
  return out;
}


struct JetFit
{
  double Normal[3] = { 0.0, 0.0, 0.0 };
  double Eigenvalues[3] = { 0.0, 0.0, 0.0 }; // of the PCA, ascending, world units squared
  double Residual = 0.0;  // distance from the point to its neighbours' jet
  double Height = 0.0;    // signed: the jet's height at the point along the normal (the point's own offset)
  double Rms = 0.0;       // root mean square misfit of the neighbours about their jet (world units)
  double Curvature = 0.0; // the larger absolute principal curvature of the jet (1 / length)
  // FitJet<true>: the mean curvature of the sphere-exact jet (see FitJet), positive where the surface bends away
  // from Normal (convex for an outward normal), 1 / length; 0 when that fit failed.
  double MeanCurvature = 0.0;
  bool Valid = false;
};

/// The mean curvature at the point of the implicit surface F = a0 + a1 u + a2 v + b3 U + b4 uv + b5 W - h = 0
/// with U = u^2 + h^2 / 2, W = v^2 + h^2 / 2 (scaled frame coordinates), signed positive where it bends away from
/// +h, in scaled units; evaluated at (0, 0, h0), the surface's point on the frame's axis. NaN when undefined.
double ImplicitMeanCurvature(const double b[6])
{
  const double c = 0.5 * (b[3] + b[5]); // the coefficient of h^2
  // F(0, 0, h) = a0 + c h^2 - h = 0: the root nearest 0 (stable form; no root: the point's own height).
  const double disc = 1.0 - 4.0 * c * b[0];
  const double h0 = disc >= 0.0 ? 2.0 * b[0] / (1.0 + std::sqrt(disc)) : b[0];
  // The gradient g and the Hessian [[2 b3, b4, 0], [b4, 2 b5, 0], [0, 0, 2 c]] at (0, 0, h0); the mean curvature
  // of the level set, div(g / |g|) / 2 = (|g|^2 tr H - g.H g) / (2 |g|^3) along g, which points to -h (g_h ~ -1).
  const double g0 = b[1], g1 = b[2], g2 = 2.0 * c * h0 - 1.0;
  const double h00 = 2.0 * b[3], h01 = b[4], h11 = 2.0 * b[5], h22 = 2.0 * c;
  const double gg = g0 * g0 + g1 * g1 + g2 * g2;
  const double gHg = h00 * g0 * g0 + 2.0 * h01 * g0 * g1 + h11 * g1 * g1 + h22 * g2 * g2;
  const double div = (gg * (h00 + h11 + h22) - gHg) / (gg * std::sqrt(gg));
  return -0.5 * div; // along +h
}

/// The sorted positions of `used` of the count entries of pos spread evenly over the list: entry m * count / used
/// for m < used (all of them when used == count), stepped without a division per entry.
void SpreadSubset(const Index* pos, size_t count, size_t used, Index* picked)
{
  const size_t whole = count / used, rest = count % used;
  size_t at = 0, carry = 0;
  for (size_t m = 0; m < used; ++m)
  {
    picked[m] = pos[at]; // at = m * count / used, carry = m * count % used
    at += whole;
    carry += rest;
    if (carry >= used)
    {
      carry -= used;
      ++at;
    }
  }
}

/// SpreadSubset's entries: pos itself when all of them are used (the same list, without the copy), else the subset
/// written to `subset`.
const Index* Spread(const Index* pos, size_t count, size_t used, Index* subset)
{
  if (used == count)
  {
    return pos;
  }
  SpreadSubset(pos, count, used, subset);
  return subset;
}

/// The sums of a jet's least squares (FitJet) in the frame (e1, e2, e3) = (t1, t2, n): over the points whose
/// scaled offset d = (p - x) inv is not zero, with u = d.e1, v = d.e2, h = d.e3 and q = h^2 / 2, each summed in the
/// points' order: U the monomials 1 u v uu uv vv uuu uuv uvv vvv uuuu uuuv uuvv uvvv vvvv (U[0] the count), H the
/// products h (1 u v uu uv vv), HH = sum h h and, WithCurvature, Q = sums of q, hq, uq, vq, uuq, uvq, vvq, qq.
struct JetSums
{
  double U[15] = {};
  double H[6] = {};
  double HH = 0.0;
  double Q[8] = {};
  size_t Fitted = 0;
};

template <bool WithCurvature>
void AccumulateJet(const double* sorted, const Index* picked, size_t used, const double x[3], double inv,
  const double e1[3], const double e2[3], const double e3[3], JetSums& out)
{
  size_t fitted = 0;
  // Pairs of the sums side by side (each lane the products and additions of one sum, in the order of the list:
  // the bits of a scalar loop, in about half the instructions).
  const Pair f0 = { e1[0], e2[0] }, f1 = { e1[1], e2[1] }, f2 = { e1[2], e2[2] };
  Pair s12 = { 0.0, 0.0 }, s34 = s12, s67 = s12, s89 = s12, s1011 = s12, s1213 = s12, h12 = s12, h34 = s12,
       h5h = s12;
  double s5 = 0.0, s14 = 0.0, h0 = 0.0;
  // The curvature jet's extra sums, of q = h^2 / 2: (q, hq), (uq, vq), (uuq, uvq), (vvq, qq).
  Pair q1 = { 0.0, 0.0 }, q2 = q1, q3 = q1, q4 = q1;
  for (size_t m = 0; m < used; ++m)
  {
    const double* p = sorted + 3 * picked[m];
    const double d0 = (p[0] - x[0]) * inv, d1 = (p[1] - x[1]) * inv, d2 = (p[2] - x[2]) * inv;
    if (d0 == 0.0 && d1 == 0.0 && d2 == 0.0)
    {
      continue;
    }
    const Pair uv2 = d0 * f0 + d1 * f1 + d2 * f2; // (u, v)
    const double u = uv2[0], v = uv2[1];
    const double h = d0 * e3[0] + d1 * e3[1] + d2 * e3[2];
    const Pair quad = u * uv2; // (uu, uv)
    const double uu = quad[0], vv = v * v;
    s12 += uv2;
    s34 += quad;
    s5 += vv;
    s67 += uu * uv2;    // (uuu, uuv)
    s89 += vv * uv2;    // (uvv, vvv)
    s1011 += uu * quad; // (uuuu, uuuv)
    s1213 += vv * quad; // (uuvv, uvvv)
    s14 += vv * vv;
    h0 += h;
    h12 += h * uv2;
    h34 += h * quad;
    const Pair vh = { vv, h };
    h5h += h * vh; // (h vv, h h)
    if constexpr (WithCurvature)
    {
      const double q = 0.5 * h * h;
      const Pair one_h = { 1.0, h }, vv_q = { vv, q };
      q1 += q * one_h;
      q2 += q * uv2;
      q3 += q * quad;
      q4 += q * vv_q;
    }
    ++fitted;
  }
  const double u[15] = { static_cast<double>(fitted), s12[0], s12[1], s34[0], s34[1], s5, s67[0], s67[1], s89[0],
    s89[1], s1011[0], s1011[1], s1213[0], s1213[1], s14 };
  const double h[6] = { h0, h12[0], h12[1], h34[0], h34[1], h5h[0] };
  const double q[8] = { q1[0], q1[1], q2[0], q2[1], q3[0], q3[1], q4[0], q4[1] };
  std::copy(u, u + 15, out.U);
  std::copy(h, h + 6, out.H);
  std::copy(q, q + 8, out.Q);
  out.HH = h5h[1];
  out.Fitted = fitted;
}

#ifdef MESHFREE_NORMALS_AVX2
/// AccumulateJet with AVX2, the same bits: no FMA in the target (every product and sum rounded as in the portable
/// code), each lane one sum, in the points' order, of the same products (IEEE products commute). Per point
/// t = (u, v, h, 0) = (d0 E0 + d1 E1) + d2 E2 as the portable code sums it, s = (uu, uv, vv, q) with
/// q = (0.5 h) h, and six (eight with the curvature) lanes of four sums each.
template <bool WithCurvature>
__attribute__((target("avx2"))) void AccumulateJetAvx2(const double* sorted, const Index* picked, size_t used,
  const double x[3], double inv, const double e1[3], const double e2[3], const double e3[3], JetSums& out)
{
  const __m256d x0 = _mm256_set1_pd(x[0]), x1 = _mm256_set1_pd(x[1]), x2 = _mm256_set1_pd(x[2]);
  const __m256d scale = _mm256_set1_pd(inv);
  const __m256d f0 = _mm256_set_pd(0.0, e3[0], e2[0], e1[0]), f1 = _mm256_set_pd(0.0, e3[1], e2[1], e1[1]),
                f2 = _mm256_set_pd(0.0, e3[2], e2[2], e1[2]);
  const __m256d halve = _mm256_set_pd(0.5, 1.0, 1.0, 1.0);
  const __m256i magnitude = _mm256_set1_epi64x(0x7FFFFFFFFFFFFFFFLL);
  __m256d linear = _mm256_setzero_pd(); // u v h -
  __m256d quadratic = linear;           // uu uv vv q
  __m256d cubic = linear;               // uuu uuv uvv vvv
  __m256d quartic = linear;             // uuuu uuuv uuvv uvvv
  __m256d heights = linear;             // hu hv huu huv
  __m256d mixed = linear;               // vvvv hvv hh hq
  __m256d curved = linear;              // qu qv quu quv
  __m256d squares = linear;             // qvv qq - -
  size_t fitted = 0;
  for (size_t m = 0; m < used; ++m)
  {
    const double* p = sorted + 3 * picked[m];
    const __m256d d0 = _mm256_mul_pd(_mm256_sub_pd(_mm256_broadcast_sd(p), x0), scale);
    const __m256d d1 = _mm256_mul_pd(_mm256_sub_pd(_mm256_broadcast_sd(p + 1), x1), scale);
    const __m256d d2 = _mm256_mul_pd(_mm256_sub_pd(_mm256_broadcast_sd(p + 2), x2), scale);
    // All three zero (either sign): the point itself or a duplicate, not fitted.
    if (_mm256_testz_si256(_mm256_castpd_si256(_mm256_or_pd(_mm256_or_pd(d0, d1), d2)), magnitude))
    {
      continue;
    }
    const __m256d t =
      _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d0, f0), _mm256_mul_pd(d1, f1)), _mm256_mul_pd(d2, f2));
    // (u, u, v, h) (1, 1, 1, 0.5) (u, v, v, h)
    const __m256d s = _mm256_mul_pd(_mm256_mul_pd(_mm256_permute4x64_pd(t, 0x90), halve),
      _mm256_permute4x64_pd(t, 0x94));
    linear = _mm256_add_pd(linear, t);
    quadratic = _mm256_add_pd(quadratic, s);
    const __m256d uuvv = _mm256_permute_pd(s, 0x0);          // uu uu vv vv
    const __m256d uv = _mm256_permute2f128_pd(t, t, 0x00);   // u v u v
    const __m256d quad = _mm256_permute2f128_pd(s, s, 0x00); // uu uv uu uv
    cubic = _mm256_add_pd(cubic, _mm256_mul_pd(uuvv, uv));
    quartic = _mm256_add_pd(quartic, _mm256_mul_pd(uuvv, quad));
    const __m256d lowTerms = _mm256_permute2f128_pd(t, s, 0x20); // u v uu uv
    heights = _mm256_add_pd(heights, _mm256_mul_pd(_mm256_permute4x64_pd(t, 0xAA), lowTerms));
    const __m256d tail = _mm256_permute2f128_pd(s, t, 0x31); // vv q h 0
    // (vv, vv, h, h) (vv, h, h, q)
    mixed = _mm256_add_pd(mixed, _mm256_mul_pd(_mm256_permute_pd(tail, 0x0), _mm256_permute4x64_pd(tail, 0x68)));
    if constexpr (WithCurvature)
    {
      const __m256d q = _mm256_permute4x64_pd(s, 0xFF);
      curved = _mm256_add_pd(curved, _mm256_mul_pd(q, lowTerms));
      squares = _mm256_add_pd(squares, _mm256_mul_pd(q, tail));
    }
    ++fitted;
  }
  alignas(32) double a[8][4];
  _mm256_store_pd(a[0], linear);
  _mm256_store_pd(a[1], quadratic);
  _mm256_store_pd(a[2], cubic);
  _mm256_store_pd(a[3], quartic);
  _mm256_store_pd(a[4], heights);
  _mm256_store_pd(a[5], mixed);
  _mm256_store_pd(a[6], curved);
  _mm256_store_pd(a[7], squares);
  const double u[15] = { static_cast<double>(fitted), a[0][0], a[0][1], a[1][0], a[1][1], a[1][2], a[2][0], a[2][1],
    a[2][2], a[2][3], a[3][0], a[3][1], a[3][2], a[3][3], a[5][0] };
  const double h[6] = { a[0][2], a[4][0], a[4][1], a[4][2], a[4][3], a[5][1] };
  const double q[8] = { a[1][3], a[5][3], a[6][0], a[6][1], a[6][2], a[6][3], a[7][0], a[7][1] };
  std::copy(u, u + 15, out.U);
  std::copy(h, h + 6, out.H);
  std::copy(q, q + 8, out.Q);
  out.HH = a[5][2];
  out.Fitted = fitted;
}
#endif

/// The jet's moment sums with the kernels chosen at run time (AVX2 where the CPU has it and they are enabled:
/// SetNormalKernelsVectorized), the same bits either way.
template <bool WithCurvature>
void AccumulateJetSums(const double* sorted, const Index* picked, size_t used, const double x[3], double inv,
  const double e1[3], const double e2[3], const double e3[3], JetSums& out)
{
#ifdef MESHFREE_NORMALS_AVX2
  if (VectorKernels.load(std::memory_order_relaxed))
  {
    AccumulateJetAvx2<WithCurvature>(sorted, picked, used, x, inv, e1, e2, e3, out);
    return;
  }
#endif
  AccumulateJet<WithCurvature>(sorted, picked, used, x, inv, e1, e2, e3, out);
}

/// The jet's normal equations from its moment sums: M(i, j) = sum b_i b_j (the monomial of b_i times b_j, from
/// sums.U: 1 u v uu uv vv uuu uuv uvv vvv uuuu uuuv uuvv uvvv vvvv) and B(i) = sum h b_i, b = (1, u, v, u^2, uv, v^2).
void JetSystem(const JetSums& sums, Eigen::Matrix<double, 6, 6>& M, Eigen::Matrix<double, 6, 1>& B)
{
  static constexpr int Product[6][6] = { { 0, 1, 2, 3, 4, 5 }, { 1, 3, 4, 6, 7, 8 }, { 2, 4, 5, 7, 8, 9 },
    { 3, 6, 7, 10, 11, 12 }, { 4, 7, 8, 11, 12, 13 }, { 5, 8, 9, 12, 13, 14 } };
  for (int i = 0; i < 6; ++i)
  {
    B(i) = sums.H[i];
    for (int j = 0; j < 6; ++j)
    {
      M(i, j) = sums.U[Product[i][j]];
    }
  }
}

/// A degree-2 jet (Cazals & Pouget 2005) over up to MaxFit of the points at sorted positions pos[0..count)
/// (a subset spread evenly over the list when there are more: the list is in cell order, so the subset is
/// spread over the neighbourhood and depends only on the positions), in coordinates shifted to x and scaled
/// by 1/scale. The frame is the subset's PCA; the jet h = a0 + a1 u + a2 v + a3 u^2 + a4 uv + a5 v^2 of the
/// height over its plane is fitted to the neighbours (the point itself and its duplicates left out, so a0 is
/// its distance to its neighbours' surface) and the normal is n - a1 t1 - a2 t2. Exact on quadrics; for a
/// support symmetric about x the slopes are orthogonal to the quadratic terms, so noise tilts them no more
/// than it tilts PCA's plane. Fewer than 2 neighbours per term or a degenerate jet: the PCA plane.
/// WithCurvature: also MeanCurvature, from a second jet over the same neighbours and frame in which u^2 and v^2
/// are completed to U = u^2 + h^2 / 2 and W = v^2 + h^2 / 2: a sphere in any frame is
/// h = a0 + a1 u + a2 v + c (u^2 + v^2 + h^2), so that jet is exact on spheres (the plain jet's mean curvature is
/// off by about (kappa R)^2 / 4 there), and on other surfaces as accurate as the jet to second order; its mean
/// curvature is that of the implicit surface it defines (ImplicitMeanCurvature). The normal stays the plain jet's
/// (the same bits either way: the second jet's sums are sums of their own).
template <bool WithCurvature = false>
JetFit FitJet(const double* sorted, const Index* pos, size_t count, const double x[3], double scale,
  size_t limit = MaxFit)
{
  JetFit out;
  if (count < 3 || !(scale > 0.0))
  {
    return out;
  }
  const size_t used = std::min(count, std::min(limit, MaxThinFit));
  Index subset[MaxThinFit];
  const Index* picked = Spread(pos, count, used, subset);
  // The frame (PCA) from fewer points still: the jet corrects its tilt.
  const size_t framed = std::min(used, FramePoints);
  Index framePicked[FramePoints];
  SpreadSubset(pos, count, framed, framePicked);
  const double inv = 1.0 / scale;
  double m1[3];
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  if (!ScaledCovariance(sorted, framePicked, framed, x, inv, m1, eig))
  {
    return out; // collinear or coincident: no plane
  }
  const Eigen::Vector3d l = eig.eigenvalues();
  Eigen::Vector3d n = eig.eigenvectors().col(0).normalized();
  const Eigen::Vector3d t1 = eig.eigenvectors().col(2).normalized();
  const Eigen::Vector3d t2 = n.cross(t1);
  bool jet = false;
  if (used >= 12)
  {
    // Moments of the basis b = (1, u, v, u^2, uv, v^2): sums of u^i v^j up to i + j = 4, and of h b.
    const double e1[3] = { t1(0), t1(1), t1(2) }, e2[3] = { t2(0), t2(1), t2(2) }, e3[3] = { n(0), n(1), n(2) };
    JetSums sums;
    AccumulateJetSums<WithCurvature>(sorted, picked, used, x, inv, e1, e2, e3, sums);
    const double hh = sums.HH;
    const size_t fitted = sums.Fitted;
    Eigen::Matrix<double, 6, 6> M;
    Eigen::Matrix<double, 6, 1> B;
    JetSystem(sums, M, B);
    const Eigen::Matrix<double, 6, 6> moments = M;
    Eigen::Matrix<double, 6, 1> a;
    double condition = 0.0;
    if (fitted >= 12 && SolveMomentFast<6>(M, B, a, condition) && a.allFinite())
    {
      jet = true;
      // Residual sum of squares h.h - 2 a.B + a.M a (a.M a = a.B for the exact solution).
      const double rss = hh - 2.0 * a.dot(B) + a.dot(moments * a);
      out.Rms = std::sqrt(std::max(0.0, rss) / static_cast<double>(fitted - 6)) * scale;
      out.Height = a(0) * scale;
      out.Residual = std::fabs(a(0)) * scale;
      // Principal curvatures: the Hessian [[2 a3, a4], [a4, 2 a5]] / scale.
      const double mean = a(3) + a(5), diff = a(3) - a(5);
      const double root = std::sqrt(diff * diff + a(4) * a(4));
      out.Curvature = (std::fabs(mean) + root) / scale;
      n = (n - a(1) * t1 - a(2) * t2).normalized();
      if constexpr (WithCurvature)
      {
        // The basis (1, u, v, U, uv, W), U = uu + q, W = vv + q: its moments from the plain ones and q's.
        const double sq = sums.Q[0], shq = sums.Q[1], suq = sums.Q[2], svq = sums.Q[3], suuq = sums.Q[4],
                     suvq = sums.Q[5], svvq = sums.Q[6], sqq = sums.Q[7];
        Eigen::Matrix<double, 6, 6> C = moments;
        C(0, 3) += sq;
        C(0, 5) += sq;
        C(1, 3) += suq;
        C(1, 5) += suq;
        C(2, 3) += svq;
        C(2, 5) += svq;
        C(3, 3) += 2.0 * suuq + sqq;
        C(3, 4) += suvq;
        C(3, 5) += suuq + svvq + sqq;
        C(4, 5) += suvq;
        C(5, 5) += 2.0 * svvq + sqq;
        for (int i = 0; i < 6; ++i)
        {
          for (int j = 0; j < i; ++j)
          {
            C(i, j) = C(j, i);
          }
        }
        Eigen::Matrix<double, 6, 1> D = B, b;
        D(3) += shq;
        D(5) += shq;
        double conditionC = 0.0;
        if (SolveMomentFast<6>(C, D, b, conditionC) && b.allFinite())
        {
          const double k = ImplicitMeanCurvature(b.data()) / scale;
          // Along the jet's normal (n - a1 t1 - a2 t2 lies on +h's side).
          out.MeanCurvature = std::isfinite(k) ? k : 0.0;
        }
      }
    }
  }
  if (!jet)
  {
    // The plane through the centroid: the point's distance to it, and the spread about it.
    out.Height = (n(0) * m1[0] + n(1) * m1[1] + n(2) * m1[2]) * scale;
    out.Residual = std::fabs(out.Height);
    out.Rms = std::sqrt(std::max(0.0, l(0))) * scale;
  }
  for (int c = 0; c < 3; ++c)
  {
    out.Normal[c] = n(c);
    out.Eigenvalues[c] = std::max(0.0, l(c)) * scale * scale;
  }
  out.Valid = n.allFinite();
  return out;
}

/// The outliers' residual (NormalField::Residual): the distance from x to the degree-2 jet fitted to the points at
/// sorted positions pos[0..count) (x and its duplicates left out), as FitJet fits it but in the frame of the given
/// unit normal (the point's wide jet's) instead of the points' own PCA: the jet's constant term is invariant to the
/// tangent axes' rotation, and a frame a little off tilts the quadric without changing its fit, so the PCA (a
/// covariance pass and a 3 x 3 eigen-decomposition per point) is saved. Over up to MaxFit of the points spread
/// over the list; fewer than 12 fitted (or a singular jet): the distance to the plane through their centroid
/// along the normal. False when there are fewer than 3 points.
bool JetResidual(const double* sorted, const Index* pos, size_t count, const double x[3], double scale,
  const double normal[3], double& residual)
{
  if (count < 3 || !(scale > 0.0))
  {
    return false;
  }
  const size_t used = std::min(count, MaxFit);
  Index subset[MaxFit];
  const Index* picked = Spread(pos, count, used, subset);
  const double inv = 1.0 / scale;
  // Tangent axes: any orthonormal pair completing the normal.
  const double e3[3] = { normal[0], normal[1], normal[2] };
  const int smallest = std::fabs(e3[0]) <= std::fabs(e3[1]) ? (std::fabs(e3[0]) <= std::fabs(e3[2]) ? 0 : 2)
                                                            : (std::fabs(e3[1]) <= std::fabs(e3[2]) ? 1 : 2);
  double axis[3] = { 0.0, 0.0, 0.0 };
  axis[smallest] = 1.0;
  double e1[3] = { axis[1] * e3[2] - axis[2] * e3[1], axis[2] * e3[0] - axis[0] * e3[2],
    axis[0] * e3[1] - axis[1] * e3[0] };
  const double length = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  if (!(length > 0.0))
  {
    return false;
  }
  for (double& c : e1)
  {
    c /= length;
  }
  const double e2[3] = { e3[1] * e1[2] - e3[2] * e1[1], e3[2] * e1[0] - e3[0] * e1[2],
    e3[0] * e1[1] - e3[1] * e1[0] };
  JetSums sums;
  AccumulateJetSums<false>(sorted, picked, used, x, inv, e1, e2, e3, sums);
  if (sums.Fitted >= 12)
  {
    Eigen::Matrix<double, 6, 6> M;
    Eigen::Matrix<double, 6, 1> B, a;
    JetSystem(sums, M, B);
    double condition = 0.0;
    if (SolveMomentFast<6>(M, B, a, condition) && a.allFinite())
    {
      residual = std::fabs(a(0)) * scale;
      return true;
    }
  }
  if (sums.Fitted == 0)
  {
    return false;
  }
  // The plane through the centroid of the fitted points (U[1], U[2]: sums of u, v; H[0]: of h), along the normal.
  residual = std::fabs(sums.H[0] / static_cast<double>(sums.Fitted)) * scale;
  return std::isfinite(residual);
}

/// A hash of a position's coordinates (+0 and -0 alike): which thinned cloud a point's jet uses.
std::uint64_t PositionHash(const double x[3])
{
  std::uint64_t h = 0x243f6a8885a308d3ull;
  for (int a = 0; a < 3; ++a)
  {
    const double v = x[a] == 0.0 ? 0.0 : x[a];
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    h = (h ^ bits) * 0x9e3779b97f4a7c15ull;
    h ^= h >> 29;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 32;
  }
  return h;
}

/// The wide jets' thinned clouds: where the normals' radius holds far more points than a jet fits (MaxFit; at 1M
/// and 10M points of a noisy scan about 1000), each jet is fitted over one of `classes` thinned clouds, so that a
/// query filters that fraction of the candidates. The classes partition every cell of `grid`: its points (sorted
/// by position) in turn, from a phase set by the cell's coordinates, as the jets' own subset (SpreadSubset) steps
/// along a list in cell order (a random fraction, by a hash of the positions, was measured less accurate: the count
/// per cell then varies). A point's jet uses the class its position hashes to, so that neighbouring points fit
/// different subsets: their curvatures' noise stays independent and the smoothing takes it out (one shared thinned
/// cloud made the smoothed curvature's error 10-45 % larger). The selection depends on the cell's points alone:
/// the same whatever the order and the split of the cloud when the cell is whole (a distributed query's reach grows
/// by a cell's diagonal). Each class' grid is laid out from the whole cloud's frame (the same cells on every
/// process), its cells sqrt(classes) times as wide (as many points per cell on a surface). False when a class is
/// empty.
bool BuildThinnedClouds(const NeighborGrid& grid, int classes, std::vector<NeighborGrid>& thin)
{
  const Index nv = grid.NumberOfValidPoints();
  const double* sorted = grid.SortedPoints();
  double bounds[6];
  Index framePoints = 0, dims[3];
  grid.GetFrame(bounds, framePoints);
  grid.GetGridDimensions(dims);
  const double inverse = 1.0 / grid.CellSize();
  auto cellOf = [&](Index s, Index cell[3]) {
    for (int a = 0; a < 3; ++a)
    {
      cell[a] = GridAxisCell(sorted[3 * s + a] - bounds[2 * a], inverse, dims[a]);
    }
  };
  std::vector<detail::Buffer<double>> xyz(static_cast<size_t>(classes));
  for (detail::Buffer<double>& c : xyz)
  {
    detail::ReserveLarge(c, static_cast<size_t>(3 * (nv / classes + 1)));
  }
  Index begin = 0, first[3] = { 0, 0, 0 };
  if (nv > 0)
  {
    cellOf(0, first);
  }
  for (Index s = 0; s < nv; ++s)
  {
    Index next[3] = { -1, -1, -1 };
    if (s + 1 < nv)
    {
      cellOf(s + 1, next);
    }
    if (next[0] == first[0] && next[1] == first[1] && next[2] == first[2])
    {
      continue; // s is not the last point of its cell
    }
    // The cell [begin, s]: its points dealt to the classes in turn.
    const Index phase = (first[0] + 3 * first[1] + 7 * first[2]) % classes;
    for (Index j = begin; j <= s; ++j)
    {
      detail::Buffer<double>& c = xyz[static_cast<size_t>((j - begin + phase) % classes)];
      c.insert(c.end(), sorted + 3 * j, sorted + 3 * j + 3);
    }
    begin = s + 1;
    std::copy(next, next + 3, first);
  }
  thin.assign(static_cast<size_t>(classes), NeighborGrid());
  for (int c = 0; c < classes; ++c)
  {
    thin[c].SetFrame(bounds, std::max<Index>(1, framePoints / classes));
    if (!thin[c].Build(xyz[c].data(), static_cast<Index>(xyz[c].size() / 3),
          grid.CellSize() * std::sqrt(static_cast<double>(classes))))
    {
      thin.clear();
      return false;
    }
    detail::Buffer<double>().swap(xyz[c]);
  }
  return true;
}

/// From a radius query's result (sorted positions `pos`, squared distances `r2`) around a point: the distance
/// to its k-th nearest other point and its `degree` nearest others (original indices, in the neighbour order
/// of NeighborGrid::FindKNearest: distance, then position, then index), exact duplicates of the point left
/// out; only the list's points within sqrt(limit2) count (a wide list: its nearest part holds the k nearest, and
/// selecting among fewer is faster): first those within sqrt(first2) (<= limit2; usually enough), else all of
/// them. False (nothing written) when there are fewer than k. `keys` is scratch.
bool NearestOfList(const double* sorted, const Index* pos, const double* r2, size_t count, double first2,
  double limit2, int k, const std::vector<Index>& order, std::int32_t* row, int degree, double& kth,
  std::vector<double>& keys)
{
  if (k <= 0)
  {
    return false;
  }
  if (keys.size() < count)
  {
    keys.resize(count); // grows once per thread
  }
  // The k-th smallest of the distances within the limit (the point itself and its exact duplicates are not
  // neighbours): the same value whichever limit holds k of them, and a smaller set is faster to select in.
  size_t kept2 = 0;
  for (const double bound : { first2, limit2 })
  {
    kept2 = 0;
    for (size_t j = 0; j < count; ++j) // branch-free: the test decides whether the slot is kept
    {
      const double d2 = r2[j];
      keys[kept2] = d2;
      kept2 += d2 > 0.0 && d2 <= bound ? 1 : 0;
    }
    if (kept2 >= static_cast<size_t>(k) || bound >= limit2)
    {
      break;
    }
  }
  if (kept2 < static_cast<size_t>(k))
  {
    return false;
  }
  // The k-th smallest is the (kept2 - k + 1)-th largest: usually few (the first bound holds a little more than k),
  // kept sorted by insertion, which is cheaper than a selection over all of them.
  constexpr size_t MaxLargest = 16;
  const size_t largest = kept2 - static_cast<size_t>(k) + 1;
  double kth2;
  if (largest <= MaxLargest)
  {
    double top[MaxLargest]; // descending
    size_t held = 0;
    for (size_t j = 0; j < kept2; ++j)
    {
      const double v = keys[j];
      if (held == largest && !(v > top[largest - 1]))
      {
        continue;
      }
      size_t at = held < largest ? held++ : largest - 1;
      while (at > 0 && top[at - 1] < v)
      {
        top[at] = top[at - 1];
        --at;
      }
      top[at] = v;
    }
    kth2 = top[largest - 1];
  }
  else
  {
    std::nth_element(keys.begin(), keys.begin() + (k - 1), keys.begin() + static_cast<std::ptrdiff_t>(kept2));
    kth2 = keys[k - 1];
  }
  kth = std::sqrt(kth2);
  // The degree <= k nearest lie within the k-th distance.
  limit2 = kth2;
  // The `degree` first in the neighbour order, kept sorted by insertion (degree is small).
  constexpr int MaxDegree = 64;
  const int want = std::min(std::min(degree, k), MaxDegree);
  double bestD2[MaxDegree];
  Index bestPos[MaxDegree];
  int kept = 0;
  auto before = [&](double d2, Index p, double e2, Index q) {
    return NeighborGrid::NeighborBefore(d2, sorted + 3 * p, order[p], e2, sorted + 3 * q, order[q]);
  };
  for (size_t j = 0; j < count; ++j)
  {
    const double d2 = r2[j];
    const Index p = pos[j];
    if (!(d2 > 0.0) || d2 > limit2 || (kept == want && !before(d2, p, bestD2[want - 1], bestPos[want - 1])))
    {
      continue;
    }
    int at = kept < want ? kept++ : want - 1;
    while (at > 0 && before(d2, p, bestD2[at - 1], bestPos[at - 1]))
    {
      bestD2[at] = bestD2[at - 1];
      bestPos[at] = bestPos[at - 1];
      --at;
    }
    bestD2[at] = d2;
    bestPos[at] = p;
  }
  for (int j = 0; j < kept; ++j)
  {
    row[j] = static_cast<std::int32_t>(order[bestPos[j]]);
  }
  return true;
}

/// A jet's misfit over `count` neighbours (of which it fits at most MaxFit) as an estimate of the noise: its six
/// coefficients take up six of the degrees of freedom, rms^2 n / (n - 6).
double CorrectedMisfit(double rms, size_t count)
{
  const double n = static_cast<double>(std::min(count, MaxFit));
  return n > 6.0 ? rms * std::sqrt(n / (n - 6.0)) : rms;
}
/// The noise around x where a crease can hardly show: the corrected misfit of the jet over the neighbours within
/// half the radius (`positions` and `dist2`: those within the radius; `half`: scratch). A crease's misfit grows
/// with the radius (about twice from R / 2 to R for a V), noise's does not: a jet that misfits by more than the
/// cloud's median noise is taken for one across a crease only if it also misfits beyond this (SurfaceNormals.h,
/// "Sharp features"). 0 where fewer than LocalNoiseMinimum neighbours lie that near.
double LocalNoise(const double* sorted, const std::vector<Index>& positions, const std::vector<double>& dist2,
  const double x[3], double radius, std::vector<Index>& half)
{
  half.clear();
  const double limit = 0.25 * radius * radius;
  for (size_t c = 0; c < positions.size(); ++c)
  {
    if (dist2[c] <= limit)
    {
      half.push_back(positions[c]);
    }
  }
  if (half.size() < LocalNoiseMinimum)
  {
    return 0.0;
  }
  const JetFit fit = FitJet(sorted, half.data(), half.size(), x, 0.5 * radius);
  return fit.Valid ? CorrectedMisfit(fit.Rms, half.size()) : 0.0;
}
/// Sharp features. A jet whose neighbourhood reaches across a crease (a cube's edge or corner) misfits its
/// neighbours far beyond the noise and smears the normal. Such a point (misfit over FlagMisfit x the cloud's
/// noise, or fewer standard errors of a large fit's misfit: FlagSignificance, over FlagFloor x its radius, and
/// over FlagMisfit x its own LocalNoise) takes the normal of the neighbour, within its radius, whose jet
/// fits with the smallest misfit (at most 1 / FlagMisfit of its own) among those whose jet passes through the
/// point (within 3 x max(noise, that jet's misfit) of its tangent plane, plus the curvature's sag): the
/// neighbourhood that lies on the point's side of the crease. Only neighbours within MaxTurn / the median
/// curvature qualify (on a curved surface a far neighbour's normal is another one: the shipped sparse torus scan
/// lost 7 degrees of mean accuracy without this; 0.1 rad cost the 20k-point cube's edges half their gain). (Refitting the point's own jet over the
/// neighbours near that plane was measured worse: at the noise's scale the band takes in the other side.)
/// rms and height are per sorted position: the jets' misfit and the point's height over its jet.
/// meanCurvature: field.MeanCurvature follows the normal (the donor's, or the small jet's).
void SharpFeatures(const NeighborGrid& grid, NormalField& field, const std::vector<double>& rms,
  const std::vector<double>& height, bool meanCurvature, const Distribution* d)
{
  const double* sorted = grid.SortedPoints();
  const std::vector<Index>& order = grid.SortedOrder();
  const Index nv = static_cast<Index>(order.size());
  const double noise = field.Scale.FitNoise;
  // The replaced normals, applied after the pass (it reads the first ones).
  detail::Buffer<double> replaced(static_cast<size_t>(3 * nv), 0.0);
  detail::Buffer<unsigned char> changed(static_cast<size_t>(nv), 0);
  detail::Buffer<double> replacedCurvature(meanCurvature ? static_cast<size_t>(nv) : 0, 0.0);
  struct Buffers
  {
    std::vector<Index> Positions, Half;
    std::vector<double> Dist2;
  };
  PerThread<Buffers> buffers;
  // The height of y over sorted position j's tangent plane; its distance to j's jet (the height less the
  // point's own) less the band that still counts as on it.
  auto along = [&](Index j, const double* y) {
    const double* nj = &field.Normals[3 * order[j]];
    const double* xj = sorted + 3 * j;
    return nj[0] * (y[0] - xj[0]) + nj[1] * (y[1] - xj[1]) + nj[2] * (y[2] - xj[2]);
  };
  auto outside = [&](Index j, const double* y) {
    const double* xj = sorted + 3 * j;
    const double d[3] = { y[0] - xj[0], y[1] - xj[1], y[2] - xj[2] };
    const double sag = 0.5 * field.Scale.Curvature * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    return std::fabs(along(j, y) - height[j]) - (3.0 * std::max(noise, rms[j]) + sag);
  };
  // The points the jet fits at radius r: pi r^2 / spacing^2, at most MaxFit (FitJet's spread subset).
  const double perArea = field.Scale.Spacing > 0.0 ? Pi / (field.Scale.Spacing * field.Scale.Spacing) : 0.0;
  auto flagged = [&](Index j) {
    const double r = field.Radii[order[j]];
    const double fitted = std::min(static_cast<double>(MaxFit), perArea * r * r);
    const double limit = fitted > 1.0 ? std::min(FlagMisfit, 1.0 + FlagSignificance / std::sqrt(2.0 * fitted))
                                      : FlagMisfit;
    return rms[j] > limit * noise && rms[j] > FlagFloor * r;
  };
  ParallelFor(nv, 256, [&](Index b0, Index b1) {
    Buffers& mine = buffers.Local();
    for (Index s = b0; s < b1; ++s)
    {
      const Index id = order[s];
      const double radius = field.Radii[id];
      if (!field.Valid[id] || !flagged(s) || !IsOwn(d, id))
      {
        continue;
      }
      const double* x = sorted + 3 * s;
      grid.FindWithinRadiusPositions(x, radius, mine.Positions, mine.Dist2);
      // The point's own noise, not a crease: its jet misfits no more than the jet over half its radius does.
      const double local = LocalNoise(sorted, mine.Positions, mine.Dist2, x, radius, mine.Half);
      if (local > 0.0 && CorrectedMisfit(rms[s], mine.Positions.size()) <= FlagMisfit * local)
      {
        continue;
      }
      // The neighbour whose jet fits best, at most 1 / FlagMisfit as badly, and passes through the point.
      Index best = -1;
      double bestRms = rms[s] / FlagMisfit;
      // Only neighbours near enough that the curvature turns the normal by less than MaxTurn between them.
      const double reach2 = field.Scale.Curvature > 0.0 ? std::pow(MaxTurn / field.Scale.Curvature, 2) : HUGE_VAL;
      for (size_t c = 0; c < mine.Positions.size(); ++c)
      {
        const Index j = mine.Positions[c];
        if (j != s && mine.Dist2[c] <= reach2 && field.Valid[order[j]] && rms[j] < bestRms && outside(j, x) <= 0.0)
        {
          best = j;
          bestRms = rms[j];
        }
      }
      if (best >= 0)
      {
        std::copy(&field.Normals[3 * order[best]], &field.Normals[3 * order[best]] + 3, &replaced[3 * s]);
        if (meanCurvature)
        {
          replacedCurvature[s] = field.MeanCurvature[order[best]];
        }
        changed[s] = 1;
        continue;
      }
      // No side fits: the point lies in the crease itself (a step's face). The smallest neighbourhood the
      // noise allows (r_k, or the fits' noise radius) reaches across the least.
      const double small = std::max(field.NeighborDistance[id], field.Scale.Radius);
      if (small < radius)
      {
        grid.FindWithinRadiusPositions(x, small, mine.Positions, mine.Dist2);
        const JetFit fit = meanCurvature
          ? FitJet<true>(sorted, mine.Positions.data(), mine.Positions.size(), x, small)
          : FitJet(sorted, mine.Positions.data(), mine.Positions.size(), x, small);
        if (fit.Valid)
        {
          std::copy(fit.Normal, fit.Normal + 3, &replaced[3 * s]);
          if (meanCurvature)
          {
            replacedCurvature[s] = fit.MeanCurvature;
          }
          changed[s] = 1;
        }
      }
    }
  });
  // The jets' own normals are kept for the orientation (NormalField::JetNormals) on every process when any process
  // replaced one: near a ridge the donors carry the other face's normal, and propagating over them tied the faces
  // wrongly (noisy prisms 0.63 / 0.78 outward).
  Index replacedCount = 0;
  for (Index s = 0; s < nv; ++s)
  {
    replacedCount += changed[s] && IsOwn(d, order[s]) ? 1 : 0;
  }
  if (GlobalSum(d, replacedCount) > 0)
  {
    detail::ReserveLarge(field.JetNormals, field.Normals.size());
    field.JetNormals.assign(field.Normals.begin(), field.Normals.end());
  }
  for (Index s = 0; s < nv; ++s)
  {
    if (changed[s])
    {
      std::copy(&replaced[3 * s], &replaced[3 * s] + 3, &field.Normals[3 * order[s]]);
      if (meanCurvature)
      {
        field.MeanCurvature[order[s]] = replacedCurvature[s];
      }
    }
  }
  UpdateHalo(d, field.Normals, 3);
  if (meanCurvature)
  {
    UpdateHalo(d, field.MeanCurvature);
  }
}

/// Outliers: points alone in their surroundings, and points farther from their neighbourhood's quadric than
/// six times the median such distance
/// (about 4 sigma for Gaussian noise) and than 5 % of the neighbourhood radius (the floor for exact data,
/// above the quadric's own O(kappa^3 R^4) misfit).
void FlagOutliers(NormalField& field, const Distribution* d)
{
  std::vector<double> residuals, distances;
  const size_t n = field.Valid.size();
  detail::ReserveLarge(residuals, n);
  detail::ReserveLarge(distances, n);
  for (size_t i = 0; i < n; ++i)
  {
    if (field.Valid[i] && IsOwn(d, static_cast<Index>(i)))
    {
      residuals.push_back(field.Residual[i]);
      distances.push_back(field.NeighborDistance[i]);
    }
  }
  const double threshold =
    std::max(6.0 * GlobalMedian(d, std::move(residuals)), 0.05 * GlobalMedian(d, std::move(distances)));
  const int k = field.GraphDegree;
  // In parallel: the neighbours' r_k are read by original index (cache misses).
  field.OutlierCount += ParallelReduce(static_cast<Index>(n), 4096, Index(0),
    [&](Index b0, Index b1) {
      Index flagged = 0;
      for (Index i = b0; i < b1; ++i)
      {
        if (!field.Valid[i] || !IsOwn(d, i))
        {
          continue;
        }
        // Isolated: its k-th neighbour three times farther than its nearest neighbours' (a sparse region of a
        // scan has sparse neighbours too, so only points alone in their surroundings qualify).
        double around = 0.0;
        int counted = 0;
        for (int j = 0; j < k; ++j)
        {
          const std::int32_t v = field.Graph[static_cast<size_t>(i) * k + j];
          if (v >= 0)
          {
            around += field.NeighborDistance[v];
            ++counted;
          }
        }
        const bool isolated = counted > 0 && field.NeighborDistance[i] > 3.0 * around / counted;
        if (isolated || field.Residual[i] > threshold)
        {
          field.Outlier[i] = 1;
          ++flagged;
        }
      }
      return flagged;
    },
    [](Index a, Index b) { return a + b; });
  UpdateHalo(d, field.Outlier);
}

/// A distributed estimate: the halo points' estimates (every array SharpFeatures, FlagOutliers and the
/// orientation read of neighbours) replaced by their owners'. rms and height are per sorted position.
void ShareEstimates(const Distribution* d, const NeighborGrid& grid, NormalField& field, std::vector<double>& rms,
  std::vector<double>& height, bool meanCurvature)
{
  UpdateHalo(d, field.Normals, 3);
  UpdateHalo(d, field.Radii);
  UpdateHalo(d, field.NeighborDistance);
  UpdateHalo(d, field.Residual);
  UpdateHalo(d, field.SurfaceVariation);
  if (meanCurvature) // the same on every process (an empty piece's array is empty too)
  {
    UpdateHalo(d, field.MeanCurvature);
  }
  UpdateHalo(d, field.Valid);
  UpdateHaloRows(d, field.Graph, field.GraphDegree);
  UpdateHaloInOrder(d, grid.SortedOrder(), static_cast<Index>(field.Valid.size()), { &rms, &height });
}

/// The largest Shortfall of this process' sample queries, at local sample point j of radius(j).
template <class Radius>
double SampleShortfall(const Distribution* d, const CloudSample& sample, const double* sorted, const Radius& radius)
{
  double shortfall = -HUGE_VAL;
  for (size_t j = 0; d && j < sample.Local().size(); ++j)
  {
    shortfall = std::max(shortfall, Shortfall(d, sorted + 3 * sample.Local()[j], radius(j)));
  }
  return shortfall;
}

/// The radius that keeps the noise's tilt below tau: R^2 = 2 sigma h / (sqrt(pi) tau).
double NoiseRadius(double noise, double spacing, double tau)
{
  return std::sqrt(2.0 * noise * spacing / (std::sqrt(Pi) * tau));
}
/// The normals' radius (CloudScale::NormalRadius): rounds of (radius -> jets over the sample -> the noise as
/// their median misfit and the curvature as their median -> radius), see SurfaceNormals.h.
void EstimateNormalRadius(
  const NeighborGrid& grid, const NormalOptions& options, const CloudSample& sample, CloudScale& scale)
{
  const Distribution* d = options.Processes;
  const int k = std::max(3, options.NeighborCount);
  const double rk = scale.Spacing / std::sqrt(Pi / k);
  if (sample.Size() < 3 || !(rk > 0.0))
  {
    return;
  }
  const Index samples = sample.Size();
  const Index mineCount = static_cast<Index>(sample.Local().size());
  const double* sorted = grid.SortedPoints();
  std::vector<double> rms, curvature;
  std::vector<double> localRms(static_cast<size_t>(mineCount), 0.0), localCurvature(static_cast<size_t>(mineCount));
  // Each sample jet's misfit over its local noise (LocalNoise), as the creases' rule below compares it.
  std::vector<double> localExcess(static_cast<size_t>(mineCount), 0.0), excess;
  struct Buffers
  {
    std::vector<Index> Positions, Half;
    std::vector<double> Dist2;
  };
  PerThread<Buffers> buffers;
  const double cap = scale.Spacing * std::sqrt(MaxNeighbors / Pi);
  double radius = rk;
  // withExcess: also each jet's misfit over its local noise, which only the creases' rule reads (not the noise's
  // rounds, whose last fit the curvature's fitSample repeats).
  auto fitSample = [&](bool withExcess) {
    ParallelFor(mineCount, 16, [&](Index begin, Index end) {
      Buffers& mine = buffers.Local();
      for (Index j = begin; j < end; ++j)
      {
        const double* x = sorted + 3 * sample.Local()[j];
        grid.FindWithinRadiusPositions(x, radius, mine.Positions, mine.Dist2);
        const JetFit fit = FitJet(sorted, mine.Positions.data(), mine.Positions.size(), x, radius);
        localRms[j] = fit.Valid ? fit.Rms : 0.0;
        localCurvature[j] = fit.Valid ? fit.Curvature : 0.0;
        if (withExcess)
        {
          const double local = fit.Valid ? LocalNoise(sorted, mine.Positions, mine.Dist2, x, radius, mine.Half) : 0.0;
          localExcess[j] = local > 0.0 ? CorrectedMisfit(fit.Rms, mine.Positions.size()) / local : HUGE_VAL;
        }
      }
    });
    scale.SampleShortfall =
      std::max(scale.SampleShortfall, SampleShortfall(d, sample, sorted, [radius](size_t) { return radius; }));
    rms = sample.Gather(d, localRms);
    if (withExcess)
    {
      excess = sample.Gather(d, localExcess);
    }
    curvature = sample.Gather(d, localCurvature);
    // The misfit also grows where a neighbourhood takes in two sheets (a part thinner than it): the noise is
    // at most NoiseAgreement x the PCA spread at the fits' own radius (CloudScale::Noise), which stays small
    // there; the jets that misfit beyond it then shrink the radius as a crease's do.
    scale.FitNoise = std::min(Median(rms), NoiseAgreement * scale.Noise);
    scale.Curvature = Median(curvature);
  };
  // The noise's tilt sigma h / (sqrt(pi) R^2) per slope below NormalTilt, the cost at most MaxNeighbors. A
  // neighbourhood smaller than the noise hides it: rounds until the radius settles.
  for (int round = 0; round < 6; ++round)
  {
    fitSample(false);
    const double next = std::max(rk, std::min(NoiseRadius(scale.FitNoise, scale.Spacing, NormalTilt), cap));
    const bool settled = std::fabs(next - radius) < 0.05 * radius;
    radius = next;
    if (settled)
    {
      break;
    }
  }
  // The jet's bias (third order) kept small by staying within CurvatureReach / curvature, the curvature
  // measured at the noise's radius (at smaller radii the noise makes it up).
  fitSample(true);
  if (scale.Curvature > 0.0 && CurvatureReach / scale.Curvature < radius)
  {
    radius = std::max(rk, CurvatureReach / scale.Curvature);
    fitSample(true);
  }
  // Creases (a cube's edges): where more than MaxCrossing of the sample's jets misfit beyond the noise, both the
  // cloud's median and their own local noise (they reach across one), the radius shrinks. (Against the median
  // alone a range scan's noisier half, its noise growing with the square of the range, counted as creases.)
  for (int round = 0; round < 6 && radius > rk; ++round)
  {
    Index crossing = 0;
    for (size_t q = 0; q < rms.size(); ++q)
    {
      const double r = rms[q];
      crossing += r > FlagMisfit * scale.FitNoise && excess[q] > FlagMisfit && r > FlagFloor * radius ? 1 : 0;
    }
    if (static_cast<double>(crossing) <= MaxCrossing * static_cast<double>(samples))
    {
      break;
    }
    radius = std::max(rk, 0.8 * radius);
    fitSample(true);
  }
  scale.NormalRadius = radius > rk ? radius : 0.0;
}
} // namespace

CloudScale EstimateCloudScale(const NeighborGrid& grid, const NormalOptions& options)
{
  CloudScale scale;
  const Distribution* d = options.Processes;
  const Index nv = grid.NumberOfValidPoints();
  const std::vector<Index>& order = grid.SortedOrder();
  const double* sorted = grid.SortedPoints();
  // The sample: the same points whatever the input's order and split among processes (CloudSample).
  CloudSample sample;
  sample.Choose(d, sorted, nv, SamplePoints, [&](Index s) { return IsOwn(d, order[s]); });
  if (sample.Size() < 3)
  {
    return scale;
  }
  const int k = std::max(3, options.NeighborCount);
  const Index samples = static_cast<Index>(sample.Local().size());
  std::vector<double> kth(static_cast<size_t>(samples), 0.0);
  std::vector<double> spread(static_cast<size_t>(samples), 0.0);
  // Per-thread query buffers of both loops below.
  struct Buffers
  {
    std::vector<Index> Ids, Positions;
    std::vector<double> Dist2;
  };
  PerThread<Buffers> buffers;
  ParallelFor(samples, 16, [&](Index begin, Index end) {
    Buffers& mine = buffers.Local();
    std::vector<Index>& ids = mine.Ids;
    std::vector<double>& d2 = mine.Dist2;
    std::vector<Index>& pos = mine.Positions;
    for (Index j = begin; j < end; ++j)
    {
      const double* x = sorted + 3 * sample.Local()[j];
      const int found = NearestDistinct(grid, x, k, ids, d2, kth[j]);
      if (found < 4 || !(kth[j] > 0.0))
      {
        kth[j] = 0.0;
        continue;
      }
      grid.FindWithinRadiusPositions(x, kth[j], pos, d2);
      const LocalPCA pca = PrincipalAxes(sorted, pos.data(), pos.size(), x, kth[j]);
      spread[j] = pca.Valid ? std::sqrt(pca.Eigenvalues[0]) : 0.0;
    }
  });
  scale.SampleShortfall = SampleShortfall(d, sample, sorted, [&kth](size_t j) { return kth[j]; });
  const double rk = Median(sample.Gather(d, kth));
  scale.Spacing = rk * std::sqrt(Pi / k);
  scale.Noise = Median(sample.Gather(d, spread));
  if (!options.AdaptToNoise || !(scale.Spacing > 0.0))
  {
    return scale;
  }
  // Radius -> noise -> radius: a neighbourhood smaller than the noise hides it.
  double radius = std::max(rk, NoiseRadius(scale.Noise, scale.Spacing, options.TiltTolerance));
  for (int round = 0; round < 3 && radius > rk; ++round)
  {
    ParallelFor(samples, 16, [&](Index begin, Index end) {
      std::vector<Index>& pos = buffers.Local().Positions;
      std::vector<double>& d2 = buffers.Local().Dist2;
      for (Index j = begin; j < end; ++j)
      {
        const double* x = sorted + 3 * sample.Local()[j];
        grid.FindWithinRadiusPositions(x, radius, pos, d2);
        const LocalPCA pca = PrincipalAxes(sorted, pos.data(), pos.size(), x, radius);
        spread[j] = pca.Valid ? std::sqrt(pca.Eigenvalues[0]) : 0.0;
      }
    });
    scale.SampleShortfall =
      std::max(scale.SampleShortfall, SampleShortfall(d, sample, sorted, [radius](size_t) { return radius; }));
    scale.Noise = Median(sample.Gather(d, spread));
    const double next = std::max(rk, NoiseRadius(scale.Noise, scale.Spacing, options.TiltTolerance));
    const bool settled = std::fabs(next - radius) < 0.05 * radius;
    radius = next;
    if (settled)
    {
      break;
    }
  }
  scale.Radius = radius > rk ? radius : 0.0;
  EstimateNormalRadius(grid, options, sample, scale);
  return scale;
}

bool SetNormalKernelsVectorized(bool enable)
{
  const bool vector = enable && CpuHasAvx2();
  VectorKernels.store(vector);
  return vector;
}

bool EstimateNormals(
  const NeighborGrid& grid, const NormalOptions& options, NormalField& field, const ProgressCallback& progress)
{
  const Distribution* d = options.Processes;
  const Index n = grid.NumberOfPoints();
  const int degree = std::max(1, options.GraphDegree);
  // On huge pages where the arrays are fresh (Common/LargeArrays.h: their pages' first touch was a large part of the
  // time at 100k points).
  detail::AssignLarge(field.Normals, static_cast<size_t>(3 * n), 0.0);
  detail::AssignLarge(field.Radii, static_cast<size_t>(n), 0.0);
  detail::AssignLarge(field.NeighborDistance, static_cast<size_t>(n), 0.0);
  detail::AssignLarge(field.Residual, static_cast<size_t>(n), 0.0);
  detail::AssignLarge(field.Outlier, static_cast<size_t>(n), static_cast<unsigned char>(0));
  field.OutlierCount = 0;
  detail::AssignLarge(field.SurfaceVariation, static_cast<size_t>(n), 0.0);
  detail::AssignLarge(field.MeanCurvature, options.MeanCurvature ? static_cast<size_t>(n) : 0, 0.0);
  detail::AssignLarge(field.Valid, static_cast<size_t>(n), static_cast<unsigned char>(0));
  detail::AssignLarge(field.Graph, static_cast<size_t>(n * degree), std::int32_t(-1));
  field.GraphDegree = degree;
  field.Scale = CloudScale();
  field.InvalidCount = n;
  field.Shortfall = -HUGE_VAL;
  Index ownValid = grid.NumberOfValidPoints();
  if (d)
  {
    ownValid = 0;
    for (Index i : grid.SortedOrder())
    {
      ownValid += d->Owned(i) ? 1 : 0;
    }
    field.InvalidCount = 0;
    for (Index i = 0; i < n; ++i)
    {
      field.InvalidCount += d->Owned(i) ? 1 : 0;
    }
  }
  if (GlobalSum(d, ownValid) < 3)
  {
    return false;
  }
  const bool fixed = options.SupportRadius > 0.0;
  if (!fixed)
  {
    field.Scale = EstimateCloudScale(grid, options);
  }
  const double normalRadius = !options.AdaptToNoise ? 0.0
    : options.WideNormals                           ? field.Scale.NormalRadius
                                                    : field.Scale.Radius;
  const int k = std::max(std::max(3, options.NeighborCount), degree);
  // One query a little wider than the typical radius usually holds the k nearest, which saves the k-nearest
  // search (a third of the normals' time on noise-free clouds).
  const double typical = field.Scale.Spacing / std::sqrt(Pi / std::max(3, options.NeighborCount));
  const double first = fixed ? options.SupportRadius : std::max(1.1 * typical, normalRadius);
  const double near2 = fixed ? first * first : 1.21 * typical * typical;
  // The near part of the first list: the k nearest (within near2) and the outliers' neighbourhood.
  const double nearLimit2 = fixed ? near2 : std::max(near2, field.Scale.Radius * field.Scale.Radius);
  // The k nearest are those of the near part when it holds k within a distance up to which the query is complete
  // (its whole reach, not only near2: a point whose k-th neighbour lies a little beyond near2 would otherwise take
  // a k-nearest query and a second radius query, for the same result).
  const double nearestLimit2 = std::min(nearLimit2, first * first);
  const double* sorted = grid.SortedPoints();
  const std::vector<Index>& order = grid.SortedOrder();
  const Index nv = static_cast<Index>(order.size());
  const Index chunk = 65536;
  Index invalid = n - nv;
  // The wide jets over thinned clouds when their radius holds far more points than they fit (BuildThinnedClouds;
  // their number from the cloud's scale: the same on every process).
  std::vector<NeighborGrid> thin;
  bool thinned = false;
  if (!fixed && options.AdaptToNoise && options.WideNormals && normalRadius > 0.0 && field.Scale.Spacing > 0.0)
  {
    const double expected = Pi * normalRadius * normalRadius / (field.Scale.Spacing * field.Scale.Spacing);
    const double classes = std::floor(expected / ThinTarget);
    if (classes >= 2.0)
    {
      thinned = BuildThinnedClouds(grid, static_cast<int>(std::min(classes, 64.0)), thin);
    }
  }
  bool aborted = false;
  // Per sorted position: the jet's misfit and the point's height over it (the sharp features' pass below).
  std::vector<double> rms, height;
  detail::AssignLarge(rms, static_cast<size_t>(nv), 0.0);
  detail::AssignLarge(height, static_cast<size_t>(nv), 0.0);
  struct Buffers
  {
    std::vector<Index> Ids, Local;
    std::vector<double> Dist2, Keys;
    detail::Buffer<Index> Positions, Small;
    detail::Buffer<double> Radius2, SmallD2;
    double Shortfall = -HUGE_VAL;
  };
  PerThread<Buffers> buffers;
  for (Index begin = 0; begin < nv && !aborted; begin += chunk)
  {
    const Index end = std::min(nv, begin + chunk);
    const Index bad = ParallelReduce(end - begin, 256, Index(0),
      [&](Index b0, Index b1) {
        Buffers& mine = buffers.Local();
        std::vector<Index>& ids = mine.Ids;
        detail::Buffer<Index>& pos = mine.Positions;
        std::vector<double>& d2 = mine.Dist2;
        detail::Buffer<double>& r2 = mine.Radius2;
        std::vector<double>& keys = mine.Keys;
        Index failed = 0;
        double& shortfall = mine.Shortfall;
        for (Index s = begin + b0; s < begin + b1; ++s)
        {
          const Index id = order[s];
          if (s + 1 < begin + b1)
          {
            // The next point's outputs, written by original index (a cache miss each, which stalled the stores
            // at the end of a point): fetched for writing while this point is estimated.
            const Index next = order[s + 1];
            PrefetchForWrite(&field.Graph[static_cast<size_t>(next) * degree]);
            PrefetchForWrite(&field.Graph[static_cast<size_t>(next) * degree + degree - 1]);
            PrefetchForWrite(&field.Normals[3 * next]);
            PrefetchForWrite(&field.Normals[3 * next + 2]);
            PrefetchForWrite(&field.NeighborDistance[next]);
            PrefetchForWrite(&field.Residual[next]);
            PrefetchForWrite(&field.SurfaceVariation[next]);
            PrefetchForWrite(&field.Radii[next]);
            PrefetchForWrite(&field.Valid[next]);
            if (options.MeanCurvature)
            {
              PrefetchForWrite(&field.MeanCurvature[next]);
            }
          }
          if (!IsOwn(d, id))
          {
            continue; // a halo point: its owner estimates it
          }
          const double* x = sorted + 3 * s;
          std::int32_t* row = &field.Graph[static_cast<size_t>(id) * degree];
          // One radius query, wide enough for every radius the point may need, usually holds its k nearest too:
          // it gives r_k, the orientation graph and the neighbourhood. Otherwise a k-nearest query first.
          // Thinned: the wide list comes from the thinned cloud below, this query gives only the near part.
          if (first > 0.0 && !thinned)
          {
            grid.FindWithinRadiusPositions(x, first, pos, r2);
          }
          double queried = thinned ? 0.0 : first;
          // The near part of the list, once (a copy: the list may be cut or queried again below): the k nearest
          // and the outliers' small neighbourhood lie in it. When it is narrower than the list, from a query of its
          // own (a few cells: a pass over the wide list cost more, also fused into the wide query's filter), a little
          // wider since its radius squared may round below nearLimit2, then cut exactly: the list's points within
          // sqrt(nearLimit2), in its order.
          if (!thinned && !(first > 0.0 && nearLimit2 < first * first))
          {
            mine.Small.assign(pos.begin(), pos.end());
            mine.SmallD2.assign(r2.begin(), r2.end());
          }
          else
          {
            grid.FindWithinRadiusPositions(x, std::sqrt(nearLimit2) * (1.0 + 1e-9), mine.Small, mine.SmallD2);
            size_t nearCount = 0;
            for (size_t j = 0; j < mine.Small.size(); ++j) // branch-free: the test decides whether j is kept
            {
              mine.Small[nearCount] = mine.Small[j];
              mine.SmallD2[nearCount] = mine.SmallD2[j];
              nearCount += mine.SmallD2[j] <= nearLimit2 ? 1 : 0;
            }
            mine.Small.resize(nearCount);
            mine.SmallD2.resize(nearCount);
          }
          const Index* nearPos = mine.Small.data();
          const double* nearD2 = mine.SmallD2.data();
          if (!(first > 0.0 && NearestOfList(sorted, nearPos, nearD2, mine.Small.size(), near2, nearestLimit2, k,
                                 order, row, degree, field.NeighborDistance[id], keys)))
          {
            const int found = NearestDistinct(grid, x, k, ids, d2, field.NeighborDistance[id]);
            int kept = 0;
            for (int j = 0; j < found && kept < degree; ++j)
            {
              if (d2[j] > 0.0)
              {
                row[kept++] = static_cast<std::int32_t>(ids[j]);
              }
            }
            queried = 0.0;
          }
          const double rk = field.NeighborDistance[id];
          const double radius = fixed ? options.SupportRadius : std::max(rk, normalRadius);
          if (d)
          {
            // Thinned: the cells the jet's query touches must be whole (BuildThinnedClouds).
            const double reach = thinned ? radius + std::sqrt(3.0) * grid.CellSize() : radius;
            const double farthest = std::max(std::max(queried, reach), std::max(rk, std::sqrt(nearLimit2)));
            shortfall = std::max(shortfall, Shortfall(d, x, farthest));
          }
          // The coordinates the jet's list refers to (the thinned cloud's when it comes from there).
          const double* fitSorted = sorted;
          if (thinned)
          {
            const NeighborGrid& mineThin = thin[PositionHash(x) % thin.size()];
            mineThin.FindWithinRadiusPositions(x, radius, pos, r2);
            fitSorted = mineThin.SortedPoints();
            if (pos.size() < ThinFloor)
            {
              grid.FindWithinRadiusPositions(x, radius, pos, r2); // sparse here: the whole cloud's
              fitSorted = sorted;
            }
          }
          else if (queried < radius)
          {
            grid.FindWithinRadiusPositions(x, radius, pos, r2);
          }
          else if (queried > radius)
          {
            // The neighbourhood is the points within the radius, as a query at it would give them.
            const double cut = radius * radius;
            size_t kept = 0;
            for (size_t j = 0; j < pos.size(); ++j)
            {
              if (r2[j] <= cut)
              {
                pos[kept] = pos[j];
                r2[kept++] = r2[j];
              }
            }
            pos.resize(kept);
            r2.resize(kept);
          }
          const size_t limit = fitSorted == sorted ? MaxFit : MaxThinFit;
          const JetFit fit = options.MeanCurvature
            ? FitJet<true>(fitSorted, pos.data(), pos.size(), x, radius, limit)
            : FitJet(fitSorted, pos.data(), pos.size(), x, radius, limit);
          if (!fit.Valid)
          {
            ++failed;
            continue;
          }
          if (options.MeanCurvature)
          {
            field.MeanCurvature[id] = fit.MeanCurvature;
          }
          for (int a = 0; a < 3; ++a)
          {
            field.Normals[3 * id + a] = fit.Normal[a];
          }
          // The outliers' residual from the smallest neighbourhood the noise allows (r_k, or the fits' noise
          // radius), as the implicit fits use it: a wide jet near a crease would find every point there far.
          const double small = fixed ? radius : std::max(rk, field.Scale.Radius);
          field.Residual[id] = fit.Residual;
          if (small < radius)
          {
            const double cut = small * small;
            // The near list holds them (it is the whole cloud's whenever a query made it); else the jet's list
            // when it is the whole cloud's, or a query of their own (the jet's is the thinned cloud's).
            const bool inNear = (queried > 0.0 || thinned) && first > 0.0 && cut <= nearLimit2;
            if (!inNear && fitSorted != sorted)
            {
              grid.FindWithinRadiusPositions(x, small, pos, r2);
            }
            const Index* from = inNear ? nearPos : pos.data();
            const double* fromD2 = inNear ? nearD2 : r2.data();
            const size_t fromCount = inNear ? mine.Small.size() : pos.size();
            if (mine.Local.size() < fromCount)
            {
              mine.Local.resize(fromCount); // grows once per thread
            }
            size_t local = 0;
            for (size_t j = 0; j < fromCount; ++j) // branch-free
            {
              mine.Local[local] = from[j];
              local += fromD2[j] <= cut ? 1 : 0;
            }
            double residual = 0.0;
            field.Residual[id] =
              JetResidual(sorted, mine.Local.data(), local, x, small, fit.Normal, residual) ? residual : fit.Residual;
          }
          const double total = fit.Eigenvalues[0] + fit.Eigenvalues[1] + fit.Eigenvalues[2];
          field.SurfaceVariation[id] = total > 0.0 ? fit.Eigenvalues[0] / total : 0.0;
          field.Radii[id] = radius;
          field.Valid[id] = 1;
          rms[s] = fit.Rms;
          height[s] = fit.Height;
        }
        return failed;
      },
      [](Index a, Index b) { return a + b; });
    invalid += bad;
    aborted = progress && !progress(0.9 * static_cast<double>(end) / static_cast<double>(nv));
  }
  if (d)
  {
    // Over own points only; the halo's estimates come from their owners (aborting is not collective: the
    // processes go on together and the caller discards the result).
    invalid = 0;
    for (Index i = 0; i < n; ++i)
    {
      invalid += d->Owned(i) && !field.Valid[i] ? 1 : 0;
    }
    ShareEstimates(d, grid, field, rms, height, options.MeanCurvature);
  }
  field.InvalidCount = invalid;
  for (const Buffers& b : buffers)
  {
    field.Shortfall = std::max(field.Shortfall, b.Shortfall);
  }
  field.Shortfall = std::max(field.Shortfall, field.Scale.SampleShortfall);
  if (!fixed && options.AdaptToNoise && options.WideNormals && (d || !aborted))
  {
    SharpFeatures(grid, field, rms, height, options.MeanCurvature, d);
    aborted = aborted || (progress && !progress(1.0));
  }
  if (d || !aborted)
  {
    FlagOutliers(field, d);
  }
  return !aborted && (d || invalid < n);
}

std::vector<double> FitSupports(const NormalField& field, double supportScale, double noiseScale, bool fixedRadius,
  double& median, const Distribution* d)
{
  const size_t n = field.Radii.size();
  std::vector<double> support(n, 0.0);
  for (size_t i = 0; i < n; ++i)
  {
    if (!(field.Radii[i] > 0.0) || field.Outlier[i])
    {
      continue;
    }
    support[i] = fixedRadius ? supportScale * field.Radii[i]
                             : std::max(supportScale * field.NeighborDistance[i], noiseScale * field.Scale.Radius);
  }
  std::vector<double> positive;
  positive.reserve(n);
  for (size_t i = 0; i < n; ++i)
  {
    if (support[i] > 0.0 && IsOwn(d, static_cast<Index>(i)))
    {
      positive.push_back(support[i]);
    }
  }
  median = GlobalMedian(d, std::move(positive));
  for (double& r : support)
  {
    r = std::min(r, 3.0 * median);
  }
  return support;
}

} // namespace meshfree
