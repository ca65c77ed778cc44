// Throughput of MeshFree's point-cloud readers (points per second), against peers measured in the same run:
// - "fread only": reading the file's bytes into memory (the ceiling any reader of that file has);
// - "istream >>": parsing the same ascii data with iostreams (the usual naive text reader).
// The cloud is PCL's PointXYZRGB plus an intensity (x y z rgb intensity, 20 bytes a point), generated with a
// fixed seed. Usage: BenchReaders [points=2000000] [folder=/tmp]; best of 5 runs each (the machine is shared: the best run is the one least disturbed).
#include "PCDFormat.h"
#include "vtkMeshFreePCDReader.h"
#include "vtkMeshFreeXYZReader.h"

#include "vtkNew.h"
#include "vtkPolyData.h"

#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace
{
// Best of `repeats` runs, wall-clock seconds; cpu receives the process CPU seconds (all threads) of that
// run, which tells how much of the wall time a busy, shared machine took away. Later runs reuse the heap
// pages of earlier ones (glibc raises its mmap threshold), so the first run, which pays the page faults of
// fresh memory, is printed too.
double FirstRun = 0;
double BestSeconds(const std::function<void()>& run, double* cpu = nullptr, int repeats = 5)
{
  double best = 1e300;
  for (int r = 0; r < repeats; ++r)
  {
    const std::clock_t c0 = std::clock();
    const auto t0 = std::chrono::steady_clock::now();
    run();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (r == 0)
      FirstRun = s;
    if (s < best)
    {
      best = s;
      if (cpu)
        *cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
    }
  }
  return best;
}

void Report(const char* what, std::uint64_t n, double seconds, double peer = 0, double cpu = 0)
{
  std::printf("%-44s %8.3f s %9.2f M points/s", what, seconds, n / seconds / 1e6);
  std::printf("  [first run %.3f s: %.2f M/s]", FirstRun, n / FirstRun / 1e6);
  if (cpu > 0)
    std::printf("  [cpu %.3f s]", cpu);
  if (peer > 0)
    std::printf("   (%.2fx the peer)", peer / seconds);
  std::printf("\n");
}
} // namespace

int main(int argc, char* argv[])
{
  namespace pcd = meshfree::pcd;
  const std::uint64_t n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 2000000;
  const std::string folder = argc > 2 ? argv[2] : "/tmp";

  std::mt19937 rng(42);
  std::uniform_real_distribution<float> uni(-10.f, 10.f);
  std::vector<float> x(n), y(n), z(n), intensity(n), rgb(n);
  for (std::uint64_t i = 0; i < n; ++i)
  {
    x[i] = uni(rng), y[i] = uni(rng), z[i] = uni(rng), intensity[i] = uni(rng) + 10.f;
    const std::uint32_t bits = rng() & 0x00FFFFFFu;
    std::memcpy(&rgb[i], &bits, 4);
  }
  pcd::Header h;
  h.Width = h.Points = n;
  for (const char* name : { "x", "y", "z", "rgb", "intensity" })
  {
    pcd::Field f;
    f.Name = name;
    h.Fields.push_back(f);
  }
  const std::vector<const void*> columns = { x.data(), y.data(), z.data(), rgb.data(), intensity.data() };

  std::printf("BenchReaders: %llu points (x y z rgb intensity, float32)\n", static_cast<unsigned long long>(n));
  for (pcd::Encoding e : { pcd::Encoding::Binary, pcd::Encoding::BinaryCompressed, pcd::Encoding::Ascii })
  {
    h.Data = e;
    const std::string path = folder + "/bench_readers_" + pcd::EncodingName(e) + ".pcd";
    std::string error;
    if (!pcd::WriteFile(path, h, columns, error))
    {
      std::fprintf(stderr, "%s\n", error.c_str());
      return 1;
    }
    std::printf("\n.pcd DATA %s\n", pcd::EncodingName(e));
    const double fread = BestSeconds([&] {
      pcd::Buffer b;
      pcd::LoadFile(path, b, error);
    });
    Report("peer: fread only", n, fread);
    double cpuCore = 0, cpuVtk = 0;
    const double core = BestSeconds(
      [&] {
        pcd::Cloud c;
        if (!pcd::ReadFile(path, c, error))
          std::abort();
      },
      &cpuCore);
    Report("core: pcd::ReadFile", n, core, 0, cpuCore);
    const double vtk = BestSeconds([&] {
      vtkNew<vtkMeshFreePCDReader> r;
      r->SetFileName(path.c_str());
      r->Update();
      if (r->GetOutput()->GetNumberOfPoints() != static_cast<vtkIdType>(n))
        std::abort();
    }, &cpuVtk);
    const double vtkFirst = FirstRun;
    if (e == pcd::Encoding::Ascii)
    {
      // The naive peer: iostreams over the same data section.
      std::ifstream in(path);
      std::stringstream all;
      all << in.rdbuf();
      const std::string text = all.str();
      const std::size_t start = text.find("DATA ascii\n") + 11;
      const double naive = BestSeconds([&] {
        std::istringstream s(text.substr(start));
        std::vector<float> v(5 * n);
        for (std::uint64_t i = 0; i < 5 * n; ++i)
          s >> v[i];
      });
      Report("peer: istream >> float", n, naive);
      FirstRun = vtkFirst;
      Report("vtkMeshFreePCDReader (polydata + vertices)", n, vtk, naive, cpuVtk);
    }
    else
      Report("vtkMeshFreePCDReader (polydata + vertices)", n, vtk, 0, cpuVtk);
    std::remove(path.c_str());
  }

  // Text cloud: the same points as "x y z intensity" lines.
  {
    const std::string path = folder + "/bench_readers.xyz";
    {
      std::string text;
      text.reserve(n * 40);
      char line[128];
      for (std::uint64_t i = 0; i < n; ++i)
        text.append(line, std::snprintf(line, sizeof(line), "%.6g %.6g %.6g %.6g\n", x[i], y[i], z[i], intensity[i]));
      std::ofstream(path, std::ios::binary) << text;
    }
    std::printf("\n.xyz text (x y z intensity)\n");
    Report("vtkMeshFreeXYZReader (polydata + vertices)", n, BestSeconds([&] {
      vtkNew<vtkMeshFreeXYZReader> r;
      r->SetFileName(path.c_str());
      r->Update();
      if (r->GetOutput()->GetNumberOfPoints() != static_cast<vtkIdType>(n))
        std::abort();
    }));
    std::remove(path.c_str());
  }
  return 0;
}
