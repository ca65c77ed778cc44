// The CUDA SPH integrator's grid and per-particle passes (cuda/SPHDevice.cu) replayed on the CPU, so that what
// only a GPU can run is checked here as far as it can be. The neighbour grid as the device rebuilds it:
// NeighborGrid::ChooseCells for the bounds, cell keys from NeighborGrid::MortonTables and GridAxisCell, a stable
// sort of (key, index) (the device's CUB radix sort is stable), cell ranges from runs of equal keys; and the
// neighbour walk GridForEachCandidate (Common/GridCell.h, the function the kernels call). They must reproduce
// NeighborGrid's SortedOrder() and Cells() (the solver's grid, SetCellsByPosition(false)), and list every point's
// neighbours within h in the order of FindWithinRadiusForAllPoints' rows (fluid) and of FindWithinRadius
// (arbitrary positions, the wall dummies' queries), so that the device's sums add the same terms in the same order
// as the CPU's. Then the kernels' per-thread functions (SPH/SPHGridPasses.h) run over such a grid in host loops must
// give SPHFluid's density, pressure and accelerations bit for bit (dam breaks in motion, 2D and 3D, Ideal and
// Tait, every force term).
#include "Common/GridCell.h"
#include "Common/GridCellView.h"
#include "Common/NeighborGrid.h"
#include "SPH/SPHFluid.h"
#include "SPH/SPHGridPasses.h"

#include <cstring>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

namespace
{
using meshfree::Index;

/// The device's grid build, on the host; fills `view` (pointing into the vectors).
void DeviceStyleBuild(const std::vector<double>& x, double h, std::vector<std::int32_t>& order,
  std::vector<double>& sorted, std::vector<meshfree::GridCellRange32>& cells, meshfree::GridCells& view)
{
  const Index n = static_cast<Index>(x.size() / 3);
  double lo[3] = { x[0], x[1], x[2] }, hi[3] = { x[0], x[1], x[2] };
  for (Index i = 0; i < n; ++i)
  {
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], x[3 * i + a]);
      hi[a] = std::max(hi[a], x[3 * i + a]);
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    view.Origin[a] = lo[a];
    view.Extent[a] = hi[a] - lo[a];
  }
  meshfree::NeighborGrid::ChooseCells(view.Extent, h, n, 8.0, view.Size, view.Inverse, view.Dims);
  std::vector<std::uint64_t> spread[3];
  meshfree::NeighborGrid::MortonTables(view.Dims, spread);
  std::vector<std::uint64_t> keys(n);
  auto cell = [&](const double* p, int a) {
    return meshfree::GridAxisCell(p[a] - view.Origin[a], view.Inverse, view.Dims[a]);
  };
  for (Index i = 0; i < n; ++i)
  {
    const double* p = &x[3 * i];
    keys[i] = spread[0][cell(p, 0)] | spread[1][cell(p, 1)] | spread[2][cell(p, 2)];
  }
  order.resize(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) { return keys[a] < keys[b]; });
  sorted.resize(3 * n);
  cells.assign(static_cast<std::size_t>(view.Dims[0] * view.Dims[1] * view.Dims[2]), { 0, 0 });
  for (Index s = 0; s < n; ++s)
  {
    const double* p = &x[3 * order[s]];
    std::copy(p, p + 3, &sorted[3 * s]);
    const Index c = cell(p, 0) + view.Dims[0] * (cell(p, 1) + view.Dims[1] * cell(p, 2));
    if (s == 0 || keys[order[s]] != keys[order[s - 1]])
    {
      cells[c].Begin = static_cast<std::int32_t>(s);
    }
    if (s == n - 1 || keys[order[s]] != keys[order[s + 1]])
    {
      cells[c].End = static_cast<std::int32_t>(s + 1);
    }
  }
  view.Sorted = sorted.data();
  view.Order = order.data();
  view.Cells = cells.data();
  view.Count = n;
}

double Distance2(const double* a, const double* b)
{
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

/// A lattice block with jitter (a dam break after some steps), a flat (2D) one, and a random cloud.
std::vector<std::vector<double>> Clouds(double dx)
{
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> jitter(-0.3 * dx, 0.3 * dx), unit(0.0, 1.0);
  std::vector<std::vector<double>> clouds(3);
  for (int i = 0; i < 24; ++i)
  {
    for (int j = 0; j < 10; ++j)
    {
      for (int k = 0; k < 20; ++k)
      {
        const double p[3] = { (i + 0.5) * dx + jitter(random), (j + 0.5) * dx + jitter(random),
          (k + 0.5) * dx + jitter(random) };
        clouds[0].insert(clouds[0].end(), p, p + 3);
        if (j == 0)
        {
          const double q[3] = { p[0], 0.0, p[2] };
          clouds[1].insert(clouds[1].end(), q, q + 3);
        }
      }
    }
  }
  for (int k = 0; k < 3000; ++k)
  {
    const double p[3] = { 0.3 * unit(random), 0.1 * unit(random), 0.2 * unit(random) * unit(random) };
    clouds[2].insert(clouds[2].end(), p, p + 3);
  }
  // Exact duplicates and points on cell faces.
  for (std::vector<double>& c : clouds)
  {
    const std::vector<double> first(c.begin(), c.begin() + 30);
    c.insert(c.end(), first.begin(), first.end());
    const double face[3] = { 4.0 * 2.0 * dx + c[0], c[1], c[2] };
    c.insert(c.end(), face, face + 3);
  }
  return clouds;
}
} // namespace

TEST(SPHDeviceEmulation, DeviceStyleBuildReproducesTheGrid)
{
  const double dx = 0.01, h = 2.0 * dx;
  for (const std::vector<double>& x : Clouds(dx))
  {
    const Index n = static_cast<Index>(x.size() / 3);
    meshfree::NeighborGrid grid;
    grid.SetCellsByPosition(false); // the SPH integrator's layout
    ASSERT_TRUE(grid.Build(x.data(), n, h));
    std::vector<std::int32_t> order;
    std::vector<double> sorted;
    std::vector<meshfree::GridCellRange32> cells;
    meshfree::GridCells view;
    DeviceStyleBuild(x, h, order, sorted, cells, view);
    EXPECT_EQ(view.Size, grid.CellSize());
    Index dims[3];
    grid.GetGridDimensions(dims);
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_EQ(view.Dims[a], dims[a]) << a;
    }
    const std::vector<Index>& want = grid.SortedOrder();
    ASSERT_EQ(static_cast<Index>(want.size()), n);
    for (Index s = 0; s < n; ++s)
    {
      ASSERT_EQ(order[s], want[s]) << "sorted position " << s;
    }
    const Index cellCount = dims[0] * dims[1] * dims[2];
    ASSERT_EQ(static_cast<Index>(cells.size()), cellCount);
    for (Index c = 0; c < cellCount; ++c)
    {
      const bool empty = grid.Cells()[c].End <= grid.Cells()[c].Begin;
      ASSERT_EQ(cells[c].End <= cells[c].Begin, empty) << "cell " << c;
      if (!empty)
      {
        ASSERT_EQ(cells[c].Begin, grid.Cells()[c].Begin) << "cell " << c;
        ASSERT_EQ(cells[c].End, grid.Cells()[c].End) << "cell " << c;
      }
    }
  }
}

TEST(SPHDeviceEmulation, CandidateWalkListsNeighboursInTheRowsOrder)
{
  const double dx = 0.01, h = 2.0 * dx, h2 = h * h;
  for (const std::vector<double>& x : Clouds(dx))
  {
    const Index n = static_cast<Index>(x.size() / 3);
    meshfree::NeighborGrid grid;
    grid.SetCellsByPosition(false); // the SPH integrator's layout
    ASSERT_TRUE(grid.Build(x.data(), n, h));
    std::vector<Index> offsets;
    std::vector<std::int32_t> rows;
    ASSERT_TRUE(grid.FindWithinRadiusForAllPoints(h, offsets, rows, true));
    std::vector<std::int32_t> order;
    std::vector<double> sorted;
    std::vector<meshfree::GridCellRange32> cells;
    meshfree::GridCells view;
    DeviceStyleBuild(x, h, order, sorted, cells, view);
    std::vector<std::int32_t> walked, expected;
    Index pairs = 0;
    for (Index s = 0; s < n; ++s) // the device's thread s: particle order[s]
    {
      const Index i = order[s];
      const double* xi = &sorted[3 * s];
      walked.clear();
      meshfree::GridForEachCandidate(view, xi, h, [&](std::int32_t t) {
        if (t != s && Distance2(xi, &sorted[3 * static_cast<Index>(t)]) < h2)
        {
          walked.push_back(order[t]);
        }
      });
      expected.clear();
      for (Index k = offsets[i]; k < offsets[i + 1]; ++k) // the CPU sums skip r^2 >= h^2
      {
        if (Distance2(&x[3 * i], &x[3 * static_cast<Index>(rows[k])]) < h2)
        {
          expected.push_back(rows[k]);
        }
      }
      ASSERT_EQ(walked, expected) << "particle " << i;
      pairs += static_cast<Index>(walked.size());
    }
    EXPECT_GT(pairs, 10 * n);

    // Queries at arbitrary positions (wall dummies, inside and outside the cloud's bounds) against
    // FindWithinRadius.
    std::mt19937_64 random(3);
    std::uniform_real_distribution<double> around(-0.05, 0.35);
    std::vector<Index> ids;
    for (int q = 0; q < 2000; ++q)
    {
      const double p[3] = { around(random), 0.4 * around(random) - 0.02, 0.7 * around(random) };
      walked.clear();
      meshfree::GridForEachCandidate(view, p, h, [&](std::int32_t t) {
        if (Distance2(p, &sorted[3 * static_cast<Index>(t)]) < h2)
        {
          walked.push_back(order[t]);
        }
      });
      grid.FindWithinRadius(p, h, ids);
      expected.clear();
      for (Index id : ids)
      {
        if (Distance2(p, &x[3 * id]) < h2)
        {
          expected.push_back(static_cast<std::int32_t>(id));
        }
      }
      ASSERT_EQ(walked, expected) << "query " << q;
    }
  }
}

namespace
{
template <class T>
bool SameBits(const std::vector<T>& a, const std::vector<T>& b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(T) * a.size()) == 0;
}
} // namespace

TEST(SPHDeviceEmulation, GridPassesGiveTheCPUsForces)
{
  for (int dimension : { 2, 3 })
  {
    for (bool tait : { false, true })
    {
      meshfree::SPHParameters p;
      p.Dimension = dimension;
      p.ParticleSpacing = dimension == 2 ? 0.004 : 0.008;
      p.Viscosity = 1e-3;
      p.SurfaceTension = 0.0728;
      p.ArtificialViscosity = 0.05;
      p.EquationOfState = tait ? meshfree::SPHEquationOfState::Tait : meshfree::SPHEquationOfState::Ideal;
      const double fluid[6] = { 0.0, 0.1, 0.0, dimension == 2 ? 0.0 : 0.06, 0.0, 0.15 };
      const double domain[6] = { 0.0, 0.3, 0.0, dimension == 2 ? 0.0 : 0.06, 0.0, 0.2 };
      std::copy(fluid, fluid + 6, p.FluidBounds);
      std::copy(domain, domain + 6, p.DomainBounds);
      meshfree::SPHFluid solver;
      solver.Setup(p);
      meshfree::SPHState state = solver.InitialState();
      ASSERT_EQ(solver.Advance(state, 0.03), meshfree::SPHFluid::Status::Ok); // in motion, reordered
      // Velocities with noise (approaching and receding pairs everywhere), then the CPU's force evaluation.
      std::mt19937_64 random(11);
      std::normal_distribution<double> noise(0.0, 0.05);
      for (double& v : state.Velocity)
      {
        v += noise(random);
      }
      if (dimension == 2)
      {
        for (std::size_t i = 1; i < state.Velocity.size(); i += 3)
        {
          state.Velocity[i] = 0.0;
        }
      }
      meshfree::SPHState cpu = state;
      solver.UpdateDerived(cpu);

      const Index n = state.Size();
      const meshfree::SPHConstants& c = solver.Constants();
      std::vector<std::int32_t> order, wallOrder;
      std::vector<double> sorted;
      std::vector<meshfree::GridCellRange32> cells, wallCells;
      meshfree::GridCells fluidView;
      DeviceStyleBuild(state.Position, c.H, order, sorted, cells, fluidView);
      const meshfree::GridCells wallView = meshfree::GridCellView(solver.BoundaryNeighborGrid(), wallOrder, wallCells);
      ASSERT_GT(wallView.Count, 0);
      std::vector<double> rho(n), pressure(n), term(n), inverse(n), acc(3 * n);
      for (Index s = 0; s < n; ++s)
      {
        meshfree::SPHGridDensity(s, fluidView, wallView, c, rho.data(), pressure.data(), term.data(), inverse.data());
      }
      const std::vector<double>& bx = solver.BoundaryPositions();
      const Index nb = static_cast<Index>(bx.size() / 3);
      std::vector<double> wallTerm(nb);
      for (Index b = 0; b < nb; ++b)
      {
        wallTerm[b] = meshfree::SPHGridWallTerm(&bx[3 * b], fluidView, pressure.data(), rho.data(), c);
      }
      for (Index s = 0; s < n; ++s)
      {
        meshfree::SPHGridAcceleration(s, fluidView, wallView, state.Velocity.data(), rho.data(), inverse.data(),
          term.data(), wallTerm.data(), c, acc.data());
      }
      const std::string what = std::to_string(dimension) + (tait ? "D Tait" : "D Ideal");
      EXPECT_TRUE(SameBits(rho, cpu.Density)) << what << ": density";
      EXPECT_TRUE(SameBits(pressure, cpu.Pressure)) << what << ": pressure";
      EXPECT_TRUE(SameBits(acc, cpu.Acceleration)) << what << ": acceleration";
      double differs = 0.0;
      for (Index k = 0; k < 3 * n; ++k)
      {
        differs += acc[k] != state.Acceleration[k] ? 1.0 : 0.0;
      }
      EXPECT_GT(differs, n) << what << ": the noise changed the accelerations (the test sees the velocity terms)";
    }
  }
}
