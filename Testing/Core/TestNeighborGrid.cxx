// SPDX-License-Identifier: BSD-3-Clause
// NeighborGrid against brute force: radius results as exact index sets, k-nearest results as exact
// (distance, index) lists. The grid breaks distance ties by position (x, y, z) and exact duplicates by the
// original index, so the brute-force reference (the first k of all points sorted that way) is unique even with
// duplicates.
#include "Common/NeighborGrid.h"
#include "Common/Parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

namespace
{
using meshfree::Index;
using meshfree::NeighborGrid;
using Cloud = std::vector<double>; // interleaved x, y, z

constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double Inf = std::numeric_limits<double>::infinity();

Index Count(const Cloud& c)
{
  return static_cast<Index>(c.size() / 3);
}

bool Valid(const double* p)
{
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

// The same expression, in the same order, as the grid: distances must agree to the last bit.
double Distance2(const double* p, const double* x)
{
  const double dx = p[0] - x[0], dy = p[1] - x[1], dz = p[2] - x[2];
  return dx * dx + dy * dy + dz * dz;
}

std::vector<std::pair<double, Index>> SortedDistances(const Cloud& c, const double* x)
{
  std::vector<std::pair<double, Index>> all;
  for (Index i = 0; i < Count(c); ++i)
  {
    if (Valid(&c[3 * i]))
    {
      all.emplace_back(Distance2(&c[3 * i], x), i);
    }
  }
  std::sort(all.begin(), all.end(), [&c](const std::pair<double, Index>& a, const std::pair<double, Index>& b) {
    return NeighborGrid::NeighborBefore(a.first, &c[3 * a.second], a.second, b.first, &c[3 * b.second], b.second);
  });
  return all;
}

Cloud Uniform(Index n, std::uint32_t seed, double lo = 0.0, double hi = 1.0)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  Cloud c(3 * n);
  for (double& v : c)
  {
    v = u(rng);
  }
  return c;
}

// Positions to query: every `stride`-th point of the cloud, and random probes in and around its bounds.
Cloud Queries(const Cloud& c, Index stride, Index probes, std::uint32_t seed)
{
  Cloud q;
  for (Index i = 0; i < Count(c); i += stride)
  {
    if (Valid(&c[3 * i]))
    {
      q.insert(q.end(), &c[3 * i], &c[3 * i] + 3);
    }
  }
  double lo[3] = { Inf, Inf, Inf }, hi[3] = { -Inf, -Inf, -Inf };
  for (Index i = 0; i < Count(c); ++i)
  {
    for (int a = 0; a < 3 && Valid(&c[3 * i]); ++a)
    {
      lo[a] = std::min(lo[a], c[3 * i + a]);
      hi[a] = std::max(hi[a], c[3 * i + a]);
    }
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.25, 1.25);
  for (Index i = 0; i < probes && lo[0] <= hi[0]; ++i)
  {
    for (int a = 0; a < 3; ++a)
    {
      const double width = std::max(hi[a] - lo[a], 1e-3 * (hi[0] - lo[0] + hi[1] - lo[1] + hi[2] - lo[2]));
      q.push_back(lo[a] + u(rng) * width);
    }
  }
  return q;
}

using Reference = std::vector<std::pair<double, Index>>; // brute force: (distance^2, index), sorted

void ExpectRadiusMatches(
  const NeighborGrid& grid, const Reference& all, const double* x, double radius)
{
  std::vector<Index> ids;
  std::vector<double> d2;
  grid.FindWithinRadius(x, radius, ids, &d2);
  ASSERT_EQ(ids.size(), d2.size());
  std::vector<std::pair<Index, double>> got;
  for (std::size_t i = 0; i < ids.size(); ++i)
  {
    got.emplace_back(ids[i], d2[i]);
  }
  std::sort(got.begin(), got.end());
  std::vector<std::pair<Index, double>> expected;
  for (const auto& [dist2, id] : all)
  {
    if (dist2 <= radius * radius)
    {
      expected.emplace_back(id, dist2);
    }
  }
  std::sort(expected.begin(), expected.end());
  ASSERT_EQ(got, expected) << "radius " << radius << " at (" << x[0] << ", " << x[1] << ", " << x[2] << ")";
  EXPECT_EQ(grid.CountWithinRadius(x, radius), static_cast<Index>(expected.size()));
}

void ExpectKNearestMatches(const NeighborGrid& grid, const Reference& all, const double* x, int k)
{
  std::vector<Index> ids;
  std::vector<double> d2;
  const int found = grid.FindKNearest(x, k, ids, d2);
  const std::size_t expectedCount =
    std::min<std::size_t>(all.size(), static_cast<std::size_t>(std::max(k, 0)));
  ASSERT_EQ(static_cast<std::size_t>(found), expectedCount);
  ASSERT_EQ(ids.size(), expectedCount);
  for (std::size_t i = 0; i < expectedCount; ++i)
  {
    ASSERT_EQ(d2[i], all[i].first) << "k " << k << ", rank " << i;
    ASSERT_EQ(ids[i], all[i].second) << "k " << k << ", rank " << i;
  }
}

// Radii scaled to the cloud (about 1, 10 and 60 neighbours in a uniform cloud) plus 0 and a huge one.
void ExpectAllMatch(const NeighborGrid& grid, const Cloud& c, const Cloud& queries, double spacing)
{
  const double radii[] = { 0.0, 0.6 * spacing, 1.3 * spacing, 2.4 * spacing, 1e300 };
  for (Index q = 0; q < Count(queries); ++q)
  {
    const double* x = &queries[3 * q];
    const Reference all = SortedDistances(c, x);
    for (const double r : radii)
    {
      if (r == 1e300 && q % 8 != 0) // returns the whole cloud: a sample of queries is enough
      {
        continue;
      }
      ExpectRadiusMatches(grid, all, x, r);
      if (::testing::Test::HasFatalFailure())
      {
        return;
      }
    }
    for (const int k : { 1, 5, 20 })
    {
      ExpectKNearestMatches(grid, all, x, k);
      if (::testing::Test::HasFatalFailure())
      {
        return;
      }
    }
  }
}

double Spacing(const NeighborGrid& grid)
{
  double b[6];
  grid.GetBounds(b);
  double measure = 1.0;
  for (int a = 0; a < 3; ++a)
  {
    if (!grid.IsAxisFlat(a))
    {
      measure *= b[2 * a + 1] - b[2 * a];
    }
  }
  const int dim = std::max(grid.Dimension(), 1);
  return grid.Dimension() == 0 ? 1.0 : std::pow(measure / grid.NumberOfValidPoints(), 1.0 / dim);
}

void CheckCloud(const Cloud& c, double cellSize = 0.0)
{
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c), cellSize));
  ExpectAllMatch(grid, c, Queries(c, std::max<Index>(1, Count(c) / 150), 100, 7), Spacing(grid));
}

TEST(NeighborGrid, UniformRandom3D)
{
  const Cloud c = Uniform(4000, 1);
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  EXPECT_EQ(grid.NumberOfPoints(), 4000);
  EXPECT_EQ(grid.NumberOfValidPoints(), 4000);
  EXPECT_EQ(grid.NumberOfInvalidPoints(), 0);
  EXPECT_EQ(grid.Dimension(), 3);
  CheckCloud(c);
}

TEST(NeighborGrid, SortedOrderIsAPermutationInCellOrder)
{
  const Cloud c = Uniform(3000, 2);
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  std::vector<Index> order = grid.SortedOrder();
  for (std::size_t s = 0; s < order.size(); ++s)
  {
    for (int a = 0; a < 3; ++a)
    {
      ASSERT_EQ(grid.SortedPoints()[3 * s + a], c[3 * order[s] + a]);
    }
  }
  std::sort(order.begin(), order.end());
  std::vector<Index> expected(3000);
  std::iota(expected.begin(), expected.end(), Index(0));
  EXPECT_EQ(order, expected);
  // Every sorted position belongs to exactly one cell, and cells hold disjoint ranges.
  Index dims[3];
  grid.GetGridDimensions(dims);
  Index covered = 0;
  for (Index cell = 0; cell < dims[0] * dims[1] * dims[2]; ++cell)
  {
    covered += grid.Cells()[cell].End - grid.Cells()[cell].Begin;
  }
  EXPECT_EQ(covered, 3000);
  EXPECT_LE(dims[0] * dims[1] * dims[2], 4 * 3000 + 64);
}

TEST(NeighborGrid, ClusteredBlobsOfDifferentDensities)
{
  std::mt19937_64 rng(3);
  Cloud c;
  const double centres[3][3] = { { 0.2, 0.2, 0.2 }, { 0.7, 0.6, 0.5 }, { 0.4, 0.9, 0.1 } };
  const double sigmas[3] = { 1e-3, 3e-2, 0.3 };
  const int counts[3] = { 1500, 1000, 500 };
  for (int b = 0; b < 3; ++b)
  {
    std::normal_distribution<double> g(0.0, sigmas[b]);
    for (int i = 0; i < counts[b]; ++i)
    {
      for (int a = 0; a < 3; ++a)
      {
        c.push_back(centres[b][a] + g(rng));
      }
    }
  }
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  // Radii for each density: inside the tight blob, the loose blob and the background.
  const Cloud queries = Queries(c, 25, 60, 4);
  for (const double spacing : { 2e-4, 5e-3, 0.05 })
  {
    ExpectAllMatch(grid, c, queries, spacing);
  }
}

TEST(NeighborGrid, AllPointsKNearestOnClusters)
{
  // Consecutive queries reuse the previous k-th distance as a first guess: wrong near cluster edges.
  std::mt19937_64 rng(35);
  Cloud c;
  for (int b = 0; b < 4; ++b)
  {
    std::normal_distribution<double> g(0.0, b == 0 ? 1e-4 : 0.02 * b);
    for (int i = 0; i < 1500; ++i)
    {
      for (int a = 0; a < 3; ++a)
      {
        c.push_back(0.25 * b + g(rng));
      }
    }
  }
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  for (const int k : { 1, 5, 20 })
  {
    std::vector<Index> ids, one;
    std::vector<double> d2, oneD2;
    grid.FindKNearestForAllPoints(k, ids, d2);
    for (Index i = 0; i < Count(c); ++i)
    {
      ASSERT_EQ(grid.FindKNearest(&c[3 * i], k, one, oneD2), k);
      ASSERT_TRUE(std::equal(one.begin(), one.end(), ids.begin() + i * k)) << i;
      ASSERT_TRUE(std::equal(oneD2.begin(), oneD2.end(), d2.begin() + i * k)) << i;
      if (i % 97 == 0)
      {
        ExpectKNearestMatches(grid, SortedDistances(c, &c[3 * i]), &c[3 * i], k);
      }
    }
  }
}

TEST(NeighborGrid, Flat2DUsesOneCellLayer)
{
  Cloud c = Uniform(3000, 5);
  for (Index i = 0; i < Count(c); ++i)
  {
    c[3 * i + 2] = 0.75;
  }
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  EXPECT_EQ(grid.Dimension(), 2);
  EXPECT_TRUE(grid.IsAxisFlat(2));
  EXPECT_FALSE(grid.IsAxisFlat(0));
  Index dims[3];
  grid.GetGridDimensions(dims);
  EXPECT_EQ(dims[2], 1);
  EXPECT_GT(dims[0], 10); // cells sized for 2D density, not 3D
  CheckCloud(c);
  // Probes off the plane.
  Cloud probes = Queries(c, 100, 30, 6);
  for (Index i = 0; i < Count(probes); ++i)
  {
    probes[3 * i + 2] += (i % 3 - 1) * 0.05;
  }
  ExpectAllMatch(grid, c, probes, Spacing(grid));
}

TEST(NeighborGrid, FlatInXAndY)
{
  for (const int flat : { 0, 1 })
  {
    Cloud c = Uniform(2000, 8 + flat);
    for (Index i = 0; i < Count(c); ++i)
    {
      c[3 * i + flat] = -3.0;
    }
    NeighborGrid grid;
    ASSERT_TRUE(grid.Build(c.data(), Count(c)));
    EXPECT_EQ(grid.Dimension(), 2);
    EXPECT_TRUE(grid.IsAxisFlat(flat));
    CheckCloud(c);
  }
}

TEST(NeighborGrid, Collinear)
{
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Cloud alongY, diagonal;
  for (int i = 0; i < 2000; ++i)
  {
    const double t = u(rng);
    alongY.insert(alongY.end(), { 1.0, 5.0 * t, -2.0 });
    diagonal.insert(diagonal.end(), { t, 2.0 * t + 1.0, -t });
  }
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(alongY.data(), Count(alongY)));
  EXPECT_EQ(grid.Dimension(), 1);
  CheckCloud(alongY);
  CheckCloud(diagonal);
}

TEST(NeighborGrid, AllPointsIdentical)
{
  const Cloud c = [] {
    Cloud c;
    for (int i = 0; i < 500; ++i)
    {
      c.insert(c.end(), { 1.0, -2.0, 3.5 });
    }
    return c;
  }();
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  EXPECT_EQ(grid.Dimension(), 0);
  Index dims[3];
  grid.GetGridDimensions(dims);
  EXPECT_EQ(dims[0] * dims[1] * dims[2], 1);
  std::vector<Index> ids;
  std::vector<double> d2;
  EXPECT_EQ(grid.FindKNearest(c.data(), 5, ids, d2), 5);
  EXPECT_EQ(ids, (std::vector<Index>{ 0, 1, 2, 3, 4 })); // ties broken by index
  grid.FindWithinRadius(c.data(), 0.0, ids);
  EXPECT_EQ(ids.size(), 500u);
  const double away[3] = { 1.0, -2.0, 4.5 };
  grid.FindWithinRadius(away, 0.999, ids);
  EXPECT_TRUE(ids.empty());
  ExpectAllMatch(grid, c, Cloud{ 1.0, -2.0, 3.5, 1.0, -2.0, 4.5, 0.0, 0.0, 0.0 }, 1.0);
}

TEST(NeighborGrid, Duplicates)
{
  const Cloud base = Uniform(800, 11);
  Cloud c;
  for (int copy = 0; copy < 3; ++copy)
  {
    c.insert(c.end(), base.begin(), base.end());
  }
  CheckCloud(c);
}

TEST(NeighborGrid, LatticeOnCellBoundaries)
{
  // Integer lattice: points lie exactly on cell faces and at distances exactly equal to the radii.
  Cloud c;
  for (int i = 0; i < 12; ++i)
  {
    for (int j = 0; j < 12; ++j)
    {
      for (int k = 0; k < 12; ++k)
      {
        c.insert(c.end(), { double(i), double(j), double(k) });
      }
    }
  }
  for (const double cellSize : { 0.0, 1.0, 0.5, 2.0, 3.0 })
  {
    NeighborGrid grid;
    ASSERT_TRUE(grid.Build(c.data(), Count(c), cellSize));
    const Cloud queries = Queries(c, 37, 20, 12);
    for (Index q = 0; q < Count(queries); ++q)
    {
      const Reference all = SortedDistances(c, &queries[3 * q]);
      for (const double r : { 1.0, std::sqrt(2.0), std::sqrt(3.0), 2.0, 3.0 })
      {
        ExpectRadiusMatches(grid, all, &queries[3 * q], r);
      }
      for (const int k : { 1, 5, 20, 27 })
      {
        ExpectKNearestMatches(grid, all, &queries[3 * q], k);
      }
    }
  }
}

TEST(NeighborGrid, FarFromTheOrigin)
{
  Cloud c = Uniform(3000, 13, 1e6, 1e6 + 1.0);
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  EXPECT_EQ(grid.Dimension(), 3);
  Index dims[3];
  grid.GetGridDimensions(dims);
  EXPECT_GT(dims[0] * dims[1] * dims[2], 100); // cells sized by the extent, not the offset
  CheckCloud(c);
  CheckCloud(Uniform(3000, 14, -1e6 - 1.0, -1e6));
}

TEST(NeighborGrid, TinyScale)
{
  CheckCloud(Uniform(3000, 15, 0.0, 1e-6));
  CheckCloud(Uniform(3000, 16, 1.0, 1.0 + 1e-6)); // tiny and offset
}

TEST(NeighborGrid, HugeRadiusFindsEverything)
{
  const Cloud c = Uniform(2000, 17);
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  std::vector<Index> ids;
  for (const double r : { 10.0, 1e150, 1e300, std::numeric_limits<double>::max(), Inf })
  {
    const double x[3] = { 0.5, 0.5, 0.5 };
    grid.FindWithinRadius(x, r, ids);
    EXPECT_EQ(ids.size(), 2000u) << r;
    const double far[3] = { -1e200, 3e250, 0.0 };
    ExpectRadiusMatches(grid, SortedDistances(c, far), far, r);
  }
}

TEST(NeighborGrid, ProbesOutsideTheBounds)
{
  const Cloud c = Uniform(3000, 18);
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  const Cloud probes{ -0.5, 0.5, 0.5, 1.5, 1.5, 1.5, 0.5, -3.0, 0.5, 100.0, -200.0, 300.0, -1e12, 0.0, 1e12,
    1e200, 1e200, -1e200 };
  ExpectAllMatch(grid, c, probes, Spacing(grid));
}

TEST(NeighborGrid, NonFinitePointsAreExcludedAndReported)
{
  Cloud c = Uniform(3000, 19);
  const std::vector<Index> bad{ 0, 17, 18, 1000, 2999 };
  c[3 * 0 + 0] = NaN;
  c[3 * 17 + 1] = Inf;
  c[3 * 18 + 2] = -Inf;
  c[3 * 1000 + 0] = NaN;
  c[3 * 1000 + 1] = NaN;
  c[3 * 1000 + 2] = NaN;
  c[3 * 2999 + 2] = NaN;
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  EXPECT_EQ(grid.NumberOfPoints(), 3000);
  EXPECT_EQ(grid.NumberOfInvalidPoints(), 5);
  EXPECT_EQ(grid.NumberOfValidPoints(), 2995);
  EXPECT_EQ(grid.InvalidPointIds(), bad);
  double b[6];
  grid.GetBounds(b);
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_GE(b[2 * a], 0.0);
    EXPECT_LE(b[2 * a + 1], 1.0);
  }
  ExpectAllMatch(grid, c, Queries(c, 50, 30, 20), Spacing(grid));
  // Only invalid points: nothing to search, no crash.
  const Cloud allBad{ NaN, 0.0, 0.0, Inf, Inf, Inf };
  EXPECT_FALSE(grid.Build(allBad.data(), 2));
  EXPECT_EQ(grid.NumberOfInvalidPoints(), 2);
  std::vector<Index> ids;
  std::vector<double> d2;
  const double x[3] = { 0.0, 0.0, 0.0 };
  EXPECT_EQ(grid.FindKNearest(x, 3, ids, d2), 0);
  grid.FindWithinRadius(x, Inf, ids);
  EXPECT_TRUE(ids.empty());
}

TEST(NeighborGrid, EmptyCloud)
{
  NeighborGrid grid;
  EXPECT_FALSE(grid.Build(nullptr, 0));
  EXPECT_EQ(grid.NumberOfPoints(), 0);
  EXPECT_EQ(grid.NumberOfValidPoints(), 0);
  std::vector<Index> ids{ 1, 2 };
  std::vector<double> d2{ 1.0 };
  const double x[3] = { 0.0, 0.0, 0.0 };
  grid.FindWithinRadius(x, 1e300, ids, &d2);
  EXPECT_TRUE(ids.empty());
  EXPECT_TRUE(d2.empty());
  EXPECT_EQ(grid.FindKNearest(x, 4, ids, d2), 0);
  EXPECT_TRUE(ids.empty());
  EXPECT_EQ(grid.CountWithinRadius(x, 1.0), 0);
  grid.FindKNearestForAllPoints(3, ids, d2);
  EXPECT_TRUE(ids.empty());
}

TEST(NeighborGrid, KLargerThanTheCloudKZeroAndNaNQueries)
{
  const Cloud c = Uniform(30, 21);
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  const double x[3] = { 0.3, 0.3, 0.3 };
  ExpectKNearestMatches(grid, SortedDistances(c, x), x, 100);
  std::vector<Index> ids;
  std::vector<double> d2;
  EXPECT_EQ(grid.FindKNearest(x, 1000000, ids, d2), 30);
  EXPECT_EQ(grid.FindKNearest(x, 0, ids, d2), 0);
  EXPECT_TRUE(ids.empty());
  EXPECT_EQ(grid.FindKNearest(x, -3, ids, d2), 0);
  for (const double bad : { NaN, Inf, -Inf })
  {
    const double q[3] = { 0.5, bad, 0.5 };
    EXPECT_EQ(grid.FindKNearest(q, 5, ids, d2), 0);
    grid.FindWithinRadius(q, 1e300, ids, &d2);
    EXPECT_TRUE(ids.empty());
  }
  grid.FindWithinRadius(x, NaN, ids);
  EXPECT_TRUE(ids.empty());
  grid.FindWithinRadius(x, -1.0, ids);
  EXPECT_TRUE(ids.empty());
}

TEST(NeighborGrid, ExplicitCellSizes)
{
  const Cloud c = Uniform(2000, 22);
  for (const double cellSize : { 1e-12, 0.01, 0.3, 5.0, 1e300 })
  {
    NeighborGrid grid;
    ASSERT_TRUE(grid.Build(c.data(), Count(c), cellSize));
    Index dims[3];
    grid.GetGridDimensions(dims);
    EXPECT_LE(dims[0] * dims[1] * dims[2], 4 * 2000 + 64) << cellSize; // tiny sizes are enlarged
    EXPECT_GE(grid.CellSize(), std::min(cellSize, 1.0));
    ExpectAllMatch(grid, c, Queries(c, 100, 20, 23), 0.08);
  }
}

TEST(NeighborGrid, SortedRadiusAndAllPointsKNearest)
{
  Cloud c = Uniform(2500, 24);
  c[3 * 7] = NaN;
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  std::vector<Index> ids;
  std::vector<double> d2;
  const double x[3] = { 0.4, 0.6, 0.5 };
  grid.FindWithinRadiusSorted(x, 0.2, ids, d2);
  const auto all = SortedDistances(c, x);
  ASSERT_LE(ids.size(), all.size());
  ASSERT_GT(ids.size(), 50u);
  for (std::size_t i = 0; i < ids.size(); ++i)
  {
    EXPECT_EQ(ids[i], all[i].second);
    EXPECT_EQ(d2[i], all[i].first);
  }
  EXPECT_GT(all[ids.size()].first, 0.2 * 0.2);

  const int k = 8;
  grid.FindKNearestForAllPoints(k, ids, d2);
  ASSERT_EQ(ids.size(), static_cast<std::size_t>(k * 2500));
  std::vector<Index> one;
  std::vector<double> oneD2;
  for (Index i = 0; i < 2500; ++i)
  {
    if (i == 7)
    {
      EXPECT_EQ(ids[7 * k], -1);
      EXPECT_EQ(d2[7 * k], Inf);
      continue;
    }
    grid.FindKNearest(&c[3 * i], k, one, oneD2);
    ASSERT_TRUE(std::equal(one.begin(), one.end(), ids.begin() + i * k)) << i;
    ASSERT_TRUE(std::equal(oneD2.begin(), oneD2.end(), d2.begin() + i * k)) << i;
    EXPECT_EQ(ids[i * k], i); // a point is its own nearest neighbour (no duplicates here)
  }
  // Fewer valid points than k: rows are padded with -1 / +inf.
  const Cloud few = Uniform(3, 25);
  ASSERT_TRUE(grid.Build(few.data(), 3));
  grid.FindKNearestForAllPoints(5, ids, d2);
  ASSERT_EQ(ids.size(), 15u);
  EXPECT_EQ(ids[3], -1);
  EXPECT_EQ(d2[4], Inf);
}

TEST(NeighborGrid, RebuildReusesTheObject)
{
  NeighborGrid grid;
  const Cloud big = Uniform(5000, 26);
  const Cloud small = Uniform(200, 27, -5.0, -4.0);
  ASSERT_TRUE(grid.Build(big.data(), Count(big)));
  ASSERT_TRUE(grid.Build(small.data(), Count(small)));
  EXPECT_EQ(grid.NumberOfValidPoints(), 200);
  CheckCloud(small);
  ExpectAllMatch(grid, small, Queries(small, 10, 10, 28), Spacing(grid));
}

TEST(NeighborGrid, LargeK)
{
  // Crosses the internal limits: sorted insertion (k <= 48), heap (k > 48), candidate buffer (256).
  const Cloud c = Uniform(3000, 31);
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  const Cloud queries = Queries(c, 600, 5, 32);
  for (Index q = 0; q < Count(queries); ++q)
  {
    const Reference all = SortedDistances(c, &queries[3 * q]);
    for (const int k : { 47, 48, 49, 100, 255, 256, 257, 600, 2999, 3000 })
    {
      ExpectKNearestMatches(grid, all, &queries[3 * q], k);
    }
  }
}

TEST(NeighborGrid, PortableKernelGivesTheSameResults)
{
  // The distance filter has vector variants (AVX-512, AVX2); the portable one must give bit-identical results.
  struct Restore
  {
    ~Restore() { NeighborGrid::SetVectorized(true); }
  } restore;
  NeighborGrid::SetVectorized(false);
  CheckCloud(Uniform(3000, 33));
  Cloud flat = Uniform(2000, 34);
  for (Index i = 0; i < Count(flat); ++i)
  {
    flat[3 * i + 1] = 0.25;
  }
  CheckCloud(flat);
}

TEST(NeighborGrid, LargeCloudBuildsInParallelLikeSerial)
{
  // Above the parallel threshold; a sample of queries against brute force.
  const Cloud c = Uniform(40000, 29, -1.0, 2.0);
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  ExpectAllMatch(grid, c, Queries(c, 4000, 10, 30), Spacing(grid));
}

// FindWithinRadiusForAllPoints(): every row against brute force as an exact index set, and against
// FindWithinRadius() at that point in order (the rows keep the per-point query's order).
void ExpectAllRowsMatch(const NeighborGrid& grid, const Cloud& c, double radius, bool excludeSelf)
{
  std::vector<Index> offsets;
  std::vector<std::int32_t> rows;
  ASSERT_TRUE(grid.FindWithinRadiusForAllPoints(radius, offsets, rows, excludeSelf));
  ASSERT_EQ(offsets.size(), static_cast<std::size_t>(Count(c)) + 1);
  ASSERT_EQ(offsets.front(), 0);
  ASSERT_EQ(static_cast<std::size_t>(offsets.back()), rows.size());
  const double r2 = radius * radius;
  std::vector<Index> ids;
  for (Index i = 0; i < Count(c); ++i)
  {
    ASSERT_LE(offsets[i], offsets[i + 1]);
    const std::vector<Index> row(rows.begin() + offsets[i], rows.begin() + offsets[i + 1]);
    if (!Valid(&c[3 * i]))
    {
      EXPECT_TRUE(row.empty()) << "invalid point " << i;
      continue;
    }
    std::vector<Index> expected;
    for (Index j = 0; j < Count(c); ++j)
    {
      if (Valid(&c[3 * j]) && Distance2(&c[3 * j], &c[3 * i]) <= r2 && !(excludeSelf && j == i))
      {
        expected.push_back(j);
      }
    }
    std::vector<Index> sorted = row;
    std::sort(sorted.begin(), sorted.end());
    ASSERT_EQ(sorted, expected) << "point " << i << ", radius " << radius;
    grid.FindWithinRadius(&c[3 * i], radius, ids);
    if (excludeSelf)
    {
      ids.erase(std::remove(ids.begin(), ids.end(), i), ids.end());
    }
    ASSERT_EQ(row, ids) << "order differs from FindWithinRadius at point " << i;
  }
}

TEST(NeighborGrid, AllPointsRadiusListsMatchBruteForce)
{
  // Uniform, clustered (one tight blob, one loose), flat, on cell boundaries, with duplicates and invalid
  // points; radii from 0 to beyond the cell size; automatic and explicit cell sizes.
  std::vector<Cloud> clouds;
  clouds.push_back(Uniform(1500, 41));
  {
    std::mt19937_64 rng(42);
    Cloud c;
    for (const double sigma : { 2e-3, 0.1 })
    {
      std::normal_distribution<double> g(0.5, sigma);
      for (int i = 0; i < 600; ++i)
      {
        c.insert(c.end(), { g(rng), g(rng), g(rng) });
      }
    }
    clouds.push_back(c);
  }
  {
    Cloud flat = Uniform(1200, 43);
    for (Index i = 0; i < Count(flat); ++i)
    {
      flat[3 * i + 1] = 0.0; // the SPH 2D case: the x-z plane
    }
    clouds.push_back(flat);
  }
  {
    Cloud lattice; // exact distances equal to the radii, points on cell faces
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 9; ++j)
        for (int k = 0; k < 9; ++k)
          lattice.insert(lattice.end(), { 0.5 * i, 0.5 * j, 0.5 * k });
    clouds.push_back(lattice);
  }
  {
    Cloud odd = Uniform(800, 44);
    odd.insert(odd.end(), { odd[0], odd[1], odd[2], odd[0], odd[1], odd[2] }); // duplicates of point 0
    odd.insert(odd.end(), { NaN, 0.5, 0.5, 0.5, Inf, 0.5 });                    // two invalid points
    clouds.push_back(odd);
  }
  for (const Cloud& c : clouds)
  {
    for (const double cellSize : { 0.0, 0.05, 0.5 })
    {
      NeighborGrid grid;
      ASSERT_TRUE(grid.Build(c.data(), Count(c), cellSize));
      for (const double radius : { 0.0, 0.01, 0.05, 0.5, 1.0 })
      {
        for (const bool excludeSelf : { false, true })
        {
          ExpectAllRowsMatch(grid, c, radius, excludeSelf);
        }
      }
    }
  }
}

TEST(NeighborGrid, AllPointsRadiusListsInParallelAndDegenerateInput)
{
  // Above the parallel threshold: the same rows whatever the number of threads.
  const Cloud c = Uniform(20000, 45);
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c), 0.04));
  std::vector<Index> offsets, serialOffsets;
  std::vector<std::int32_t> rows, serialRows;
  ASSERT_TRUE(grid.FindWithinRadiusForAllPoints(0.04, offsets, rows, true));
  meshfree::SetMaxThreads(1);
  ASSERT_TRUE(grid.FindWithinRadiusForAllPoints(0.04, serialOffsets, serialRows, true));
  meshfree::SetMaxThreads(0);
  EXPECT_EQ(offsets, serialOffsets);
  EXPECT_EQ(rows, serialRows);
  // A sample of rows against brute force.
  for (Index i = 0; i < Count(c); i += 997)
  {
    std::vector<Index> expected;
    for (Index j = 0; j < Count(c); ++j)
    {
      if (j != i && Distance2(&c[3 * j], &c[3 * i]) <= 0.04 * 0.04)
      {
        expected.push_back(j);
      }
    }
    std::vector<Index> row(rows.begin() + offsets[i], rows.begin() + offsets[i + 1]);
    std::sort(row.begin(), row.end());
    EXPECT_EQ(row, expected) << "point " << i;
  }
  // NaN or negative radius, empty grid: empty rows of the right count.
  EXPECT_TRUE(grid.FindWithinRadiusForAllPoints(NaN, offsets, rows));
  EXPECT_EQ(offsets.size(), static_cast<std::size_t>(Count(c)) + 1);
  EXPECT_TRUE(rows.empty());
  EXPECT_TRUE(grid.FindWithinRadiusForAllPoints(-1.0, offsets, rows));
  EXPECT_TRUE(rows.empty());
  NeighborGrid empty;
  empty.Build(nullptr, 0);
  EXPECT_TRUE(empty.FindWithinRadiusForAllPoints(1.0, offsets, rows));
  EXPECT_EQ(offsets.size(), 1u);
  EXPECT_TRUE(rows.empty());
}
} // namespace

TEST(NeighborGrid, FindDuplicatesGroupsEqualCoordinatesOnly)
{
  // Points 0, 3 and 5 coincide; 1 and 4 coincide; 2 differs from 1 in the last bit; 6 is NaN.
  const double x = 0.1 + 0.2;
  const double next = std::nextafter(x, 1.0);
  const std::vector<double> p = { 1, 2, 3, x, 0, 0, next, 0, 0, 1, 2, 3, x, 0, 0, 1, 2, 3,
    std::numeric_limits<double>::quiet_NaN(), 0, 0 };
  NeighborGrid grid;
  grid.Build(p.data(), 7);
  std::vector<Index> rep;
  EXPECT_EQ(grid.FindDuplicates(rep), 3);
  const std::vector<Index> expected = { 0, 1, 2, 0, 1, 0, -1 };
  EXPECT_EQ(rep, expected);
  // A million copies of one point fall into one cell: still linear-logarithmic, one group.
  std::vector<double> same(3000000, 0.5);
  grid.Build(same.data(), 1000000);
  EXPECT_EQ(grid.FindDuplicates(rep), 999999);
  EXPECT_EQ(*std::max_element(rep.begin(), rep.end()), 0);
  // No valid point at all.
  grid.Build(p.data() + 18, 1);
  EXPECT_EQ(grid.FindDuplicates(rep), 0);
  EXPECT_EQ(rep, std::vector<Index>{ -1 });
}

TEST(NeighborGrid, RadiusQueryIntoBuffersListsAsTheVectorQuery)
{
  // FindWithinRadiusPositions into detail::Buffer (the filter writes straight into the output, growing it batch by
  // batch) lists the same positions and squared distances in the same order as the std::vector query; radii from
  // none to thousands of points (many batches of the filter, and growth of reused buffers), empty buffers reused.
  const Cloud c = Uniform(20000, 41);
  NeighborGrid grid;
  ASSERT_TRUE(grid.Build(c.data(), Count(c)));
  const Cloud queries = Queries(c, 500, 20, 42);
  std::vector<Index> pos;
  std::vector<double> d2;
  meshfree::detail::Buffer<Index> bufferPos;
  meshfree::detail::Buffer<double> bufferD2;
  size_t largest = 0;
  for (const double radius : { 0.0, 0.01, 0.05, 0.2, 0.45, 0.03 })
  {
    for (size_t q = 0; q + 3 <= queries.size(); q += 3)
    {
      grid.FindWithinRadiusPositions(&queries[q], radius, pos, d2);
      grid.FindWithinRadiusPositions(&queries[q], radius, bufferPos, bufferD2);
      ASSERT_EQ(bufferPos.size(), pos.size());
      ASSERT_EQ(bufferD2.size(), d2.size());
      EXPECT_TRUE(std::equal(pos.begin(), pos.end(), bufferPos.begin()));
      EXPECT_TRUE(std::equal(d2.begin(), d2.end(), bufferD2.begin()));
      largest = std::max(largest, pos.size());
    }
  }
  EXPECT_GT(largest, 5000u); // many filter batches in one query
}
