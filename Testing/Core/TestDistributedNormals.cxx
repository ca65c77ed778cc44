// SPDX-License-Identifier: BSD-3-Clause
// The core's distributed normals (Common/Distribution.h) without MPI: P threads stand in for P processes, each with
// its piece and a halo (every point within the halo radius of its piece's box), communicating through shared
// memory. Each piece's own results must equal the serial run's, bit for bit; and the exact distributed selection
// (GlobalSelect) must pick what nth_element picks.
#include "Common/Distribution.h"
#include "Common/Parallel.h"
#include "Surface/CloudNormals.h"
#include "SurfaceSamples.h"
#include "ThreadProcesses.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

using namespace meshfree;
using namespace meshfree::testing;
namespace samples = meshfree::testing;

namespace
{
/// Splits the cloud into `size` slabs along x (owner by position rank), each with every point within `radius`
/// of its slab's box as halo. Keys are the input indices.
std::vector<Piece> Split(const std::vector<double>& xyz, int size, double radius)
{
  const Index n = static_cast<Index>(xyz.size() / 3);
  std::vector<Index> order(n);
  for (Index i = 0; i < n; ++i)
  {
    order[i] = i;
  }
  std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) { return xyz[3 * a] < xyz[3 * b]; });
  std::vector<int> owner(n);
  std::vector<Index> ownerIndex(n);
  std::vector<Piece> pieces(size);
  for (Index j = 0; j < n; ++j)
  {
    const int r = static_cast<int>(j * size / n);
    const Index i = order[j];
    Piece& p = pieces[r];
    owner[i] = r;
    ownerIndex[i] = p.OwnCount++;
    p.Points.insert(p.Points.end(), &xyz[3 * i], &xyz[3 * i] + 3);
    p.Owner.push_back(r);
    p.OwnerIndex.push_back(ownerIndex[i]);
    p.Keys.push_back(i);
  }
  for (int r = 0; r < size; ++r)
  {
    Piece& p = pieces[r];
    p.Radius = radius;
    for (int a = 0; a < 3; ++a)
    {
      p.Region[2 * a] = HUGE_VAL;
      p.Region[2 * a + 1] = -HUGE_VAL;
    }
    for (Index i = 0; i < p.OwnCount; ++i)
    {
      for (int a = 0; a < 3; ++a)
      {
        p.Region[2 * a] = std::min(p.Region[2 * a], p.Points[3 * i + a]);
        p.Region[2 * a + 1] = std::max(p.Region[2 * a + 1], p.Points[3 * i + a]);
      }
    }
    for (Index i = 0; i < n; ++i)
    {
      if (owner[i] == r)
      {
        continue;
      }
      double d2 = 0.0;
      for (int a = 0; a < 3; ++a)
      {
        const double x = xyz[3 * i + a];
        const double d = x < p.Region[2 * a] ? p.Region[2 * a] - x : (x > p.Region[2 * a + 1] ? x - p.Region[2 * a + 1] : 0.0);
        d2 += d * d;
      }
      if (d2 <= radius * radius)
      {
        p.Points.insert(p.Points.end(), &xyz[3 * i], &xyz[3 * i] + 3);
        p.Owner.push_back(owner[i]);
        p.OwnerIndex.push_back(ownerIndex[i]);
        p.Keys.push_back(i);
      }
    }
  }
  return pieces;
}

/// Runs the distributed computation on `size` threads; returns each piece's result and the largest shortfall.
double RunDistributed(const std::vector<double>& xyz, int size, double radius, const CloudNormalsOptions& options,
  std::vector<Piece>& pieces, std::vector<CloudNormalsResult>& results)
{
  pieces = Split(xyz, size, radius);
  results.assign(size, CloudNormalsResult());
  World world(size);
  double frame[6];
  const Index finite = WholeFrame(xyz, frame);
  std::vector<std::thread> threads;
  for (int r = 0; r < size; ++r)
  {
    threads.emplace_back([&, r]() {
      ThreadDistribution processes(world, r, pieces);
      CloudNormalsOptions mine = options;
      mine.Neighborhood.Processes = &processes;
      mine.Framed = true;
      std::copy(frame, frame + 6, mine.FrameBounds);
      mine.FramePoints = finite;
      const Piece& p = pieces[r];
      ComputeCloudNormals(p.Points.data(), static_cast<Index>(p.Points.size() / 3), nullptr, mine, results[r]);
    });
  }
  for (std::thread& t : threads)
  {
    t.join();
  }
  double shortfall = -HUGE_VAL;
  for (const CloudNormalsResult& r : results)
  {
    shortfall = std::max(shortfall, r.Shortfall);
  }
  return shortfall;
}

void ExpectSameAsSerial(const std::vector<double>& xyz, const CloudNormalsOptions& options, int size, double radius)
{
  CloudNormalsResult serial;
  ASSERT_TRUE(ComputeCloudNormals(xyz.data(), static_cast<Index>(xyz.size() / 3), nullptr, options, serial));
  std::vector<Piece> pieces;
  std::vector<CloudNormalsResult> results;
  const double shortfall = RunDistributed(xyz, size, radius, options, pieces, results);
  ASSERT_LE(shortfall, 0.0) << "the halo of radius " << radius << " was too narrow";
  Index checked = 0, halo = 0;
  for (int r = 0; r < size; ++r)
  {
    const Piece& p = pieces[r];
    const CloudNormalsResult& got = results[r];
    halo += static_cast<Index>(p.Points.size() / 3) - p.OwnCount;
    for (Index i = 0; i < p.OwnCount; ++i)
    {
      const Index k = p.Keys[i];
      for (int a = 0; a < 3; ++a)
      {
        ASSERT_EQ(got.Normals[3 * i + a], serial.Normals[3 * k + a]) << "point " << k << " on " << r;
        // The same bits (a NaN input point keeps its NaN coordinates).
        ASSERT_EQ(std::memcmp(&got.Points[3 * i + a], &serial.Points[3 * k + a], sizeof(double)), 0)
          << "point " << k << " on " << r;
      }
      ASSERT_EQ(got.Curvature[i], serial.Curvature[k]) << "point " << k;
      ASSERT_EQ(got.SurfaceVariation[i], serial.SurfaceVariation[k]) << "point " << k;
      ASSERT_EQ(got.Confidence[i], serial.Confidence[k]) << "point " << k;
      ASSERT_EQ(got.Valid[i], serial.Valid[k]) << "point " << k;
      ++checked;
    }
    EXPECT_EQ(got.Orientation.Components, serial.Orientation.Components);
    EXPECT_EQ(got.Orientation.Ambiguous, serial.Orientation.Ambiguous);
    EXPECT_EQ(got.Scale.NormalRadius, serial.Scale.NormalRadius);
  }
  EXPECT_EQ(checked, static_cast<Index>(xyz.size() / 3));
  // Not the whole cloud on every piece: the halos together are less than (size - 1) clouds.
  EXPECT_LT(halo, (size - 1) * static_cast<Index>(xyz.size() / 3));
}

class DistributedNormals : public ::testing::Test
{
protected:
  void SetUp() override { SetMaxThreads(1); } // the "processes" are threads already
  void TearDown() override { SetMaxThreads(0); }
};
} // namespace

TEST(Distribution, GlobalSelectIsTheSerialSelection)
{
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> values;
  for (int i = 0; i < 5000; ++i)
  {
    values.push_back(i % 7 == 0 ? std::round(normal(rng)) : normal(rng)); // ties, and both signs
  }
  values.push_back(0.0);
  values.push_back(-0.0);
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  // Three "processes" holding interleaved thirds.
  for (Index rank : { Index(0), Index(1), Index(2500), Index(5001) })
  {
    World world(3);
    std::vector<Piece> none(3);
    std::vector<double> got(3);
    std::vector<std::thread> threads;
    for (int r = 0; r < 3; ++r)
    {
      threads.emplace_back([&, r]() {
        ThreadDistribution d(world, r, none);
        std::vector<double> mine;
        for (size_t i = r; i < values.size(); i += 3)
        {
          mine.push_back(values[i]);
        }
        got[r] = GlobalSelect(&d, mine, rank);
      });
    }
    for (std::thread& t : threads)
    {
      t.join();
    }
    for (int r = 0; r < 3; ++r)
    {
      EXPECT_EQ(got[r], sorted[rank]) << "rank " << rank;
    }
  }
  EXPECT_EQ(GlobalMedian(nullptr, values), sorted[values.size() / 2]);
}

TEST_F(DistributedNormals, NoisyTorusOnThreeSlabsIsTheSerialRun)
{
  const samples::SurfaceCloud cloud = samples::SampleSurface(true, 12000, 0.004, 21);
  std::vector<double> xyz = cloud.Points;
  // A few exact duplicates across slabs, and points with a NaN coordinate (invalid, on the ranks of their x).
  std::copy(xyz.begin(), xyz.begin() + 30, xyz.end() - 30);
  for (int j = 0; j < 5; ++j)
  {
    xyz[3 * (100 + 997 * j) + 1] = std::nan("");
  }
  ExpectSameAsSerial(xyz, CloudNormalsOptions(), 3, 0.6);
}

TEST_F(DistributedNormals, ThinnedWideJetsOnThreeSlabsAreTheSerialRun)
{
  // Noise large against the spacing: the normals' radius holds about 1000 points, so the jets are fitted over the
  // thinned cloud (SurfaceNormals.cxx, BuildThinnedCloud), a grid of its own on every process.
  const samples::SurfaceCloud cloud = samples::SampleSurface(false, 20000, 0.02, 17);
  CloudNormalsResult serial;
  ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, CloudNormalsOptions(), serial));
  const double held = M_PI * std::pow(serial.Scale.NormalRadius / serial.Scale.Spacing, 2);
  ASSERT_GT(held, 400.0) << "the cloud does not exercise the thinned jets";
  ExpectSameAsSerial(cloud.Points, CloudNormalsOptions(), 3, 1.0);
}

TEST_F(DistributedNormals, SharpEdgesOnThreeSlabsAreTheSerialRun)
{
  // A noisy cube: points near its edges take a neighbour's normal (SurfaceNormals.cxx, SharpFeatures), the jets'
  // own normals are oriented and the donors' follow them (NormalOrientation.h), on every process alike.
  const samples::SurfaceCloud cloud = samples::SampleCube(20000, 0.02, 9);
  ExpectSameAsSerial(cloud.Points, CloudNormalsOptions(), 3, 1.0);
}

TEST_F(DistributedNormals, ProjectionAndViewpointOnFourSlabs)
{
  const samples::SurfaceCloud cloud = samples::SampleSurface(false, 8000, 0.003, 5);
  CloudNormalsOptions options;
  options.ProjectPoints = true;
  options.Orientation = OrientationMode::Viewpoint;
  options.Viewpoint[2] = 3.0;
  ExpectSameAsSerial(cloud.Points, options, 4, 1.25);
}

TEST_F(DistributedNormals, ANarrowHaloIsReportedAsAShortfall)
{
  const samples::SurfaceCloud cloud = samples::SampleSurface(true, 6000, 0.004, 8);
  std::vector<Piece> pieces;
  std::vector<CloudNormalsResult> results;
  EXPECT_GT(RunDistributed(cloud.Points, 2, 0.01, CloudNormalsOptions(), pieces, results), 0.0);
}
