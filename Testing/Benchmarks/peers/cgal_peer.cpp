// CGAL 5.5 as a peer of the scan benchmark (Testing/Benchmarks/bench_scans.py, issue 23). Built by
// ../setup_peers.sh with this folder's CMakeLists.txt (Debian libcgal-dev), not by the project's CMake.
//
//   cgal_peer normals IN.xyz OUT.xyz --k K [--method jet|pca] [--orient]
//       normals only: jet (degree-2 jet fit, CGAL::jet_estimate_normals) or PCA (CGAL::pca_estimate_normals)
//       over the K nearest neighbours; --orient: then CGAL::mst_orient_normals (same K); points it cannot
//       orient keep their unoriented normal. OUT: "x y z nx ny nz" per line, in IN's order.
//   cgal_peer poisson IN.xyz OUT.off [--k K]
//       positions only -> jet normals (K, default 18), MST orientation (K), CGAL Poisson surface
//       reconstruction (poisson_surface_reconstruction_delaunay: spacing = average spacing over 6 neighbours,
//       CGAL's default mesh criteria: angle 20 degrees, radius 30 and distance 0.375 spacings)
//   cgal_peer afront IN.xyz OUT.off
//       positions only -> advancing front surface reconstruction (CGAL's default parameters)
// IN: text, the first three numbers of each line are x y z. Prints one JSON line: the seconds of each step
// (file reading and writing excluded) and the output's size. Uses TBB where CGAL has it (Parallel_if_available).
#include <CGAL/Advancing_front_surface_reconstruction.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/compute_average_spacing.h>
#include <CGAL/jet_estimate_normals.h>
#include <CGAL/mst_orient_normals.h>
#include <CGAL/pca_estimate_normals.h>
#include <CGAL/poisson_surface_reconstruction.h>
#include <CGAL/property_map.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Vector = Kernel::Vector_3;
using PointNormal = std::pair<Point, Vector>;
using Mesh = CGAL::Surface_mesh<Point>;
using Concurrency = CGAL::Parallel_if_available_tag;

namespace
{
double Seconds(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

bool ReadXYZ(const char* path, std::vector<PointNormal>& points)
{
  std::ifstream in(path);
  if (!in)
  {
    return false;
  }
  std::string line;
  while (std::getline(in, line))
  {
    std::istringstream s(line);
    double x, y, z;
    if (s >> x >> y >> z)
    {
      points.emplace_back(Point(x, y, z), Vector(0, 0, 0));
    }
  }
  return !points.empty();
}

bool WriteOFF(const char* path, const std::vector<Point>& vertices, const std::vector<std::array<std::size_t, 3>>& faces)
{
  std::FILE* f = std::fopen(path, "w");
  if (!f)
  {
    return false;
  }
  std::fprintf(f, "OFF\n%zu %zu 0\n", vertices.size(), faces.size());
  for (const Point& p : vertices)
  {
    std::fprintf(f, "%.9g %.9g %.9g\n", p.x(), p.y(), p.z());
  }
  for (const auto& t : faces)
  {
    std::fprintf(f, "3 %zu %zu %zu\n", t[0], t[1], t[2]);
  }
  return std::fclose(f) == 0;
}

void EstimateNormals(std::vector<PointNormal>& points, int k, bool jet)
{
  auto params = CGAL::parameters::point_map(CGAL::First_of_pair_property_map<PointNormal>())
                  .normal_map(CGAL::Second_of_pair_property_map<PointNormal>());
  if (jet)
  {
    CGAL::jet_estimate_normals<Concurrency>(points, k, params);
  }
  else
  {
    CGAL::pca_estimate_normals<Concurrency>(points, k, params);
  }
}

// Orients in place, keeping IN's order (mst_orient_normals reorders the range: work on a copy with indices).
std::size_t OrientNormals(std::vector<PointNormal>& points, int k)
{
  using Item = std::tuple<Point, Vector, std::size_t>;
  std::vector<Item> work(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    work[i] = Item(points[i].first, points[i].second, i);
  }
  auto unoriented = CGAL::mst_orient_normals(work, k,
    CGAL::parameters::point_map(CGAL::Nth_of_tuple_property_map<0, Item>())
      .normal_map(CGAL::Nth_of_tuple_property_map<1, Item>()));
  for (const auto& item : work)
  {
    points[std::get<2>(item)] = PointNormal(std::get<0>(item), std::get<1>(item));
  }
  return static_cast<std::size_t>(std::distance(unoriented, work.end()));
}

int Usage()
{
  std::cerr << "usage: cgal_peer normals IN.xyz OUT.xyz --k K [--method jet|pca] [--orient]\n"
               "       cgal_peer poisson IN.xyz OUT.off [--k K]\n"
               "       cgal_peer afront IN.xyz OUT.off\n";
  return 1;
}
} // namespace

int main(int argc, char** argv)
{
  if (argc < 4)
  {
    return Usage();
  }
  const std::string mode = argv[1];
  int k = 18;
  bool jet = true, orient = false;
  for (int i = 4; i < argc; ++i)
  {
    if (!std::strcmp(argv[i], "--k") && i + 1 < argc)
    {
      k = std::atoi(argv[++i]);
    }
    else if (!std::strcmp(argv[i], "--method") && i + 1 < argc)
    {
      jet = std::strcmp(argv[++i], "pca") != 0;
    }
    else if (!std::strcmp(argv[i], "--orient"))
    {
      orient = true;
    }
    else
    {
      return Usage();
    }
  }
  if (k < 3)
  {
    std::cerr << "cgal_peer: --k must be at least 3\n";
    return 1;
  }
  std::vector<PointNormal> points;
  if (!ReadXYZ(argv[2], points))
  {
    std::cerr << "cgal_peer: cannot read points from " << argv[2] << "\n";
    return 2;
  }
  std::ostringstream json;
  json << "{\"points\": " << points.size();
  auto t0 = std::chrono::steady_clock::now();
  if (mode == "normals")
  {
    EstimateNormals(points, k, jet);
    json << ", \"normals_s\": " << Seconds(t0);
    if (orient)
    {
      t0 = std::chrono::steady_clock::now();
      const std::size_t left = OrientNormals(points, k);
      json << ", \"orient_s\": " << Seconds(t0) << ", \"unoriented\": " << left;
    }
    std::FILE* f = std::fopen(argv[3], "w");
    if (!f)
    {
      return 2;
    }
    for (const auto& pn : points)
    {
      std::fprintf(f, "%.9g %.9g %.9g %.7g %.7g %.7g\n", pn.first.x(), pn.first.y(), pn.first.z(), pn.second.x(),
        pn.second.y(), pn.second.z());
    }
    std::fclose(f);
  }
  else if (mode == "poisson")
  {
    EstimateNormals(points, k, true);
    json << ", \"normals_s\": " << Seconds(t0);
    t0 = std::chrono::steady_clock::now();
    const std::size_t left = OrientNormals(points, k);
    json << ", \"orient_s\": " << Seconds(t0) << ", \"unoriented\": " << left;
    t0 = std::chrono::steady_clock::now();
    const double spacing = CGAL::compute_average_spacing<Concurrency>(
      points, 6, CGAL::parameters::point_map(CGAL::First_of_pair_property_map<PointNormal>()));
    Mesh mesh;
    const bool ok = CGAL::poisson_surface_reconstruction_delaunay(points.begin(), points.end(),
      CGAL::First_of_pair_property_map<PointNormal>(), CGAL::Second_of_pair_property_map<PointNormal>(), mesh,
      spacing);
    json << ", \"poisson_s\": " << Seconds(t0) << ", \"ok\": " << (ok ? "true" : "false");
    std::vector<Point> vertices;
    std::vector<std::size_t> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices());
    for (auto v : mesh.vertices())
    {
      index[v] = vertices.size();
      vertices.push_back(mesh.point(v));
    }
    std::vector<std::array<std::size_t, 3>> faces;
    for (auto f : mesh.faces())
    {
      std::array<std::size_t, 3> t{};
      int j = 0;
      for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
      {
        if (j < 3)
        {
          t[j] = index[v];
        }
        ++j;
      }
      if (j == 3)
      {
        faces.push_back(t);
      }
    }
    json << ", \"triangles\": " << faces.size();
    if (!WriteOFF(argv[3], vertices, faces))
    {
      return 2;
    }
  }
  else if (mode == "afront")
  {
    std::vector<Point> vertices;
    vertices.reserve(points.size());
    for (const auto& pn : points)
    {
      vertices.push_back(pn.first);
    }
    std::vector<std::array<std::size_t, 3>> faces;
    CGAL::advancing_front_surface_reconstruction(vertices.begin(), vertices.end(), std::back_inserter(faces));
    json << ", \"afront_s\": " << Seconds(t0) << ", \"triangles\": " << faces.size();
    if (!WriteOFF(argv[3], vertices, faces))
    {
      return 2;
    }
  }
  else
  {
    return Usage();
  }
  json << "}";
  std::cout << json.str() << std::endl;
  return 0;
}
