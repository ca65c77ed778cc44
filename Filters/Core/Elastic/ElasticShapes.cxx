// SPDX-License-Identifier: BSD-3-Clause
#include "Elastic/ElasticShapes.h"

#include "Common/Parallel.h"
#include "Elastic/ElasticSolid.h"

#include <array>
#include <cmath>
#include <map>

namespace meshfree
{
namespace
{
constexpr double Pi = 3.141592653589793238462643383279502884;

void CentreAndHalfWidths(const double b[6], double c[3], double r[3])
{
  for (int a = 0; a < 3; ++a)
  {
    c[a] = 0.5 * (b[2 * a] + b[2 * a + 1]);
    r[a] = std::max(0.0, 0.5 * (b[2 * a + 1] - b[2 * a]));
  }
}

// Builds an indexed mesh from triangles given by integer-keyed vertices (shared keys are merged).
struct MeshBuilder
{
  std::map<std::array<long, 3>, Index> Ids;
  std::vector<double> Points;
  std::vector<Index> Triangles;
  Index Vertex(const std::array<long, 3>& key, const double p[3])
  {
    auto it = this->Ids.find(key);
    if (it != this->Ids.end())
    {
      return it->second;
    }
    const Index id = static_cast<Index>(this->Points.size() / 3);
    this->Ids.emplace(key, id);
    this->Points.insert(this->Points.end(), p, p + 3);
    return id;
  }
};

// Star-shaped surfaces around the centre c: orient every triangle so that its normal points away from c.
void OrientOutward(const std::vector<double>& pts, std::vector<Index>& tris, const double c[3])
{
  for (size_t t = 0; t + 2 < tris.size(); t += 3)
  {
    const double* p0 = &pts[3 * tris[t]];
    const double* p1 = &pts[3 * tris[t + 1]];
    const double* p2 = &pts[3 * tris[t + 2]];
    const double e1[3] = { p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2] };
    const double e2[3] = { p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2] };
    const double nrm[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
      e1[0] * e2[1] - e1[1] * e2[0] };
    double dot = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      dot += nrm[a] * ((p0[a] + p1[a] + p2[a]) / 3.0 - c[a]);
    }
    if (dot < 0.0)
    {
      std::swap(tris[t + 1], tris[t + 2]);
    }
  }
}
} // namespace

bool InsideShape(ElasticShape shape, const double b[6], const double p[3])
{
  double c[3], r[3];
  CentreAndHalfWidths(b, c, r);
  const double tol = 1e-9;
  double q[3]; // coordinates relative to the half-widths (0 along flat axes)
  for (int a = 0; a < 3; ++a)
  {
    q[a] = r[a] > 0.0 ? (p[a] - c[a]) / r[a] : 0.0;
  }
  switch (shape)
  {
    case ElasticShape::Octahedron:
      return std::fabs(q[0]) + std::fabs(q[1]) + std::fabs(q[2]) <= 1.0 + tol;
    case ElasticShape::Ellipsoid:
      return q[0] * q[0] + q[1] * q[1] + q[2] * q[2] <= 1.0 + tol;
    case ElasticShape::Box:
      return std::fabs(q[0]) <= 1.0 + tol && std::fabs(q[1]) <= 1.0 + tol && std::fabs(q[2]) <= 1.0 + tol;
    case ElasticShape::Sphere:
    {
      const double R = std::min(r[0], std::min(r[1], r[2]));
      double d2 = 0.0;
      for (int a = 0; a < 3; ++a)
      {
        d2 += (p[a] - c[a]) * (p[a] - c[a]);
      }
      return d2 <= R * R * (1.0 + tol) + 1e-300;
    }
  }
  return false;
}

double ShapeVolume(ElasticShape shape, const double b[6])
{
  double c[3], r[3];
  CentreAndHalfWidths(b, c, r);
  switch (shape)
  {
    case ElasticShape::Octahedron:
      return 4.0 / 3.0 * r[0] * r[1] * r[2];
    case ElasticShape::Ellipsoid:
      return 4.0 / 3.0 * Pi * r[0] * r[1] * r[2];
    case ElasticShape::Box:
      return 8.0 * r[0] * r[1] * r[2];
    case ElasticShape::Sphere:
    {
      const double R = std::min(r[0], std::min(r[1], r[2]));
      return 4.0 / 3.0 * Pi * R * R * R;
    }
  }
  return 0.0;
}

void ShapeSurface(ElasticShape shape, const double b[6], int resolution, std::vector<double>& points,
  std::vector<Index>& triangles)
{
  double c[3], r[3];
  CentreAndHalfWidths(b, c, r);
  MeshBuilder mesh;
  const int res = std::max(4, resolution);
  if (shape == ElasticShape::Ellipsoid || shape == ElasticShape::Sphere)
  {
    if (shape == ElasticShape::Sphere)
    {
      r[0] = r[1] = r[2] = std::min(r[0], std::min(r[1], r[2]));
    }
    // UV sphere: `res` meridians, `circles` parallels and two poles: V = res circles + 2, F = 2 V - 4.
    const int circles = std::max(2, (13 * res) / 19);
    auto at = [&](long ring, long seg) {
      const double theta = Pi * ring / (circles + 1), phi = 2.0 * Pi * seg / res;
      const double p[3] = { c[0] + r[0] * std::sin(theta) * std::cos(phi),
        c[1] + r[1] * std::sin(theta) * std::sin(phi), c[2] + r[2] * std::cos(theta) };
      const long key = (ring == 0 || ring == circles + 1) ? 0 : seg % res;
      return mesh.Vertex({ ring, key, 0 }, p);
    };
    for (long ring = 0; ring <= circles; ++ring)
    {
      for (long seg = 0; seg < res; ++seg)
      {
        const Index a = at(ring, seg), bb = at(ring, seg + 1), cc = at(ring + 1, seg), d = at(ring + 1, seg + 1);
        if (ring > 0)
        {
          mesh.Triangles.insert(mesh.Triangles.end(), { a, cc, bb });
        }
        if (ring < circles)
        {
          mesh.Triangles.insert(mesh.Triangles.end(), { bb, cc, d });
        }
      }
    }
  }
  else if (shape == ElasticShape::Octahedron)
  {
    const long m = std::max(1, res / 4);
    for (int face = 0; face < 8; ++face)
    {
      const long s[3] = { face & 1 ? -1 : 1, face & 2 ? -1 : 1, face & 4 ? -1 : 1 };
      auto at = [&](long i, long j) {
        const long k = m - i - j;
        const double p[3] = { c[0] + r[0] * s[0] * i / double(m), c[1] + r[1] * s[1] * j / double(m),
          c[2] + r[2] * s[2] * k / double(m) };
        return mesh.Vertex({ s[0] * i, s[1] * j, s[2] * k }, p);
      };
      for (long i = 0; i < m; ++i)
      {
        for (long j = 0; j < m - i; ++j)
        {
          mesh.Triangles.insert(mesh.Triangles.end(), { at(i, j), at(i + 1, j), at(i, j + 1) });
          if (j < m - 1 - i)
          {
            mesh.Triangles.insert(mesh.Triangles.end(), { at(i + 1, j), at(i + 1, j + 1), at(i, j + 1) });
          }
        }
      }
    }
  }
  else // Box: every face an m x m grid, vertices keyed on the (m+1)^3 lattice
  {
    const long m = std::max(1, res / 4);
    for (int axis = 0; axis < 3; ++axis)
    {
      for (long side = 0; side <= m; side += m)
      {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        auto at = [&](long i, long j) {
          std::array<long, 3> key;
          key[axis] = side;
          key[u] = i;
          key[v] = j;
          double p[3];
          for (int a = 0; a < 3; ++a)
          {
            p[a] = b[2 * a] + (b[2 * a + 1] - b[2 * a]) * key[a] / double(m);
          }
          return mesh.Vertex(key, p);
        };
        for (long i = 0; i < m; ++i)
        {
          for (long j = 0; j < m; ++j)
          {
            mesh.Triangles.insert(mesh.Triangles.end(), { at(i, j), at(i + 1, j), at(i + 1, j + 1) });
            mesh.Triangles.insert(mesh.Triangles.end(), { at(i, j), at(i + 1, j + 1), at(i, j + 1) });
          }
        }
      }
    }
  }
  OrientOutward(mesh.Points, mesh.Triangles, c);
  points = std::move(mesh.Points);
  triangles = std::move(mesh.Triangles);
}

double MeshVolume(const std::vector<double>& p, const std::vector<Index>& t)
{
  double v = 0.0;
  for (size_t i = 0; i + 2 < t.size(); i += 3)
  {
    const double* a = &p[3 * t[i]];
    const double* b = &p[3 * t[i + 1]];
    const double* c = &p[3 * t[i + 2]];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v / 6.0;
}

void InsideMesh(const std::vector<double>& p, const std::vector<Index>& t, const std::vector<double>& queries,
  std::vector<char>& inside)
{
  const Index nq = static_cast<Index>(queries.size() / 3);
  inside.assign(nq, 0);
  const Index nt = static_cast<Index>(t.size() / 3);
  ParallelFor(
    nq, 64,
    [&](Index begin, Index end) {
      for (Index q = begin; q < end; ++q)
      {
        const double* x = &queries[3 * q];
        double omega = 0.0;
        for (Index f = 0; f < nt; ++f)
        {
          double a[3], b[3], c[3];
          for (int k = 0; k < 3; ++k)
          {
            a[k] = p[3 * t[3 * f] + k] - x[k];
            b[k] = p[3 * t[3 * f + 1] + k] - x[k];
            c[k] = p[3 * t[3 * f + 2] + k] - x[k];
          }
          const double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
          const double lb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
          const double lc = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
          const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
            a[2] * (b[0] * c[1] - b[1] * c[0]);
          const double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
          const double ac = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
          const double bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
          // Van Oosterom & Strackee: solid angle of the triangle seen from x.
          omega += 2.0 * std::atan2(det, la * lb * lc + ab * lc + ac * lb + bc * la);
        }
        inside[q] = std::fabs(omega) > 2.0 * Pi ? 1 : 0;
      }
    },
    1000000 + 1);
}

void VertexNormals(const std::vector<double>& p, const std::vector<Index>& t, std::vector<double>& normals)
{
  normals.assign(p.size(), 0.0);
  for (size_t i = 0; i + 2 < t.size(); i += 3)
  {
    const double* a = &p[3 * t[i]];
    const double* b = &p[3 * t[i + 1]];
    const double* c = &p[3 * t[i + 2]];
    const double e1[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
    const double e2[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
    const double nrm[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
      e1[0] * e2[1] - e1[1] * e2[0] };
    for (int k = 0; k < 3; ++k)
    {
      for (int a2 = 0; a2 < 3; ++a2)
      {
        normals[3 * t[i + k] + a2] += nrm[a2];
      }
    }
  }
  for (size_t v = 0; v + 2 < normals.size(); v += 3)
  {
    const double len = std::sqrt(normals[v] * normals[v] + normals[v + 1] * normals[v + 1] + normals[v + 2] * normals[v + 2]);
    for (int a = 0; a < 3; ++a)
    {
      normals[v + a] = len > 0.0 ? normals[v + a] / len : 0.0;
    }
  }
}

void ElasticSurface::Bind(const ElasticSolid& solid, const std::vector<double>& restVertices, int neighbors)
{
  this->RestVertices = restVertices;
  const Index nv = this->Size();
  const Index np = solid.Size();
  this->K = static_cast<int>(std::min<Index>(std::max(1, neighbors), np));
  this->Phyxel.assign(nv * this->K, -1);
  this->Weight.assign(nv * this->K, 0.0);
  if (np == 0)
  {
    return;
  }
  NeighborGrid grid;
  grid.Build(solid.RestPositions().data(), np);
  PerThread<std::vector<Index>> idsPerThread;
  PerThread<std::vector<double>> d2PerThread;
  ParallelFor(
    nv, 256,
    [&](Index begin, Index end) {
      std::vector<Index>& ids = idsPerThread.Local();
      std::vector<double>& d2 = d2PerThread.Local();
      for (Index v = begin; v < end; ++v)
      {
        const int found = grid.FindKNearest(&this->RestVertices[3 * v], this->K, ids, d2);
        double mean = 0.0;
        for (int t = 0; t < found; ++t)
        {
          mean += std::sqrt(d2[t]);
        }
        mean = found > 0 ? mean / found : 1.0;
        const double h2 = mean > 0.0 ? mean * mean : 1.0;
        for (int t = 0; t < found; ++t)
        {
          this->Phyxel[v * this->K + t] = ids[t];
          this->Weight[v * this->K + t] = std::exp(-d2[t] / h2); // [4.44]
        }
      }
    },
    kElasticParallel + 1);
}

void ElasticSurface::Deform(const ElasticSolid& solid, const std::vector<double>& F, std::vector<double>& points,
  std::vector<double>& displacement) const
{
  const Index nv = this->Size();
  points.resize(3 * nv);
  displacement.resize(3 * nv);
  const std::vector<double>& X = solid.RestPositions();
  const std::vector<double>& x = solid.State().Position;
  ParallelFor(
    nv, 1024,
    [&](Index begin, Index end) {
      for (Index v = begin; v < end; ++v)
      {
        const double* P = &this->RestVertices[3 * v];
        double u[3] = { 0, 0, 0 }, wsum = 0.0;
        for (int t = 0; t < this->K; ++t)
        {
          const Index i = this->Phyxel[v * this->K + t];
          if (i < 0)
          {
            continue;
          }
          const double w = this->Weight[v * this->K + t];
          const double* Fi = &F[9 * i];
          const double r[3] = { P[0] - X[3 * i], P[1] - X[3 * i + 1], P[2] - X[3 * i + 2] };
          for (int a = 0; a < 3; ++a) // [4.43]: u_i + grad u_i^T (x - X_i), grad u^T = F - I
          {
            const double ui = x[3 * i + a] - X[3 * i + a];
            const double gu = (Fi[a * 3] * r[0] + Fi[a * 3 + 1] * r[1] + Fi[a * 3 + 2] * r[2]) - r[a];
            u[a] += w * (ui + gu);
          }
          wsum += w;
        }
        for (int a = 0; a < 3; ++a)
        {
          displacement[3 * v + a] = wsum > 0.0 ? u[a] / wsum : 0.0;
          points[3 * v + a] = P[a] + displacement[3 * v + a];
        }
      }
    },
    kElasticParallel + 1);
}

} // namespace meshfree
