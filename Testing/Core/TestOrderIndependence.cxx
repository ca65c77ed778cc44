// SPDX-License-Identifier: BSD-3-Clause
// Order independence (issue 24): permuting the input points changes nothing but the numbering. For 3 random
// permutations of a lattice (every query has many equidistant neighbours) and of a random cloud, NeighborGrid's
// layout and every query (k nearest inside, between and far outside the points, small and large k; radius lists,
// sorted radius lists, the all-points k-nearest and radius rows) give the same points (mapped back through the
// permutation) in the same order, and the approximation (LS, WLS, MLS, PU-WLS, SPH with volumes from the number
// density and from given volumes; k nearest and fixed radius; values, gradients, masks, neighbour counts) gives the
// same bits. Ties are broken by position: at a lattice cell's centre the nearest of its 8 equidistant corners is
// the one with the smallest (x, y, z), whatever the order. Meshless Normals' core (CloudNormals.h: the jets, their
// radius, the sharp-feature pass, the orientation graph and its spanning tree, curvature) gives the same bits too.
#include "Approximation/Approximation.h"
#include "Common/NeighborGrid.h"
#include "Surface/CloudNormals.h"
#include "Surface/SurfaceReconstruction.h"
#include "SurfaceSamples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace
{
using namespace meshfree;
using Cloud = std::vector<double>;

Index Count(const Cloud& c)
{
  return static_cast<Index>(c.size() / 3);
}

/// A lattice of nx x ny x nz points with spacing h (every interior point has 6 neighbours at h, 12 at h sqrt 2...).
Cloud Lattice(int nx, int ny, int nz, double h)
{
  Cloud c;
  for (int k = 0; k < nz; ++k)
  {
    for (int j = 0; j < ny; ++j)
    {
      for (int i = 0; i < nx; ++i)
      {
        c.insert(c.end(), { h * i, h * j, h * k });
      }
    }
  }
  return c;
}

Cloud Random(Index n, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Cloud c(3 * n);
  for (double& v : c)
  {
    v = u(rng);
  }
  return c;
}

/// perm[i]: the original index of the permuted cloud's point i.
std::vector<Index> Permutation(Index n, unsigned seed)
{
  std::vector<Index> p(n);
  std::iota(p.begin(), p.end(), Index(0));
  std::shuffle(p.begin(), p.end(), std::mt19937_64(seed));
  return p;
}

/// Rows of `width` values each, reordered: out row i = in row perm[i].
std::vector<double> Permute(const std::vector<double>& in, const std::vector<Index>& perm, int width)
{
  std::vector<double> out(in.size());
  for (std::size_t i = 0; i < perm.size(); ++i)
  {
    std::copy(in.begin() + perm[i] * width, in.begin() + (perm[i] + 1) * width, out.begin() + i * width);
  }
  return out;
}

/// Query positions: on lattice points, on midpoints of edges and at cell centres (ties), random, far away.
Cloud Queries(double h, int cells)
{
  Cloud q;
  for (int a = 0; a < 4; ++a)
  {
    for (int b = 0; b < 4; ++b)
    {
      const double base[3] = { h * (1 + a), h * (1 + b), h * (1 + (a + b) % cells) };
      q.insert(q.end(), { base[0], base[1], base[2] });
      q.insert(q.end(), { base[0] + 0.5 * h, base[1], base[2] });
      q.insert(q.end(), { base[0] + 0.5 * h, base[1] + 0.5 * h, base[2] + 0.5 * h });
    }
  }
  const Cloud random = Random(40, 99);
  for (std::size_t i = 0; i < random.size(); ++i)
  {
    q.push_back(random[i] * h * cells);
  }
  q.insert(q.end(), { -5.0 * h * cells, 0.5 * h * cells, 0.3 * h * cells }); // far: the exact shell search
  q.insert(q.end(), { 3.0 * h * cells, 4.0 * h * cells, -2.0 * h * cells });
  return q;
}

template <class T>
bool SameBits(const std::vector<T>& a, const std::vector<T>& b)
{
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

/// Every query of the grid of `c` and of its permutation agrees (ids mapped back through perm).
void CheckGrid(const Cloud& c, const std::vector<Index>& perm, double spacing, const std::string& what)
{
  const Cloud p = Permute(c, perm, 3);
  NeighborGrid one, other;
  ASSERT_TRUE(one.Build(c.data(), Count(c)));
  ASSERT_TRUE(other.Build(p.data(), Count(p)));
  // The layout: the same coordinates in the same order, the same cells, the same points.
  const Index n = one.NumberOfValidPoints();
  ASSERT_EQ(n, other.NumberOfValidPoints());
  ASSERT_EQ(std::memcmp(one.SortedPoints(), other.SortedPoints(), 3 * n * sizeof(double)), 0) << what;
  for (Index s = 0; s < n; ++s)
  {
    ASSERT_EQ(perm[other.SortedOrder()[s]], one.SortedOrder()[s]) << what << " sorted position " << s;
  }
  Index dims[3];
  one.GetGridDimensions(dims);
  for (Index cell = 0; cell < dims[0] * dims[1] * dims[2]; ++cell) // each cell's points by (x, y, z)
  {
    for (Index s = one.Cells()[cell].Begin + 1; s < one.Cells()[cell].End; ++s)
    {
      const double* xyz = one.SortedPoints();
      ASSERT_TRUE(GridPointBefore(xyz + 3 * (s - 1), one.SortedOrder()[s - 1], xyz + 3 * s, one.SortedOrder()[s]))
        << what << " cell " << cell;
    }
  }
  auto mapped = [&](std::vector<Index> ids) {
    for (Index& id : ids)
    {
      id = id >= 0 ? perm[id] : id;
    }
    return ids;
  };
  const Cloud queries = Queries(spacing, 6);
  std::vector<Index> a, b;
  std::vector<double> da, db;
  for (Index q = 0; q < Count(queries); ++q)
  {
    const double* x = &queries[3 * q];
    for (int k : { 1, 5, 7, 20, 27, 60, 300 })
    {
      one.FindKNearest(x, k, a, da);
      other.FindKNearest(x, k, b, db);
      ASSERT_EQ(a, mapped(b)) << what << " k " << k << " query " << q;
      ASSERT_TRUE(SameBits(da, db)) << what << " k " << k << " query " << q;
    }
    for (double r : { 0.0, 1.0 * spacing, 1.5 * spacing, 2.5 * spacing })
    {
      one.FindWithinRadius(x, r, a, &da);
      other.FindWithinRadius(x, r, b, &db);
      ASSERT_EQ(a, mapped(b)) << what << " radius " << r << " query " << q;
      ASSERT_TRUE(SameBits(da, db));
      one.FindWithinRadiusSorted(x, r, a, da);
      other.FindWithinRadiusSorted(x, r, b, db);
      ASSERT_EQ(a, mapped(b)) << what << " sorted radius " << r << " query " << q;
      ASSERT_TRUE(SameBits(da, db));
    }
  }
  // Rows of every point: row i of the permuted cloud is row perm[i] of the original.
  const int k = 12;
  one.FindKNearestForAllPoints(k, a, da);
  other.FindKNearestForAllPoints(k, b, db);
  for (Index i = 0; i < Count(c); ++i)
  {
    const std::vector<Index> rowA(a.begin() + perm[i] * k, a.begin() + (perm[i] + 1) * k);
    const std::vector<Index> rowB(b.begin() + i * k, b.begin() + (i + 1) * k);
    ASSERT_EQ(rowA, mapped(rowB)) << what << " k-nearest row " << i;
  }
  std::vector<Index> offsetsA, offsetsB;
  std::vector<std::int32_t> rowsA, rowsB;
  ASSERT_TRUE(one.FindWithinRadiusForAllPoints(1.5 * spacing, offsetsA, rowsA, true));
  ASSERT_TRUE(other.FindWithinRadiusForAllPoints(1.5 * spacing, offsetsB, rowsB, true));
  for (Index i = 0; i < Count(c); ++i)
  {
    const std::vector<Index> rowA(rowsA.begin() + offsetsA[perm[i]], rowsA.begin() + offsetsA[perm[i] + 1]);
    const std::vector<Index> rowB(rowsB.begin() + offsetsB[i], rowsB.begin() + offsetsB[i + 1]);
    ASSERT_EQ(rowA, mapped(rowB)) << what << " radius row " << i;
  }
}
} // namespace

TEST(OrderIndependence, GridQueriesOfAPermutedCloud)
{
  const Cloud lattice = Lattice(9, 8, 7, 0.125);
  const Cloud random = Random(2000, 5);
  for (unsigned seed : { 1u, 2u, 3u })
  {
    CheckGrid(lattice, Permutation(Count(lattice), seed), 0.125, "lattice, permutation " + std::to_string(seed));
    CheckGrid(random, Permutation(Count(random), seed), 0.08, "random, permutation " + std::to_string(seed));
  }
}

TEST(OrderIndependence, TiesGoToTheSmallestPosition)
{
  // At a cell's centre all 8 corners are equally far: the first is the corner with the smallest (x, y, z), then
  // the others in lexicographic order, whatever the numbering; the same for the 4 corners of a face.
  const Cloud lattice = Lattice(5, 5, 5, 1.0);
  for (unsigned seed : { 0u, 1u, 2u, 3u })
  {
    const Cloud p = seed == 0 ? lattice : Permute(lattice, Permutation(Count(lattice), seed), 3);
    NeighborGrid grid;
    ASSERT_TRUE(grid.Build(p.data(), Count(p)));
    std::vector<Index> ids;
    std::vector<double> d2;
    const double centre[3] = { 1.5, 2.5, 0.5 };
    ASSERT_EQ(grid.FindKNearest(centre, 8, ids, d2), 8);
    const double corners[8][3] = { { 1, 2, 0 }, { 1, 2, 1 }, { 1, 3, 0 }, { 1, 3, 1 }, { 2, 2, 0 }, { 2, 2, 1 },
      { 2, 3, 0 }, { 2, 3, 1 } };
    for (int j = 0; j < 8; ++j)
    {
      EXPECT_EQ(d2[j], 0.75);
      for (int a = 0; a < 3; ++a)
      {
        EXPECT_EQ(p[3 * ids[j] + a], corners[j][a]) << "seed " << seed << " rank " << j;
      }
    }
    const double face[3] = { 3.5, 3.0, 2.5 }; // between (3, 3, 2), (3, 3, 3), (4, 3, 2), (4, 3, 3)
    ASSERT_EQ(grid.FindKNearest(face, 1, ids, d2), 1);
    EXPECT_EQ(p[3 * ids[0]], 3.0);
    EXPECT_EQ(p[3 * ids[0] + 1], 3.0);
    EXPECT_EQ(p[3 * ids[0] + 2], 2.0);
    // The comparator itself: distance first, then x, y, z, then the index (exact duplicates).
    const double lo[3] = { 0, 5, 5 }, hi[3] = { 1, 0, 0 };
    EXPECT_TRUE(NeighborGrid::NeighborBefore(1.0, hi, 0, 2.0, lo, 1));
    EXPECT_TRUE(NeighborGrid::NeighborBefore(1.0, lo, 9, 1.0, hi, 1));
    EXPECT_FALSE(NeighborGrid::NeighborBefore(1.0, hi, 0, 1.0, lo, 9));
    EXPECT_TRUE(NeighborGrid::NeighborBefore(1.0, lo, 1, 1.0, lo, 2));
    EXPECT_FALSE(NeighborGrid::NeighborBefore(1.0, lo, 2, 1.0, lo, 2));
  }
}

TEST(OrderIndependence, DuplicatesKeepTheLayoutAndTheDistances)
{
  // Exact duplicates are the one place where the input order still decides (which of two equal positions comes
  // first): the coordinates in sorted order, every distance list and every set of positions stay the same.
  Cloud c = Lattice(6, 6, 6, 0.2);
  const Cloud copy(c.begin(), c.begin() + 3 * 50);
  c.insert(c.end(), copy.begin(), copy.end());
  for (unsigned seed : { 1u, 2u, 3u })
  {
    const std::vector<Index> perm = Permutation(Count(c), seed);
    const Cloud p = Permute(c, perm, 3);
    NeighborGrid one, other;
    ASSERT_TRUE(one.Build(c.data(), Count(c)));
    ASSERT_TRUE(other.Build(p.data(), Count(p)));
    ASSERT_EQ(std::memcmp(one.SortedPoints(), other.SortedPoints(), 3 * Count(c) * sizeof(double)), 0);
    const Cloud queries = Queries(0.2, 5);
    std::vector<Index> a, b;
    std::vector<double> da, db;
    for (Index q = 0; q < Count(queries); ++q)
    {
      for (int k : { 1, 8, 30 })
      {
        one.FindKNearest(&queries[3 * q], k, a, da);
        other.FindKNearest(&queries[3 * q], k, b, db);
        ASSERT_TRUE(SameBits(da, db));
        for (std::size_t j = 0; j < a.size(); ++j)
        {
          for (int x = 0; x < 3; ++x)
          {
            ASSERT_EQ(c[3 * a[j] + x], p[3 * b[j] + x]) << "query " << q << " k " << k << " rank " << j;
          }
        }
      }
    }
  }
}

namespace
{
struct Result
{
  std::vector<double> Values, Gradients, Counts;
  std::vector<unsigned char> Valid;
};

Result Approximate(const ApproximationOptions& options, const Cloud& xyz, const std::vector<double>& values,
  int components, const std::vector<double>* volumes, const Cloud& probes)
{
  Approximator approx;
  EXPECT_TRUE(approx.SetOptions(options)) << approx.Error();
  EXPECT_TRUE(approx.SetCloud(xyz.data(), Count(xyz), values.data(), components, volumes ? volumes->data() : nullptr))
    << approx.Error();
  const Index m = Count(probes);
  Result r;
  r.Values.assign(m * components, -1.0);
  r.Gradients.assign(3 * m * components, -1.0);
  r.Counts.assign(m, -1.0);
  r.Valid.assign(m, 2);
  ApproximationOutput out;
  out.Values = r.Values.data();
  out.Gradients = r.Gradients.data();
  out.NeighborCounts = r.Counts.data();
  out.Valid = r.Valid.data();
  EXPECT_TRUE(approx.Evaluate(probes.data(), m, out)) << approx.Error();
  return r;
}

/// f and a second component at every point of c.
std::vector<double> Values(const Cloud& c)
{
  std::vector<double> v;
  for (Index i = 0; i < Count(c); ++i)
  {
    const double* x = &c[3 * i];
    v.push_back(std::sin(3.0 * x[0]) + x[1] * x[1] + 0.5 * x[2]);
    v.push_back(x[0] * x[1] - std::cos(2.0 * x[2]));
  }
  return v;
}
} // namespace

TEST(OrderIndependence, ApproximationOfAPermutedCloudIsBitwiseEqual)
{
  const Cloud lattice = Lattice(9, 9, 9, 0.125); // a Wavelet's cell centres: ties everywhere
  const Cloud random = Random(900, 11);
  // Probes on lattice points, edge midpoints and cell centres (tied neighbourhoods), and at random.
  Cloud probes = Queries(0.125, 6);
  probes.resize(probes.size() - 6); // not the far ones: masked anyway
  const ApproximationMethod methods[] = { ApproximationMethod::LS, ApproximationMethod::WLS, ApproximationMethod::MLS,
    ApproximationMethod::PUWLS, ApproximationMethod::SPH };
  int compared = 0;
  for (const Cloud* cloud : { &lattice, &random })
  {
    const std::string cloudName = cloud == &lattice ? "lattice" : "random";
    const std::vector<double> values = Values(*cloud);
    std::vector<double> volumes(Count(*cloud));
    for (Index i = 0; i < Count(*cloud); ++i)
    {
      volumes[i] = 1e-3 * (1.0 + 0.1 * std::sin(static_cast<double>(i)));
    }
    for (ApproximationMethod method : methods)
    {
      for (double radius : { 0.0, 0.3 })
      {
        for (bool givenVolumes : { false, true })
        {
          if (givenVolumes && method != ApproximationMethod::SPH)
          {
            continue;
          }
          ApproximationOptions options;
          options.Method = method;
          options.NeighborCount = 20;
          options.SupportRadius = radius;
          options.ComputeGradients = true;
          options.Backend = ApproximationBackend::CPU;
          const std::string what = cloudName + " " + ApproximationMethodName(method) +
            (radius > 0.0 ? " radius" : " k nearest") + (givenVolumes ? " given volumes" : "");
          const Result want =
            Approximate(options, *cloud, values, 2, givenVolumes ? &volumes : nullptr, probes);
          EXPECT_GT(std::count(want.Valid.begin(), want.Valid.end(), 1), Count(probes) / 2) << what;
          for (unsigned seed : { 1u, 2u, 3u })
          {
            const std::vector<Index> perm = Permutation(Count(*cloud), seed);
            const std::vector<double> permutedVolumes = Permute(volumes, perm, 1);
            const Result got = Approximate(options, Permute(*cloud, perm, 3), Permute(values, perm, 2), 2,
              givenVolumes ? &permutedVolumes : nullptr, probes);
            EXPECT_TRUE(SameBits(got.Values, want.Values)) << what << ", permutation " << seed;
            EXPECT_TRUE(SameBits(got.Gradients, want.Gradients)) << what << ", permutation " << seed;
            EXPECT_TRUE(SameBits(got.Counts, want.Counts)) << what << ", permutation " << seed;
            EXPECT_EQ(got.Valid, want.Valid) << what << ", permutation " << seed;
            ++compared;
          }
        }
      }
    }
  }
  EXPECT_EQ(compared, 2 * (5 * 2 + 2) * 3);
}

namespace
{
/// The mesh's triangles as a set: each one's 9 vertex coordinates starting at its smallest vertex (the winding
/// kept), sorted.
std::vector<std::array<double, 9>> TriangleSet(const TriangleMesh& mesh)
{
  std::vector<std::array<double, 9>> set(mesh.NumberOfTriangles());
  for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    const double* v[3];
    for (int c = 0; c < 3; ++c)
    {
      v[c] = &mesh.Points[3 * mesh.Triangles[3 * t + c]];
    }
    int first = 0;
    for (int c = 1; c < 3; ++c)
    {
      if (std::lexicographical_compare(v[c], v[c] + 3, v[first], v[first] + 3))
      {
        first = c;
      }
    }
    for (int c = 0; c < 3; ++c)
    {
      std::copy(v[(first + c) % 3], v[(first + c) % 3] + 3, set[t].begin() + 3 * c);
    }
  }
  std::sort(set.begin(), set.end());
  return set;
}
} // namespace

TEST(OrderIndependence, SurfaceOfAPermutedCloudHasTheSameTriangles)
{
  // A noisy torus (normals estimated and oriented: the whole path) and a lattice-like sphere (ties) with exact
  // duplicates.
  const meshfree::testing::SurfaceCloud torus = meshfree::testing::SampleSurface(true, 3000, 0.002, 7);
  Cloud sphere;
  for (int i = 0; i < 24; ++i)
  {
    for (int j = 0; j < 48; ++j)
    {
      const double theta = M_PI * (i + 0.5) / 24.0;
      const double phi = 2.0 * M_PI * j / 48.0;
      sphere.insert(sphere.end(), { std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
        std::cos(theta) });
    }
  }
  for (Index i = 0; i < 200; i += 7) // exact duplicates: merged (MLS, WLS) or kept (SPH)
  {
    sphere.insert(sphere.end(), sphere.begin() + 3 * i, sphere.begin() + 3 * i + 3);
  }
  // The torus with a hole (x > 0.7 cut away), filled: the filled part follows the winding number's tree.
  Cloud holed;
  for (Index i = 0; i < torus.Count(); ++i)
  {
    if (torus.Points[3 * i] <= 0.7)
    {
      holed.insert(holed.end(), torus.Points.begin() + 3 * i, torus.Points.begin() + 3 * i + 3);
    }
  }
  int compared = 0;
  const Cloud* clouds[] = { &torus.Points, &sphere, &holed };
  for (const Cloud* cloud : clouds)
  {
    const std::string cloudName = cloud == &sphere ? "sphere" : cloud == &holed ? "holed torus, filled" : "torus";
    for (SurfaceMethod method : { SurfaceMethod::MLS, SurfaceMethod::WLS, SurfaceMethod::SPH })
    {
      if (cloud == &holed && method == SurfaceMethod::SPH)
      {
        continue;
      }
      SurfaceOptions options;
      options.Method = method;
      options.HoleFilling = cloud == &holed ? HoleFillingMode::On : HoleFillingMode::Auto;
      const std::string what = cloudName + " " + SurfaceMethodName(method);
      auto run = [&](const Cloud& c) {
        SurfaceInput input;
        input.Points = c.data();
        input.Count = Count(c);
        SurfaceMesh mesh;
        SurfaceReport report;
        std::string error;
        EXPECT_TRUE(ReconstructSurface(input, options, mesh, report, error)) << what << ": " << error;
        return TriangleSet(mesh);
      };
      const auto want = run(*cloud);
      EXPECT_GT(want.size(), 500u) << what;
      for (unsigned seed : { 1u, 2u, 3u })
      {
        const auto got = run(Permute(*cloud, Permutation(Count(*cloud), seed), 3));
        EXPECT_EQ(got.size(), want.size()) << what << ", permutation " << seed;
        EXPECT_TRUE(got == want) << what << ", permutation " << seed; // bitwise: == on doubles, no NaN here
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, (2 * 3 + 2) * 3);
}

TEST(OrderIndependence, NormalsOfAPermutedCloudAreBitwiseEqual)
{
  // A torus sampled on a (u, v) lattice (every point has pairs of equidistant neighbours: the k-th nearest and
  // the orientation graph's rows are decided by ties), a noisy random torus (the noise-adapted jets), a noisy
  // cube (the sharp-feature pass) and a sphere whose noise is large against its spacing (the normals' radius holds
  // about 1000 points: the jets over the thinned cloud, chosen by a hash of the positions).
  std::vector<Cloud> clouds(4);
  for (int i = 0; i < 120; ++i)
  {
    for (int j = 0; j < 40; ++j)
    {
      const double u = 2.0 * M_PI * i / 120.0, v = 2.0 * M_PI * j / 40.0, ring = 1.0 + 0.35 * std::cos(v);
      clouds[0].insert(clouds[0].end(), { ring * std::cos(u), ring * std::sin(u), 0.35 * std::sin(v) });
    }
  }
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int i = 0; i < 6000; ++i)
  {
    const double u = 2.0 * M_PI * u01(rng), v = 2.0 * M_PI * u01(rng), ring = 1.0 + 0.35 * std::cos(v);
    clouds[1].insert(clouds[1].end(),
      { ring * std::cos(u) + 0.005 * g(rng), ring * std::sin(u) + 0.005 * g(rng), 0.35 * std::sin(v) + 0.005 * g(rng) });
    double p[3] = { 2.0 * u01(rng) - 1.0, 2.0 * u01(rng) - 1.0, 2.0 * u01(rng) - 1.0 };
    p[i % 3] = i % 2 ? 1.0 : -1.0;
    clouds[2].insert(clouds[2].end(), { p[0] + 0.005 * g(rng), p[1] + 0.005 * g(rng), p[2] + 0.005 * g(rng) });
  }
  for (int i = 0; i < 20000; ++i)
  {
    double p[3] = { g(rng), g(rng), g(rng) };
    const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    clouds[3].insert(clouds[3].end(), { p[0] / r + 0.02 * g(rng), p[1] / r + 0.02 * g(rng), p[2] / r + 0.02 * g(rng) });
  }
  const char* names[] = { "lattice torus", "noisy torus", "noisy cube", "very noisy sphere" };
  for (int c = 0; c < 4; ++c)
  {
    const Cloud& cloud = clouds[c];
    CloudNormalsResult want;
    ASSERT_TRUE(ComputeCloudNormals(cloud.data(), Count(cloud), nullptr, CloudNormalsOptions(), want));
    EXPECT_EQ(want.Invalid, 0) << names[c];
    if (c == 3)
    {
      ASSERT_GT(M_PI * std::pow(want.Scale.NormalRadius / want.Scale.Spacing, 2), 400.0)
        << "the cloud does not exercise the thinned jets";
    }
    for (unsigned seed : { 1u, 2u, 3u })
    {
      const std::vector<Index> perm = Permutation(Count(cloud), seed);
      const Cloud permuted = Permute(cloud, perm, 3);
      CloudNormalsResult got;
      ASSERT_TRUE(ComputeCloudNormals(permuted.data(), Count(permuted), nullptr, CloudNormalsOptions(), got));
      EXPECT_TRUE(SameBits(got.Normals, Permute(want.Normals, perm, 3))) << names[c] << ", permutation " << seed;
      EXPECT_TRUE(SameBits(got.Curvature, Permute(want.Curvature, perm, 1))) << names[c] << ", permutation " << seed;
      EXPECT_TRUE(SameBits(got.Radius, Permute(want.Radius, perm, 1))) << names[c] << ", permutation " << seed;
      EXPECT_TRUE(SameBits(got.Confidence, Permute(want.Confidence, perm, 1))) << names[c] << ", permutation " << seed;
    }
  }
}
