// Meshless Surface on a point cloud file, without VTK: the stage timings of ReconstructSurface (issue 23's
// profile of the scan benchmark) and the mesh for scoring.
// Usage: BenchSurfaceScan CLOUD.xyz [--method MLS|WLS] [--fill off|on|auto] [--repeat N] [--out MESH.bin]
//        [--support-scale S] [--neighbors K] [--noise-scale S] [--cell SIZE]
// CLOUD.xyz: "x y z" per line (scans_data.py's NAME.xyz). MESH.bin: int64 vertex count, int64 triangle count,
// then the vertices (3 doubles each), the triangles (3 int64 each) and DistanceToData (1 double per vertex); read
// it with numpy (scans_score.read_bin, or read_mesh). Prints one line per run: the report's stage seconds and counts.
// Threads: all the CPUs, or MESHFREE_NUM_THREADS.
#include "Common/Parallel.h"
#include "Surface/MeshTopology.h"
#include "Surface/SurfaceReconstruction.h"

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

int main(int argc, char** argv)
{
  if (argc < 2)
  {
    std::fprintf(stderr, "usage: %s CLOUD.xyz [--method MLS|WLS] [--fill off|on|auto] [--repeat N] [--out MESH.bin]\n"
                         "  [--support-scale S] [--noise-scale S] [--cell H] [--neighbors K] [--trim SPACINGS]\n",
      argv[0]);
    return 2;
  }
  meshfree::SurfaceOptions options;
  int repeat = 1;
  std::string out;
  for (int a = 2; a + 1 < argc; a += 2)
  {
    const std::string key = argv[a], value = argv[a + 1];
    if (key == "--method")
    {
      options.Method = value == "WLS" ? meshfree::SurfaceMethod::WLS : meshfree::SurfaceMethod::MLS;
    }
    else if (key == "--fill")
    {
      options.HoleFilling = value == "on" ? meshfree::HoleFillingMode::On
        : value == "off"                  ? meshfree::HoleFillingMode::Off
                                          : meshfree::HoleFillingMode::Auto;
    }
    else if (key == "--repeat")
    {
      repeat = std::atoi(value.c_str());
    }
    else if (key == "--out")
    {
      out = value;
    }
    else if (key == "--support-scale")
    {
      options.SupportScale = std::atof(value.c_str());
    }
    else if (key == "--noise-scale")
    {
      options.NoiseScale = std::atof(value.c_str());
    }
    else if (key == "--cell")
    {
      options.CellSize = std::atof(value.c_str());
    }
    else if (key == "--trim")
    {
      options.TrimSpacings = std::atof(value.c_str()); // 0: an open surface is not trimmed to its data's border
    }
    else if (key == "--neighbors")
    {
      options.NeighborCount = std::atoi(value.c_str());
    }
    else
    {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
      return 2;
    }
  }
  std::vector<double> points;
  {
    FILE* f = std::fopen(argv[1], "r");
    if (!f)
    {
      std::fprintf(stderr, "cannot read %s\n", argv[1]);
      return 1;
    }
    double p[3];
    while (std::fscanf(f, "%lf %lf %lf", &p[0], &p[1], &p[2]) == 3)
    {
      points.insert(points.end(), p, p + 3);
    }
    std::fclose(f);
  }
  meshfree::SurfaceInput input;
  input.Points = points.data();
  input.Count = static_cast<meshfree::Index>(points.size() / 3);
  std::printf("%lld points, %d threads\n", static_cast<long long>(input.Count), meshfree::MaxThreads());
  meshfree::SurfaceMesh mesh;
  for (int r = 0; r < repeat; ++r)
  {
    meshfree::SurfaceReport report;
    std::string error;
    const auto start = std::chrono::steady_clock::now();
    if (!meshfree::ReconstructSurface(input, options, mesh, report, error))
    {
      std::fprintf(stderr, "failed: %s\n", error.c_str());
      return 1;
    }
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const meshfree::MeshTopology topology = meshfree::ComputeMeshTopology(mesh.Triangles, mesh.NumberOfPoints());
    std::printf("total %.3f s: setup %.3f (fill set-up %.3f) contour %.3f project+trim %.3f | corners %lld, "
                "vertices %lld, triangles %lld, boundary edges %lld, chi %lld, open share %.3f, filled %d, pieces %lld "
                "(removed %lld), support %.3g, cell %.3g, noise %.3g, spacing %.3g\n",
      total, report.SetupSeconds, report.FillSeconds, report.ContourSeconds, report.ProjectionSeconds,
      static_cast<long long>(report.Contour.EvaluatedCorners), static_cast<long long>(mesh.NumberOfPoints()),
      static_cast<long long>(mesh.NumberOfTriangles()), static_cast<long long>(topology.BoundaryEdges), static_cast<long long>(topology.EulerCharacteristic),
      report.OpenShare, report.HolesFilled ? 1 : 0, static_cast<long long>(report.Pieces),
      static_cast<long long>(report.RemovedPieces), report.SupportRadius, report.CellSize, report.Scale.Noise,
      report.Scale.Spacing);
    std::fflush(stdout);
  }
  if (!out.empty())
  {
    FILE* f = std::fopen(out.c_str(), "wb");
    if (!f)
    {
      std::fprintf(stderr, "cannot write %s\n", out.c_str());
      return 1;
    }
    const std::int64_t counts[2] = { mesh.NumberOfPoints(), mesh.NumberOfTriangles() };
    std::fwrite(counts, sizeof(counts), 1, f);
    std::fwrite(mesh.Points.data(), sizeof(double), mesh.Points.size(), f);
    std::vector<std::int64_t> triangles(mesh.Triangles.begin(), mesh.Triangles.end());
    std::fwrite(triangles.data(), sizeof(std::int64_t), triangles.size(), f);
    std::fwrite(mesh.DistanceToData.data(), sizeof(double), mesh.DistanceToData.size(), f);
    std::fclose(f);
  }
  return 0;
}
