// SPDX-License-Identifier: BSD-3-Clause
// Approximator's Backend choice (Auto/CPU/CUDA): Backend CUDA gives the CPU's result bit for bit whatever happens -
// without a device (here: the report says "CPU (...)" and why) and with one (the device's points carry the CPU's
// bits, the others are finished by the CPU; the report says "CUDA (...)"). Image probes generated on the fly give
// the bits of the same points given explicitly. Auto stays on the CPU for small jobs; methods without a device path
// say so when CUDA is asked for.
#include "Approximation/Approximation.h"
#include "StripCloud.h"
#include "cuda/Device.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace
{
using namespace meshfree;

struct Result
{
  std::vector<double> Values, Gradients, Counts;
  std::vector<unsigned char> Valid;
  ApproximationReport Report;
};

/// m probes over the cloud of MakeStripCloud, the first 20 on its strip.
std::vector<double> Probes(int dim, int m, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.1, 1.1);
  std::vector<double> q(3 * m);
  for (int i = 0; i < m; ++i)
  {
    double* x = &q[3 * i];
    x[0] = u(rng);
    x[1] = u(rng);
    x[2] = dim == 3 ? u(rng) : 0.3 * x[0] + 0.1 * x[1] + 2.0;
    if (i < 20)
    {
      x[0] = 2.0 + 1e-3 * i;
      x[1] = 2.0;
      x[2] = dim == 3 ? 2.0 : 0.3 * x[0] + 0.1 * x[1] + 2.0;
    }
  }
  return q;
}

Result Approximate(const std::vector<double>& xyz, const std::vector<double>& values, const double* probes,
  const ImageGeometry* image, Index m, ApproximationOptions options)
{
  Approximator a;
  EXPECT_TRUE(a.SetOptions(options));
  a.SetCloud(xyz.data(), static_cast<Index>(xyz.size() / 3), values.data(), 2);
  Result r;
  r.Values.assign(2 * m, -1.0);
  r.Gradients.assign(6 * m, -1.0);
  r.Counts.assign(m, -1.0);
  r.Valid.assign(m, 7);
  ApproximationOutput out;
  out.Values = r.Values.data();
  out.Gradients = options.ComputeGradients ? r.Gradients.data() : nullptr;
  out.NeighborCounts = r.Counts.data();
  out.Valid = r.Valid.data();
  if (image)
  {
    a.EvaluateImage(*image, out);
  }
  else
  {
    a.Evaluate(probes, m, out);
  }
  r.Report = a.Report();
  return r;
}

template <class T>
bool SameBits(const std::vector<T>& a, const std::vector<T>& b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(T) * a.size()) == 0;
}

void ExpectSame(const Result& a, const Result& b, const std::string& what)
{
  EXPECT_TRUE(SameBits(a.Values, b.Values)) << what << ": values";
  EXPECT_TRUE(SameBits(a.Gradients, b.Gradients)) << what << ": gradients";
  EXPECT_TRUE(SameBits(a.Counts, b.Counts)) << what << ": neighbour counts";
  EXPECT_TRUE(SameBits(a.Valid, b.Valid)) << what << ": valid flags";
  EXPECT_EQ(a.Report.Masked, b.Report.Masked) << what;
}
} // namespace

TEST(ApproximationBackend, CudaGivesTheCpuBits)
{
  std::string reason;
  const bool device = cuda::Available(&reason);
  for (int dim = 2; dim <= 3; ++dim)
  {
    std::vector<double> xyz, values;
    meshfree::testing::MakeStripCloud(dim, 4000, xyz, values, 100 + dim);
    const int m = 3000;
    const std::vector<double> q = Probes(dim, m, 200 + dim);
    for (int degree = 1; degree <= 3; ++degree)
    {
      for (int gradients = 0; gradients <= 1; ++gradients)
      {
        for (KernelType weight : { KernelType::Wendland, KernelType::Poly6 })
        {
          ApproximationOptions o;
          o.Method = ApproximationMethod::MLS;
          o.Degree = degree;
          o.Weight = weight;
          o.ComputeGradients = gradients != 0;
          o.Backend = ApproximationBackend::CPU;
          const Result cpu = Approximate(xyz, values, q.data(), nullptr, m, o);
          o.Backend = ApproximationBackend::CUDA;
          const Result gpu = Approximate(xyz, values, q.data(), nullptr, m, o);
          const std::string what = "dim " + std::to_string(dim) + " degree " + std::to_string(degree) + " gradients " +
            std::to_string(gradients) + " weight " + KernelName(weight);
          ExpectSame(cpu, gpu, what);
          EXPECT_EQ(cpu.Report.Backend.rfind("CPU (", 0), 0u) << cpu.Report.Backend;
          EXPECT_TRUE(cpu.Report.BackendNote.empty()) << cpu.Report.BackendNote;
          EXPECT_GT(cpu.Report.Widened + cpu.Report.DegreeLowered, 0) << what << ": the strip needs fallbacks";
          const bool devicePath = device && !(dim == 3 && degree == 3);
          if (devicePath)
          {
            EXPECT_EQ(gpu.Report.Backend.rfind("CUDA (", 0), 0u) << gpu.Report.Backend;
            EXPECT_GT(gpu.Report.DeviceEvaluated, m / 2) << what;
            EXPECT_GT(gpu.Report.DeviceToCPU, 0) << what << ": the strip's probes go back to the CPU";
          }
          else
          {
            EXPECT_EQ(gpu.Report.Backend.rfind("CPU (", 0), 0u) << gpu.Report.Backend;
            EXPECT_EQ(gpu.Report.BackendNote.rfind("Backend CUDA: the CPU evaluated (", 0), 0u)
              << gpu.Report.BackendNote;
            if (!device)
            {
              EXPECT_NE(gpu.Report.BackendNote.find(reason), std::string::npos) << gpu.Report.BackendNote;
            }
            EXPECT_EQ(gpu.Report.DeviceEvaluated, 0);
          }
        }
      }
    }
  }
}

TEST(ApproximationBackend, ImageProbesGiveTheBitsOfExplicitPoints)
{
  std::vector<double> xyz, values;
  meshfree::testing::MakeStripCloud(3, 4000, xyz, values, 7);
  ImageGeometry image;
  const double origin[3] = { -1.05, -0.95, -1.0 }, spacing[3] = { 0.07, 0.09, 0.11 };
  const Index dims[3] = { 31, 23, 19 };
  for (int a = 0; a < 3; ++a)
  {
    image.Origin[a] = origin[a];
    image.Spacing[a] = spacing[a];
    image.Dimensions[a] = dims[a];
  }
  const Index m = image.NumberOfPoints();
  std::vector<double> q(3 * m);
  for (Index i = 0; i < m; ++i)
  {
    ImagePoint(image, i, &q[3 * i]);
  }
  // The lattice formula itself: point (i, j, k) at origin + (i, j, k) * spacing.
  const Index probe = 5 + dims[0] * (7 + dims[1] * 11);
  EXPECT_EQ(q[3 * probe], origin[0] + 5.0 * spacing[0]);
  EXPECT_EQ(q[3 * probe + 1], origin[1] + 7.0 * spacing[1]);
  EXPECT_EQ(q[3 * probe + 2], origin[2] + 11.0 * spacing[2]);
  for (ApproximationMethod method : { ApproximationMethod::MLS, ApproximationMethod::PUWLS })
  {
    for (ApproximationBackend backend : { ApproximationBackend::CPU, ApproximationBackend::CUDA })
    {
      ApproximationOptions o;
      o.Method = method;
      o.ComputeGradients = true;
      o.Backend = backend;
      const Result explicitPoints = Approximate(xyz, values, q.data(), nullptr, m, o);
      const Result generated = Approximate(xyz, values, nullptr, &image, m, o);
      ExpectSame(explicitPoints, generated, ApproximationMethodName(method));
    }
  }
}

TEST(ApproximationBackend, AutoAndOtherMethods)
{
  std::vector<double> xyz, values;
  meshfree::testing::MakeStripCloud(2, 4000, xyz, values, 9);
  const std::vector<double> q = Probes(2, 100, 10);
  ApproximationOptions o;
  o.Backend = ApproximationBackend::Auto; // 100 points x 20 neighbours: far below kAutoDeviceWork
  Result r = Approximate(xyz, values, q.data(), nullptr, 100, o);
  EXPECT_EQ(r.Report.Backend.rfind("CPU (", 0), 0u);
  EXPECT_TRUE(r.Report.BackendNote.empty()) << r.Report.BackendNote;
  EXPECT_EQ(r.Report.DeviceEvaluated, 0);
  o.Method = ApproximationMethod::SPH;
  o.Backend = ApproximationBackend::CUDA;
  r = Approximate(xyz, values, q.data(), nullptr, 100, o);
  EXPECT_EQ(r.Report.Backend.rfind("CPU (", 0), 0u);
  EXPECT_NE(r.Report.BackendNote.find("only MLS has a device path"), std::string::npos) << r.Report.BackendNote;
  // MLS with a fixed support radius and Diagnostics stay on the CPU with a reason, on any machine.
  o.Method = ApproximationMethod::MLS;
  o.SupportRadius = 0.3;
  r = Approximate(xyz, values, q.data(), nullptr, 100, o);
  EXPECT_EQ(r.Report.Backend.rfind("CPU (", 0), 0u);
  EXPECT_FALSE(r.Report.BackendNote.empty());
}
