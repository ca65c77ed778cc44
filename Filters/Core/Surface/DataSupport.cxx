// SPDX-License-Identifier: BSD-3-Clause
// Distance to the data, trimming and supported pieces of a reconstructed surface (DataSupport.h).
#include "Surface/DataSupport.h"

#include "Common/Parallel.h"
#include "Surface/MeshTopology.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace meshfree
{

void DistanceToData(const NeighborGrid& grid, const std::vector<double>& vertices, std::vector<double>& distance,
  std::vector<Index>& nearest)
{
  const Index nv = static_cast<Index>(vertices.size() / 3);
  distance.assign(static_cast<size_t>(nv), std::numeric_limits<double>::infinity());
  nearest.assign(static_cast<size_t>(nv), -1);
  if (grid.NumberOfValidPoints() == 0)
  {
    return;
  }
  ParallelFor(nv, 1024, [&](Index begin, Index end) {
    for (Index v = begin; v < end; ++v)
    {
      Index id = -1;
      double d2 = 0.0;
      if (grid.FindKNearest(&vertices[3 * v], 1, &id, &d2) == 1)
      {
        distance[v] = std::sqrt(d2);
        nearest[v] = id;
      }
    }
  });
}

Index KeepTriangles(TriangleMesh& mesh, const std::vector<unsigned char>& keep, const std::vector<VertexAttribute>& attributes)
{
  const Index nt = mesh.NumberOfTriangles();
  const Index nv = mesh.NumberOfPoints();
  std::vector<Index> index(static_cast<size_t>(nv), -1);
  Index kept = 0;
  for (Index t = 0; t < nt; ++t)
  {
    if (!keep[t])
    {
      continue;
    }
    for (int c = 0; c < 3; ++c)
    {
      mesh.Triangles[3 * kept + c] = mesh.Triangles[3 * t + c];
      index[mesh.Triangles[3 * t + c]] = 0;
    }
    ++kept;
  }
  if (kept == nt)
  {
    return 0;
  }
  mesh.Triangles.resize(static_cast<size_t>(3 * kept));
  Index used = 0;
  for (Index v = 0; v < nv; ++v)
  {
    if (index[v] < 0)
    {
      continue;
    }
    index[v] = used;
    std::copy_n(&mesh.Points[3 * v], 3, &mesh.Points[3 * used]);
    for (const VertexAttribute& a : attributes)
    {
      std::copy_n(&(*a.Values)[static_cast<size_t>(a.Components) * v], a.Components,
        &(*a.Values)[static_cast<size_t>(a.Components) * used]);
    }
    ++used;
  }
  mesh.Points.resize(static_cast<size_t>(3 * used));
  for (const VertexAttribute& a : attributes)
  {
    a.Values->resize(static_cast<size_t>(a.Components) * used);
  }
  for (Index& id : mesh.Triangles)
  {
    id = index[id];
  }
  return nt - kept;
}

std::vector<unsigned char> TrimmedTriangles(const TriangleMesh& mesh, const std::vector<double>& normals,
  const NeighborGrid& grid, const std::vector<double>& distance, const std::vector<double>& near,
  const std::vector<double>& limit)
{
  const Index nv = mesh.NumberOfPoints();
  std::vector<unsigned char> on(static_cast<size_t>(nv), 0);
  struct Buffers
  {
    std::vector<Index> Positions;
    std::vector<double> Dist2;
  };
  PerThread<Buffers> buffers;
  const double* sorted = grid.SortedPoints();
  ParallelFor(nv, 256, [&](Index begin, Index end) {
    Buffers& b = buffers.Local();
    for (Index v = begin; v < end; ++v)
    {
      if (distance[v] <= near[v])
      {
        on[v] = 1;
        continue;
      }
      if (!(distance[v] <= limit[v]))
      {
        continue;
      }
      const double* x = &mesh.Points[3 * v];
      const double* n = &normals[3 * v];
      grid.FindWithinRadiusPositions(x, 1.5 * limit[v], b.Positions, b.Dist2);
      double mean[3] = { 0.0, 0.0, 0.0 };
      Index count = 0;
      for (size_t j = 0; j < b.Positions.size(); ++j)
      {
        const double* p = sorted + 3 * b.Positions[j];
        double d[3] = { p[0] - x[0], p[1] - x[1], p[2] - x[2] };
        const double along = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
        for (int a = 0; a < 3; ++a)
        {
          d[a] -= along * n[a];
        }
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (len > 0.0)
        {
          for (int a = 0; a < 3; ++a)
          {
            mean[a] += d[a] / len;
          }
          ++count;
        }
      }
      const double spread = count > 0 ? std::sqrt(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]) / count : 1.0;
      on[v] = spread < OneSided ? 1 : 0;
    }
  });
  const Index nt = mesh.NumberOfTriangles();
  std::vector<unsigned char> keep(static_cast<size_t>(nt), 1);
  for (Index t = 0; t < nt; ++t)
  {
    keep[t] = on[mesh.Triangles[3 * t]] && on[mesh.Triangles[3 * t + 1]] && on[mesh.Triangles[3 * t + 2]];
  }
  return keep;
}

std::vector<unsigned char> SupportedPieces(const TriangleMesh& mesh, const NeighborGrid& grid,
  const std::vector<double>& sampleLimit, Index minimumSamples, Index& pieces, Index& removedPieces)
{
  const Index nt = mesh.NumberOfTriangles();
  const Index nv = mesh.NumberOfPoints();
  std::vector<Index> component;
  pieces = TriangleComponents(mesh.Triangles, nv, component);
  removedPieces = 0;
  std::vector<unsigned char> keep(static_cast<size_t>(nt), 1);
  if (pieces <= 1 || nv == 0)
  {
    return keep; // one piece is always kept (the best-supported one)
  }
  std::vector<Index> vertexPiece(static_cast<size_t>(nv), -1);
  for (Index t = 0; t < nt; ++t)
  {
    for (int c = 0; c < 3; ++c)
    {
      vertexPiece[mesh.Triangles[3 * t + c]] = component[t];
    }
  }
  // Each sample's nearest vertex, through a grid over the vertices.
  NeighborGrid vertices;
  vertices.Build(mesh.Points.data(), nv);
  const std::vector<Index>& order = grid.SortedOrder();
  const double* sorted = grid.SortedPoints();
  const Index ns = static_cast<Index>(order.size());
  std::vector<Index> owner(static_cast<size_t>(ns), -1);
  ParallelFor(ns, 1024, [&](Index begin, Index end) {
    for (Index s = begin; s < end; ++s)
    {
      Index id = -1;
      double d2 = 0.0;
      const double limit = sampleLimit[order[s]];
      if (vertices.FindKNearest(sorted + 3 * s, 1, &id, &d2) == 1 && d2 <= limit * limit)
      {
        owner[s] = vertexPiece[id];
      }
    }
  });
  std::vector<Index> support(static_cast<size_t>(pieces), 0);
  for (Index s = 0; s < ns; ++s)
  {
    if (owner[s] >= 0)
    {
      ++support[owner[s]];
    }
  }
  // The best-supported piece is always kept (a cloud of fewer samples than minimumSamples still has a surface).
  const Index best = static_cast<Index>(std::max_element(support.begin(), support.end()) - support.begin());
  std::vector<unsigned char> kept(static_cast<size_t>(pieces), 0);
  for (Index p = 0; p < pieces; ++p)
  {
    kept[p] = p == best || support[p] >= minimumSamples ? 1 : 0;
    removedPieces += kept[p] ? 0 : 1;
  }
  for (Index t = 0; t < nt; ++t)
  {
    keep[t] = kept[component[t]];
  }
  return keep;
}

} // namespace meshfree
