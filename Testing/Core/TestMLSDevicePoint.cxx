// SPDX-License-Identifier: BSD-3-Clause
// Approximation/MLSDevicePoint.h, the per-point code the CUDA kernel runs, executed here on the CPU (it is
// MESHFREE_HD): its k-nearest search returns exactly NeighborGrid::FindKNearest's (d2, position)-ordered points (random
// and lattice clouds with many distance ties, queries inside, outside and far away, k from 1 to 64 and above the
// cloud size); the whole point (search, weights, fast path, values and gradients) gives the Approximator's bits
// wherever it does not hand the point back, and hands back every probe of a nearly collinear strip.
#include "Approximation/Approximation.h"
#include "Approximation/MLSDevicePoint.h"
#include "MLSHostViews.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace
{
using namespace meshfree;

using meshfree::testing::HostViews;
using meshfree::testing::MakeHostViews;

void CheckKNearest(const std::vector<double>& xyz, const std::vector<double>& queries, const std::string& what)
{
  NeighborGrid grid;
  grid.Build(xyz.data(), static_cast<Index>(xyz.size() / 3));
  HostViews v;
  MakeHostViews(grid, std::vector<double>(xyz.size() / 3, 0.0), 1, v);
  const Index n = grid.NumberOfValidPoints();
  int compared = 0, gaveUp = 0;
  for (int k : { 1, 7, 20, 64 })
  {
    std::vector<Index> ids(k);
    std::vector<double> d2(k);
    for (size_t q = 0; q < queries.size() / 3; ++q)
    {
      const double* x = &queries[3 * q];
      double bd2[mls::kMaxNeighbors];
      int bid[mls::kMaxNeighbors], bpos[mls::kMaxNeighbors];
      const int found = mls::KNearest(v.Cloud, x, k, bd2, bid, bpos);
      if (found < 0)
      {
        ++gaveUp; // far query: the CPU takes it
        continue;
      }
      const int expected = grid.FindKNearest(x, k, ids.data(), d2.data());
      ASSERT_EQ(found, expected) << what << " k " << k << " query " << q;
      ASSERT_EQ(found, std::min<Index>(k, n));
      for (int j = 0; j < found; ++j)
      {
        ASSERT_EQ(bid[j], ids[j]) << what << " k " << k << " query " << q << " rank " << j;
        ASSERT_EQ(std::memcmp(&bd2[j], &d2[j], sizeof(double)), 0) << what << " k " << k << " query " << q;
        ASSERT_EQ(grid.SortedOrder()[bpos[j]], ids[j]);
      }
      ++compared;
    }
  }
  EXPECT_GT(compared, static_cast<int>(queries.size() / 3) * 3) << what;
  EXPECT_LT(gaveUp, static_cast<int>(queries.size() / 3)) << what;
}

std::vector<double> Queries(int count, double lo, double hi, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> q(3 * count);
  for (double& x : q)
  {
    x = u(rng);
  }
  return q;
}
} // namespace

TEST(MLSDevicePoint, KNearestIsFindKNearest)
{
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> random(3 * 5000);
  for (double& x : random)
  {
    x = u(rng);
  }
  CheckKNearest(random, Queries(300, -1.3, 1.3, 4), "random cube");
  // A lattice (many equal distances: the position decides) with queries on and between lattice points.
  std::vector<double> lattice;
  for (int i = 0; i < 12; ++i)
  {
    for (int j = 0; j < 12; ++j)
    {
      for (int k = 0; k < 12; ++k)
      {
        lattice.insert(lattice.end(), { 0.1 * i, 0.1 * j, 0.1 * k });
      }
    }
  }
  std::vector<double> onLattice;
  for (int q = 0; q < 100; ++q)
  {
    onLattice.insert(onLattice.end(), { 0.1 * (q % 12), 0.05 * (q % 23), 0.1 * ((q / 12) % 12) });
  }
  CheckKNearest(lattice, onLattice, "lattice");
  // A flat cloud (one layer of cells in z), queries off the plane; and a cloud smaller than k.
  std::vector<double> flat(random);
  for (size_t i = 0; i < flat.size() / 3; ++i)
  {
    flat[3 * i + 2] = 0.0;
  }
  CheckKNearest(flat, Queries(200, -1.2, 1.2, 5), "flat");
  CheckKNearest(std::vector<double>(random.begin(), random.begin() + 3 * 30), Queries(50, -1.0, 1.0, 6), "30 points");
}

namespace
{
template <int D, int M>
void CheckPoints(int dim, KernelType weight, bool gradients)
{
  const std::string what = "dim " + std::to_string(dim) + " degree " + std::to_string(M) + " " + KernelName(weight) +
    (gradients ? " with gradients" : "");
  std::mt19937_64 rng(10 * dim + M);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 6000, C = 5; // 5 components: two passes of the component group
  std::vector<double> xyz(3 * n), values(C * n);
  for (int i = 0; i < n; ++i)
  {
    double* x = &xyz[3 * i];
    x[0] = i < 40 ? 2.0 + 1e-3 * i : u(rng);
    x[1] = i < 40 ? 2.0 + 1e-9 * u(rng) : u(rng);
    x[2] = dim == 3 ? (i < 40 ? 2.0 : u(rng)) : 0.3 * x[0] + 0.1 * x[1] + 2.0;
    for (int c = 0; c < C; ++c)
    {
      values[C * i + c] = c == 0 ? std::sin(3.0 * x[0]) + x[1] * x[2] : u(rng);
    }
  }
  const int m = 1500;
  std::vector<double> q(3 * m);
  for (int i = 0; i < m; ++i)
  {
    double* x = &q[3 * i];
    x[0] = i < 20 ? 2.0 + 1e-3 * i : 1.1 * u(rng);
    x[1] = i < 20 ? 2.0 : 1.1 * u(rng);
    x[2] = dim == 3 ? (i < 20 ? 2.0 : 1.1 * u(rng)) : 0.3 * x[0] + 0.1 * x[1] + 2.0;
  }
  ApproximationOptions o;
  o.Degree = M;
  o.Weight = weight;
  o.ComputeGradients = gradients;
  o.Backend = ApproximationBackend::CPU;
  Approximator a;
  ASSERT_TRUE(a.SetOptions(o));
  a.SetCloud(xyz.data(), n, values.data(), C);
  ASSERT_EQ(a.CloudDimension(), D);
  std::vector<double> cv(C * m), cg(3 * C * m), cn(m);
  std::vector<unsigned char> valid(m);
  ApproximationOutput out;
  out.Values = cv.data();
  out.Gradients = gradients ? cg.data() : nullptr;
  out.NeighborCounts = cn.data();
  out.Valid = valid.data();
  a.Evaluate(q.data(), m, out);

  HostViews v;
  MakeHostViews(a.Grid(), values, C, v);
  mls::FitConstants fc = meshfree::testing::MakeFitConstants(a, o, D);
  std::vector<double> dv(C * m, -7.0), dg(3 * C * m, -7.0), conditions(m);
  std::vector<int> dn(m, -1);
  std::vector<unsigned char> needs(m, 0);
  mls::OutputView ov{ dv.data(), dg.data(), dn.data(), conditions.data(), needs.data() };
  meshfree::testing::RunHostPoints<D, M>(v.Cloud, fc, q.data(), m, ov);
  int handed = 0, strip = 0, differ = 0;
  for (int t = 0; t < m; ++t)
  {
    if (needs[t])
    {
      ++handed;
      strip += t < 20 ? 1 : 0;
      continue;
    }
    const bool same = valid[t] == 1 && std::memcmp(&dv[C * t], &cv[C * t], sizeof(double) * C) == 0 &&
      (!gradients || std::memcmp(&dg[3 * C * t], &cg[3 * C * t], sizeof(double) * 3 * C) == 0) &&
      static_cast<double>(dn[t]) == cn[t] && conditions[t] >= 1.0 && conditions[t] < kFastPathRatio;
    differ += same ? 0 : 1;
  }
  EXPECT_EQ(differ, 0) << what << ": the points it finishes carry the CPU's bits";
  EXPECT_EQ(strip, 20) << what << ": every strip probe goes to the CPU";
  EXPECT_LT(handed, m / 20) << what << ": few points go to the CPU on a healthy cloud";
}
} // namespace

TEST(MLSDevicePoint, PointsCarryTheCpuBits)
{
  for (KernelType weight : { KernelType::Wendland, KernelType::Poly6, KernelType::Lucy })
  {
    for (bool gradients : { false, true })
    {
      CheckPoints<2, 1>(2, weight, gradients);
      CheckPoints<2, 2>(2, weight, gradients);
      CheckPoints<2, 3>(2, weight, gradients);
      CheckPoints<3, 1>(3, weight, gradients);
      CheckPoints<3, 2>(3, weight, gradients);
    }
  }
}
