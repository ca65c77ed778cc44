// SPDX-License-Identifier: BSD-3-Clause
#include "Surface/MeshTopology.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace meshfree
{

MeshTopology ComputeMeshTopology(const std::vector<Index>& triangles, Index numberOfPoints)
{
  MeshTopology topo;
  const Index nt = static_cast<Index>(triangles.size() / 3);
  topo.Triangles = nt;
  // Each directed half-edge as (min, max, direction); sorting groups the half-edges of an edge.
  struct HalfEdge
  {
    Index A, B;
    int Forward;
    bool operator<(const HalfEdge& o) const { return A != o.A ? A < o.A : (B != o.B ? B < o.B : Forward < o.Forward); }
  };
  std::vector<HalfEdge> half;
  half.reserve(static_cast<size_t>(3 * nt));
  std::vector<char> used(static_cast<size_t>(std::max<Index>(numberOfPoints, 0)), 0);
  for (Index t = 0; t < nt; ++t)
  {
    for (int e = 0; e < 3; ++e)
    {
      const Index a = triangles[3 * t + e], b = triangles[3 * t + (e + 1) % 3];
      half.push_back(HalfEdge{ std::min(a, b), std::max(a, b), a < b ? 1 : 0 });
      if (a >= 0 && a < numberOfPoints)
      {
        used[a] = 1;
      }
    }
  }
  std::sort(half.begin(), half.end());
  for (size_t i = 0; i < half.size();)
  {
    size_t j = i + 1;
    while (j < half.size() && half[j].A == half[i].A && half[j].B == half[i].B)
    {
      ++j;
    }
    ++topo.Edges;
    const size_t count = j - i;
    if (count == 1)
    {
      ++topo.BoundaryEdges;
    }
    else if (count > 2)
    {
      ++topo.NonManifoldEdges;
    }
    else if (half[i].Forward == half[i + 1].Forward)
    {
      ++topo.InconsistentEdges;
    }
    i = j;
  }
  topo.Vertices = std::count(used.begin(), used.end(), 1);
  topo.EulerCharacteristic = topo.Vertices - topo.Edges + topo.Triangles;
  std::vector<Index> component;
  topo.Components = TriangleComponents(triangles, numberOfPoints, component);
  return topo;
}

namespace
{
Index Root(std::vector<Index>& parent, Index i)
{
  while (parent[i] != i)
  {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}
} // namespace

Index TriangleComponents(const std::vector<Index>& triangles, Index numberOfPoints, std::vector<Index>& component)
{
  const Index nt = static_cast<Index>(triangles.size() / 3);
  std::vector<Index> parent(static_cast<size_t>(std::max<Index>(numberOfPoints, 0)));
  std::iota(parent.begin(), parent.end(), Index(0));
  auto valid = [numberOfPoints](Index v) { return v >= 0 && v < numberOfPoints; };
  for (Index t = 0; t < nt; ++t)
  {
    for (int e = 1; e < 3; ++e)
    {
      const Index a = triangles[3 * t], b = triangles[3 * t + e];
      if (valid(a) && valid(b))
      {
        const Index ra = Root(parent, a), rb = Root(parent, b);
        if (ra != rb)
        {
          parent[std::max(ra, rb)] = std::min(ra, rb);
        }
      }
    }
  }
  component.assign(static_cast<size_t>(nt), -1);
  std::vector<Index> label(parent.size(), -1);
  Index count = 0;
  for (Index t = 0; t < nt; ++t)
  {
    const Index a = triangles[3 * t];
    if (!valid(a))
    {
      continue;
    }
    const Index r = Root(parent, a);
    if (label[r] < 0)
    {
      label[r] = count++;
    }
    component[t] = label[r];
  }
  return count;
}

double EnclosedVolume(const std::vector<double>& points, const std::vector<Index>& triangles)
{
  const Index nt = static_cast<Index>(triangles.size() / 3);
  const Index np = static_cast<Index>(points.size() / 3);
  if (np == 0)
  {
    return 0.0;
  }
  // Relative to the first point, so that a mesh far from the origin loses no precision.
  const double* o = points.data();
  double volume = 0.0;
  for (Index t = 0; t < nt; ++t)
  {
    const Index* ids = &triangles[3 * t];
    if (ids[0] < 0 || ids[1] < 0 || ids[2] < 0 || ids[0] >= np || ids[1] >= np || ids[2] >= np)
    {
      continue;
    }
    double p[3][3];
    for (int c = 0; c < 3; ++c)
    {
      for (int a = 0; a < 3; ++a)
      {
        p[c][a] = points[3 * ids[c] + a] - o[a];
      }
    }
    volume += p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) - p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
      p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0]);
  }
  return volume / 6.0;
}

} // namespace meshfree
