// SPDX-License-Identifier: BSD-3-Clause
// The surface-reconstruction driver (SurfaceReconstruction.h): validate, scales, field, contour, project.
#include "Surface/SurfaceReconstruction.h"

#include "Common/Parallel.h"
#include "Surface/DataSupport.h"
#include "Surface/FluidSurface.h"
#include "Surface/HoleFilling.h"
#include "Surface/PatchSurface.h"
#include "Surface/PointSetSurface.h"
#include "Surface/UniqueCloud.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

namespace meshfree
{

const char* SurfaceMethodName(SurfaceMethod method)
{
  switch (method)
  {
    case SurfaceMethod::MLS:
      return "MLS";
    case SurfaceMethod::WLS:
      return "WLS";
    case SurfaceMethod::SPH:
      return "SPH";
  }
  return "Unknown";
}

namespace
{
/// A sub-range [begin, end) of the progress scale.
ProgressCallback Stage(const ProgressCallback& progress, double begin, double end)
{
  if (!progress)
  {
    return ProgressCallback();
  }
  return [progress, begin, end](double f) { return progress(begin + (end - begin) * f); };
}

/// Unit normals from the input. A point with finite coordinates and a usable normal takes part even where
/// its neighbourhood gave no PCA plane; one without a usable normal is ignored (radius 0). Returns how many
/// points with finite coordinates had no usable normal.
Index TakeNormals(const SurfaceInput& input, NormalField& field)
{
  Index missing = 0;
  for (Index i = 0; i < input.Count; ++i)
  {
    const double* p = input.Points + 3 * i;
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
    {
      continue;
    }
    const double* n = input.Normals + 3 * i;
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0) || !std::isfinite(len))
    {
      field.Radii[i] = 0.0;
      field.Valid[i] = 0;
      ++missing;
      continue;
    }
    for (int a = 0; a < 3; ++a)
    {
      field.Normals[3 * i + a] = n[a] / len;
    }
    if (!field.Valid[i] && field.NeighborDistance[i] > 0.0)
    {
      field.Radii[i] = std::max(field.NeighborDistance[i], field.Scale.Radius);
    }
    field.Valid[i] = field.Radii[i] > 0.0 ? 1 : 0;
  }
  return missing;
}

/// Lattice origin and cell size around the grid's bounds with a margin; the cell grows when the bounds
/// would need more lattice cells than there are.
void ChooseLattice(const NeighborGrid& grid, double cell, double margin, ContourOptions& lattice, bool& enlarged)
{
  double b[6];
  grid.GetBounds(b);
  double extent = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    extent = std::max(extent, b[2 * a + 1] - b[2 * a]);
  }
  // Room for the data, the margins on both sides and growth beyond them.
  const double usable = static_cast<double>(SparseContour::kMaximumCoordinate) / 2.0;
  enlarged = false;
  if ((extent + 2.0 * margin) / cell > usable)
  {
    cell = (extent + 2.0 * margin) / usable;
    enlarged = true;
  }
  lattice.CellSize = cell;
  for (int a = 0; a < 3; ++a)
  {
    // Centre the data in the lattice's coordinate range so that growth has room on every side.
    const double centre = 0.5 * (b[2 * a] + b[2 * a + 1]);
    lattice.Origin[a] = centre - usable * cell;
  }
}

/// Seed cells of the continuation: per occupied block of 4^3 lattice cells, its first chosen point is moved
/// onto the surface (a few projection steps, at most `reach` away) and the cell it lands in is a seed; a point
/// that cannot be projected, or where |f| >= `farther` (when finite), seeds nothing. Every piece of surface
/// near the data gets many seeds, yet only the cells the surface crosses are evaluated (seeding every
/// occupied cell would evaluate the whole noisy shell of points, several cells thick).
std::vector<std::uint64_t> SeedCells(const NeighborGrid& grid, const ImplicitField& field, const ContourOptions& lattice,
  double reach, const std::vector<unsigned char>& chosen, double farther = std::numeric_limits<double>::infinity(),
  const Distribution* d = nullptr)
{
  const std::vector<Index>& order = grid.SortedOrder();
  const double* sorted = grid.SortedPoints();
  const Index nv = static_cast<Index>(order.size());
  // One representative per block (the sorted order is by grid cell, not by block: sort the block keys).
  std::vector<std::pair<std::uint64_t, Index>> blocks;
  blocks.reserve(static_cast<size_t>(nv));
  for (Index s = 0; s < nv; ++s)
  {
    Index c[3];
    if (chosen[order[s]] && SparseContour::CellOf(sorted + 3 * s, lattice, c))
    {
      blocks.emplace_back(SparseContour::CellKey(c[0] >> 2, c[1] >> 2, c[2] >> 2), s);
    }
  }
  std::sort(blocks.begin(), blocks.end());
  blocks.erase(std::unique(blocks.begin(), blocks.end(),
                 [](const std::pair<std::uint64_t, Index>& a, const std::pair<std::uint64_t, Index>& b) {
                   return a.first == b.first;
                 }),
    blocks.end());
  // Distributed: a block's representative is the whole cloud's (the sorted order is the framed grid's, the same
  // as serial; the halo holds every point of a block with an own point); its owner seeds it.
  blocks.erase(std::remove_if(blocks.begin(), blocks.end(),
                 [d, &order](const std::pair<std::uint64_t, Index>& b) { return !IsOwn(d, order[b.second]); }),
    blocks.end());
  const Index count = static_cast<Index>(blocks.size());
  std::vector<std::uint64_t> seeds(static_cast<size_t>(count), 0);
  std::vector<unsigned char> ok(static_cast<size_t>(count), 0);
  PerThread<FieldScratch> scratches;
  ParallelFor(count, 64, [&](Index begin, Index end) {
    FieldScratch& scratch = scratches.Local();
    for (Index b = begin; b < end; ++b)
    {
      double x[3], n[3];
      const double* p = sorted + 3 * blocks[b].second;
      std::copy(p, p + 3, x);
      double f = 0.0;
      if (std::isfinite(farther) && (!field.Evaluate(x, f, nullptr, scratch) || !(std::fabs(f) < farther)))
      {
        continue; // far from the surface by the field's own measure (a particle deep in the fluid)
      }
      bool projected = field.Project(x, n, reach, 3, scratch);
      if (!projected)
      {
        // A flat field at the point (the centre of a lone droplet): try once from a quarter reach aside.
        const double aside[3] = { p[0] + 0.25 * reach, p[1], p[2] };
        std::copy(aside, aside + 3, x);
        projected = field.Project(x, n, reach, 3, scratch);
      }
      Index c[3];
      if (projected && SparseContour::CellOf(x, lattice, c))
      {
        seeds[b] = SparseContour::CellKey(c[0], c[1], c[2]);
        ok[b] = 1;
      }
    }
  });
  std::vector<std::uint64_t> kept;
  kept.reserve(seeds.size());
  for (Index b = 0; b < count; ++b)
  {
    if (ok[b])
    {
      kept.push_back(seeds[b]);
    }
  }
  return kept;
}

/// |sum a_i n_i| / sum a_i over the (own) samples, 1 without area. The sums are exact integer sums of the terms
/// rounded to a common fixed point (2^-62 of the largest term times the number of terms below it), so that they
/// do not depend on the order of the points nor on how they are split among processes.
double OpenShare(const NeighborGrid& grid, const std::vector<double>& areas, const std::vector<double>& normals,
  const Distribution* d)
{
  const std::vector<Index>& order = grid.SortedOrder();
  double largest = 0.0;
  Index count = 0;
  for (const Index i : order)
  {
    if (areas[i] > 0.0 && std::isfinite(areas[i]) && IsOwn(d, i))
    {
      largest = std::max(largest, areas[i]);
      ++count;
    }
  }
  largest = GlobalMax(d, largest);
  count = GlobalSum(d, count);
  if (!(largest > 0.0) || count == 0)
  {
    return 1.0;
  }
  const int bits = 62 - static_cast<int>(std::ceil(std::log2(static_cast<double>(count) + 1.0)));
  const double scale = std::ldexp(1.0, bits) / largest;
  std::int64_t sums[4] = { 0, 0, 0, 0 };
  for (const Index i : order)
  {
    if (areas[i] > 0.0 && std::isfinite(areas[i]) && IsOwn(d, i))
    {
      sums[0] += std::llround(areas[i] * scale);
      for (int a = 0; a < 3; ++a)
      {
        sums[1 + a] += std::llround(areas[i] * normals[3 * i + a] * scale);
      }
    }
  }
  if (d)
  {
    d->Sum(sums, 4);
  }
  const double total = static_cast<double>(sums[0]);
  const double dipole[3] = { static_cast<double>(sums[1]), static_cast<double>(sums[2]), static_cast<double>(sums[3]) };
  return total > 0.0 ? std::sqrt(dipole[0] * dipole[0] + dipole[1] * dipole[1] + dipole[2] * dipole[2]) / total : 1.0;
}

/// Moves the vertices onto the surface and sets their normals; vertices that cannot be projected keep
/// their place and get the mean of their triangles' normals.
Index ProjectVertices(const ImplicitField& field, double maxStep, bool project, SurfaceMesh& mesh)
{
  const Index nv = mesh.NumberOfPoints();
  mesh.Normals.assign(static_cast<size_t>(3 * nv), 0.0);
  std::vector<unsigned char> done(static_cast<size_t>(nv), 0);
  PerThread<FieldScratch> scratches;
  const Index projected = ParallelReduce(nv, 512, Index(0),
    [&](Index begin, Index end) {
      FieldScratch& scratch = scratches.Local();
      Index count = 0;
      for (Index v = begin; v < end; ++v)
      {
        double* x = &mesh.Points[3 * v];
        double* n = &mesh.Normals[3 * v];
        if (project)
        {
          if (field.Project(x, n, maxStep, 1, scratch))
          {
            done[v] = 1;
            ++count;
          }
          continue;
        }
        double f = 0.0, g[3];
        const double len = field.Evaluate(x, f, g, scratch) ? std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) : 0.0;
        if (len > 0.0 && std::isfinite(len))
        {
          for (int a = 0; a < 3; ++a)
          {
            n[a] = g[a] / len;
          }
          done[v] = 1;
        }
      }
      return count;
    },
    [](Index a, Index b) { return a + b; });
  // Triangle normals (area-weighted) for the rest.
  const Index nt = mesh.NumberOfTriangles();
  bool any = false;
  for (Index v = 0; v < nv && !any; ++v)
  {
    any = !done[v];
  }
  if (!any)
  {
    return projected;
  }
  std::vector<double> sum(static_cast<size_t>(3 * nv), 0.0);
  for (Index t = 0; t < nt; ++t)
  {
    const Index* id = &mesh.Triangles[3 * t];
    const double* a = &mesh.Points[3 * id[0]];
    const double* b = &mesh.Points[3 * id[1]];
    const double* c = &mesh.Points[3 * id[2]];
    const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
    const double w[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
    const double cross[3] = { u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0] };
    for (int k = 0; k < 3; ++k)
    {
      for (int q = 0; q < 3; ++q)
      {
        sum[3 * id[k] + q] += cross[q];
      }
    }
  }
  for (Index v = 0; v < nv; ++v)
  {
    if (done[v])
    {
      continue;
    }
    const double* s = &sum[3 * v];
    const double len = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int a = 0; a < 3; ++a)
    {
      mesh.Normals[3 * v + a] = len > 0.0 ? s[a] / len : (a == 2 ? 1.0 : 0.0);
    }
  }
  return projected;
}
} // namespace

bool ReconstructSurface(const SurfaceInput& input, const SurfaceOptions& options, SurfaceMesh& mesh,
  SurfaceReport& report, std::string& error, const ProgressCallback& progress)
{
  mesh = SurfaceMesh();
  report = SurfaceReport();
  error.clear();
  report.InputPoints = input.Count;
  if (options.NeighborCount < 3 || options.NeighborCount > 10000)
  {
    error = "NeighborCount must be between 3 and 10000.";
    return false;
  }
  if (!(options.SupportRadius >= 0.0) || !std::isfinite(options.SupportRadius) || !(options.CellSize >= 0.0) ||
    !std::isfinite(options.CellSize))
  {
    error = "SupportRadius and CellSize must be finite and >= 0.";
    return false;
  }
  if (!(options.SupportScale >= 1.0) || !(options.SupportScale <= 100.0))
  {
    error = "SupportScale must be between 1 and 100.";
    return false;
  }
  if (options.Method == SurfaceMethod::SPH && (!(options.Level > 0.0) || !(options.Level < 1.0)))
  {
    error = "The SPH surface level must lie strictly between 0 and 1 (the colour field's range).";
    return false;
  }
  if (input.Count < 0 || (input.Count > 0 && !input.Points))
  {
    error = "No point coordinates given.";
    return false;
  }

  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); };
  auto start = Clock::now();
  const Distribution* processes = options.Processes;
  NeighborGrid grid;
  if (options.Framed)
  {
    grid.SetFrame(options.FrameBounds, options.FramePoints);
  }
  // The default layout (each cell's points by position): every loop over the sorted points, the seeds, the fits'
  // neighbour lists and sums follow the positions, not the input order (issue 24).
  grid.Build(input.Points, input.Count);
  report.InvalidPoints = grid.NumberOfInvalidPoints();
  if (processes)
  {
    report.InvalidPoints = 0;
    for (Index i = 0; i < input.Count; ++i)
    {
      const double* p = input.Points + 3 * i;
      report.InvalidPoints += processes->Owned(i) && !(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]));
    }
  }
  if (GlobalSum(processes, grid.NumberOfValidPoints()) == 0)
  {
    return true;
  }
  // Point-set surfaces work on the distinct points (UniqueCloud.h); particles keep their duplicates' mass.
  // Distributed, every process does so when one has duplicates (the same frame, the same distinct cloud).
  UniqueCloud unique;
  SurfaceInput distinct = input;
  std::unique_ptr<DistinctDistribution> distinctProcesses;
  const Distribution* d = processes;
  if (options.Method != SurfaceMethod::SPH)
  {
    if (MergeDuplicates(grid, input.Points, input.Normals, input.Count, processes, unique, distinctProcesses,
          report.Duplicates))
    {
      d = distinctProcesses ? distinctProcesses.get() : processes;
      distinct.Points = unique.Points.data();
      distinct.Count = static_cast<Index>(unique.Points.size() / 3);
      distinct.Normals = input.Normals ? unique.Normals.data() : nullptr;
      // The same frame as the input's (serial too: the grid's cells do not depend on how many were duplicates).
      double frame[6];
      Index framePoints = 0;
      grid.GetFrame(frame, framePoints);
      grid.SetFrame(frame, framePoints);
      grid.Build(distinct.Points, distinct.Count);
    }
  }

  grid.ReleaseBuildScratch(); // built for good

  std::unique_ptr<ImplicitField> field; // the surface contoured
  std::unique_ptr<ImplicitField> fit;   // MLS/WLS with holes filled: the fits the field continues
  NormalField normals;
  std::vector<double> areas;
  std::vector<double> support;
  std::vector<std::uint64_t> seeds;
  ContourOptions lattice;
  lattice.MaximumRounds = options.MaximumRounds;
  double cell = options.CellSize;
  double margin = 0.0;
  if (options.Method == SurfaceMethod::SPH)
  {
    auto fluid = std::make_unique<FluidSurface>();
    FluidSurfaceOptions fo;
    fo.SupportRadius = options.SupportRadius;
    fo.Level = options.Level;
    fo.Anisotropic = options.Anisotropic;
    fluid->SetParticles(grid, input.Volumes, fo, processes);
    report.Shortfall = std::max(report.Shortfall, fluid->Shortfall());
    report.SupportRadius = fluid->SupportRadius();
    report.ParticleVolume = fluid->TotalVolume();
    if (!(cell > 0.0))
    {
      cell = 0.5 * fluid->Spacing();
    }
    margin = 2.0 * fluid->SupportRadius();
    ChooseLattice(grid, cell, margin, lattice, report.CellSizeEnlarged);
    // Every particle may seed, but one deep in the fluid (colour above 0.9 or below 0.1: |level - c| >= 0.4,
    // a flat field where projection has no direction) is passed over.
    const std::vector<unsigned char> near(static_cast<size_t>(input.Count), 1);
    seeds = SeedCells(grid, *fluid, lattice, 2.0 * fluid->SupportRadius(), near, 0.4, processes);
    if (GlobalSum(processes, static_cast<Index>(seeds.size())) == 0)
    {
      // A lone droplet: no bulk.
      seeds = SeedCells(grid, *fluid, lattice, 2.0 * fluid->SupportRadius(), near,
        std::numeric_limits<double>::infinity(), processes);
    }
    field = std::move(fluid);
    if (progress && !progress(0.2))
    {
      report.Aborted = true;
      return false;
    }
  }
  else
  {
    // Neighbourhoods (and normals, unless given).
    NormalOptions no;
    no.NeighborCount = options.NeighborCount;
    no.SupportRadius = options.SupportRadius;
    no.WideNormals = false; // the fits' own radius: wide jets take in both sides of thin parts
    no.Processes = d;
    if (!EstimateNormals(grid, no, normals, Stage(progress, 0.0, 0.15)) && progress && !progress(0.15))
    {
      report.Aborted = true;
      return false;
    }
    report.Scale = normals.Scale;
    report.Shortfall = std::max(report.Shortfall, normals.Shortfall);
    if (distinct.Normals)
    {
      report.PointsWithoutNormal = TakeNormals(distinct, normals);
    }
    // The fits' supports read the radii, the outlier flags and r_k, none of which the orientation changes: taken
    // first, so that the radii and the normals' statistics (24 bytes per point) go before the orientation, where
    // the serial run's peak falls and, at 10M points on 4 ranks, a rank's (issue 24).
    support = FitSupports(
      normals, options.SupportScale, options.NoiseScale, options.SupportRadius > 0.0, report.SupportRadius, d);
    std::vector<double>().swap(normals.Radii);
    std::vector<double>().swap(normals.SurfaceVariation);
    std::vector<double>().swap(normals.Residual);
    if (!distinct.Normals)
    {
      report.NormalsEstimated = true;
      std::vector<double> confidence;
      OrientationOptions orientation;
      orientation.Processes = d;
      report.Orientation = OrientNormals(grid, normals, orientation, confidence);
      report.Shortfall = std::max(report.Shortfall, report.Orientation.Shortfall);
      report.PointsWithoutNormal = normals.InvalidCount - (d ? 0 : grid.NumberOfInvalidPoints());
    }
    // What the fits, the hole filling, the contour and the trimming no longer read goes now: the orientation's graph.
    detail::Buffer<std::int32_t>().swap(normals.Graph);
    if (!(cell > 0.0))
    {
      // 1.5 sample spacings (about 0.7 vertices per sample), or a quarter of the fits' support (finer detail
      // than that the fits cannot represent); the projection makes accuracy independent of it.
      cell = std::max(1.5 * normals.Scale.Spacing, 0.25 * report.SupportRadius);
    }
    if (!(cell > 0.0))
    {
      return true; // every normal is invalid (collinear or coincident points): no surface
    }
    margin = 2.0 * report.SupportRadius;
    ChooseLattice(grid, cell, margin, lattice, report.CellSizeEnlarged);
    if (options.Method == SurfaceMethod::MLS)
    {
      auto apss = std::make_unique<PointSetSurface>();
      apss->SetCloud(grid, normals.Normals.data(), support.data(), d);
      field = std::move(apss);
    }
    else
    {
      auto patches = std::make_unique<PatchSurface>();
      patches->SetCloud(grid, normals.Normals.data(), support.data(), d);
      field = std::move(patches);
    }
    // How closed the cloud is, from the samples the fits use, and the continuation of the fits across the
    // regions without samples (HoleFilling.h; the winding number's tree is built when first needed).
    const auto fillStart = Clock::now();
    areas = SampleAreas(normals.NeighborDistance, options.NeighborCount);
    for (size_t i = 0; i < areas.size(); ++i)
    {
      areas[i] = support[i] > 0.0 && !normals.Outlier[i] ? areas[i] : 0.0;
    }
    report.OpenShare = OpenShare(grid, areas, normals.Normals, d);
    report.HolesFilled = options.HoleFilling == HoleFillingMode::On ||
      (options.HoleFilling == HoleFillingMode::Auto && report.OpenShare < options.ClosedBelow);
    if (report.HolesFilled)
    {
      auto filled = std::make_unique<FilledField>();
      filled->Set(*field, grid, support.data(), distinct.Points, normals.Normals.data(), areas.data(), distinct.Count, d);
      fit = std::move(field);
      field = std::move(filled);
    }
    report.FillSeconds = seconds(fillStart);
    if (!report.HolesFilled || d)
    {
      // The fits keep their own copy of the normals (PointSetSurface) or none (PatchSurface), and the winding
      // number's tree its own, built by now when distributed (serially on first use, when it still reads these).
      std::vector<double>().swap(normals.Normals);
      std::vector<double>().swap(areas);
    }
    std::vector<unsigned char> seeding(normals.Valid);
    for (size_t i = 0; i < seeding.size(); ++i)
    {
      seeding[i] = seeding[i] && !normals.Outlier[i] && support[i] > 0.0;
    }
    report.Outliers = normals.OutlierCount;
    seeds = SeedCells(grid, *field, lattice, report.SupportRadius, seeding, std::numeric_limits<double>::infinity(), d);
    if (progress && !progress(0.2))
    {
      report.Aborted = true;
      return false;
    }
  }
  report.CellSize = lattice.CellSize;
  report.SetupSeconds = seconds(start);
  start = Clock::now();
  if (!SparseContour().Run(*field, std::move(seeds), lattice, mesh, report.Contour, Stage(progress, 0.2, 0.85), d))
  {
    report.Aborted = report.Contour.Aborted;
    mesh = SurfaceMesh();
    if (!report.Aborted)
    {
      error = "The contouring lattice could not be set up.";
    }
    return false;
  }
  report.ContourSeconds = seconds(start);
  if (d)
  {
    // A vertex's field reads up to a cell away (the contour's corners), and the projection moves it by at most a
    // cell. MLS: the samples within the largest support of the whole cloud (at most 3 x the median); WLS: the
    // patches within the median support rho, whose centres and fits read the points within rho of them; the
    // fluid's kernels (H, stretched up to 4^(2/3) and shifted) read their particles' neighbours within two
    // spacings (H).
    double read = 3.0 * report.SupportRadius;
    if (options.Method == SurfaceMethod::MLS)
    {
      double largest = 0.0;
      for (size_t i = 0; i < support.size(); ++i)
      {
        largest = IsOwn(d, static_cast<Index>(i)) ? std::max(largest, support[i]) : largest;
      }
      read = GlobalMax(d, largest);
    }
    else if (options.Method == SurfaceMethod::WLS)
    {
      read = 2.0 * report.SupportRadius;
    }
    else if (options.Anisotropic)
    {
      read = 4.5 * report.SupportRadius;
    }
    const double reach = read + 2.0 * lattice.CellSize;
    for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
    {
      report.Shortfall = std::max(report.Shortfall, Shortfall(d, &mesh.Points[3 * v], reach));
    }
    if (report.HolesFilled)
    {
      // (Only known after every evaluation of the contouring and the projection: checked again below.)
      report.Shortfall = std::max(report.Shortfall, static_cast<const FilledField&>(*field).Shortfall());
    }
  }
  start = Clock::now();
  report.ProjectedVertices = ProjectVertices(*field, lattice.CellSize, options.ProjectVertices, mesh);
  // The field's last evaluation: its shortfall is final, and the fits and the winding number's tree go before the
  // distances and the pieces (the memory they take would add to theirs).
  if (d && report.HolesFilled)
  {
    report.Shortfall = std::max(report.Shortfall, static_cast<const FilledField&>(*field).Shortfall());
  }
  field.reset();
  fit.reset();
  std::vector<double>().swap(support);
  std::vector<double>().swap(areas);
  std::vector<Index> nearest;
  DistanceToData(grid, mesh.Points, mesh.DistanceToData, nearest, d);
  if (options.Method != SurfaceMethod::SPH)
  {
    // How far from a sample the surface still counts as on the data: TrimSpacings local spacings (from the
    // sample's r_k) and the noise's spread.
    const double k = static_cast<double>(options.NeighborCount);
    const double noise = 3.0 * report.Scale.Noise;
    std::vector<double> limit(normals.NeighborDistance.size(), 0.0), nearLimit(limit.size(), 0.0);
    for (size_t i = 0; i < limit.size(); ++i)
    {
      const double rk = normals.NeighborDistance[i];
      const double spacing = rk > 0.0 && std::isfinite(rk) ? rk * std::sqrt(M_PI / k) : report.Scale.Spacing;
      const double reach = options.TrimSpacings * spacing;
      limit[i] = std::sqrt(reach * reach + noise * noise);
      nearLimit[i] = std::sqrt(spacing * spacing + noise * noise);
    }
    const std::vector<VertexAttribute> attributes = { { &mesh.Normals, 3 }, { &mesh.DistanceToData, 1 } };
    if (!report.HolesFilled && options.TrimSpacings > 0.0)
    {
      // On the data: within one local spacing (and the noise) of a sample, or within the limit and surrounded
      // by samples (DataSupport.h).
      std::vector<double> vertexLimit(nearest.size(), 0.0), vertexNear(nearest.size(), 0.0);
      for (size_t v = 0; v < nearest.size(); ++v)
      {
        vertexLimit[v] = nearest[v] >= 0 ? limit[nearest[v]] : 0.0;
        vertexNear[v] = nearest[v] >= 0 ? nearLimit[nearest[v]] : 0.0;
      }
      report.TrimmedTriangles = KeepTriangles(
        mesh, TrimmedTriangles(mesh, mesh.Normals, grid, mesh.DistanceToData, vertexNear, vertexLimit, d,
          2.0 * report.CellSize), attributes);
    }
    // (Distributed: every process alike, a part without triangles too - the pieces are the whole mesh's.)
    if (options.RemoveStrayPieces && GlobalSum(d, mesh.NumberOfTriangles()) > 0)
    {
      const Index before = mesh.NumberOfTriangles();
      const std::vector<unsigned char> keep = SupportedPieces(mesh, grid, limit,
        std::min<Index>(options.NeighborCount, GlobalSum(d, static_cast<Index>(distinct.Count))), report.Pieces,
        report.RemovedPieces, d);
      KeepTriangles(mesh, keep, attributes);
      report.RemovedTriangles = before - mesh.NumberOfTriangles();
    }
  }
  report.ProjectionSeconds = seconds(start);
  if (progress && !progress(1.0))
  {
    report.Aborted = true;
    mesh = SurfaceMesh();
    return false;
  }
  return true;
}

} // namespace meshfree
