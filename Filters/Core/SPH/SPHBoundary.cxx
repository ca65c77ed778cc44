#include "SPH/SPHBoundary.h"

#include <algorithm>
#include <cmath>

namespace meshfree
{
namespace
{
int Divisions(double length, double spacing)
{
  const double n = std::ceil(length / spacing - 1e-9);
  return n < 1.0 ? 1 : static_cast<int>(std::min(n, 1e6));
}
}

void BoxWallLayers(const double b[6], int dimension, double spacing, int layers, std::vector<double>& xyz)
{
  int n[3];
  double step[3];
  for (int a = 0; a < 3; ++a)
  {
    const double count = std::floor((b[2 * a + 1] - b[2 * a]) / spacing + 0.5);
    n[a] = count < 1.0 ? 1 : static_cast<int>(std::min(count, 1e7));
    step[a] = (b[2 * a + 1] - b[2 * a]) / n[a];
  }
  const int jLow = dimension == 2 ? 0 : -layers, jHigh = dimension == 2 ? 1 : n[1] + layers;
  for (int k = -layers; k < n[2] + layers; ++k)
  {
    const bool kIn = k >= 0 && k < n[2];
    for (int j = jLow; j < jHigh; ++j)
    {
      const bool jIn = dimension == 2 || (j >= 0 && j < n[1]);
      for (int i = -layers; i < n[0] + layers; ++i)
      {
        if (kIn && jIn && i >= 0 && i < n[0])
        {
          i = n[0] - 1; // skip the inside of the box
          continue;
        }
        xyz.insert(xyz.end(), { b[0] + (i + 0.5) * step[0], dimension == 2 ? 0.0 : b[2] + (j + 0.5) * step[1],
                                b[4] + (k + 0.5) * step[2] });
      }
    }
  }
}

void ObstacleLayers(const std::vector<double>& samples, const std::vector<double>& normals,
  const NeighborGrid& grid, const double origin[3], double spacing, double depth, int dimension,
  std::vector<double>& xyz)
{
  if (samples.empty())
  {
    return;
  }
  double box[6];
  grid.GetBounds(box);
  long first[3], last[3];
  for (int a = 0; a < 3; ++a)
  {
    first[a] = static_cast<long>(std::floor((box[2 * a] - origin[a]) / spacing - 0.5));
    last[a] = static_cast<long>(std::ceil((box[2 * a + 1] - origin[a]) / spacing - 0.5));
  }
  if (dimension == 2)
  {
    first[1] = last[1] = 0;
  }
  std::vector<Index> nearest(1);
  std::vector<double> d2(1);
  for (long k = first[2]; k <= last[2]; ++k)
  {
    for (long j = first[1]; j <= last[1]; ++j)
    {
      for (long i = first[0]; i <= last[0]; ++i)
      {
        const double x[3] = { origin[0] + (i + 0.5) * spacing,
          dimension == 2 ? 0.0 : origin[1] + (j + 0.5) * spacing, origin[2] + (k + 0.5) * spacing };
        if (grid.FindKNearest(x, 1, nearest, d2) != 1)
        {
          continue;
        }
        const double* s = &samples[3 * nearest[0]];
        const double* nrm = &normals[3 * nearest[0]];
        const double behind = -((x[0] - s[0]) * nrm[0] + (x[1] - s[1]) * nrm[1] + (x[2] - s[2]) * nrm[2]);
        if (behind > 0.0 && behind < depth)
        {
          xyz.insert(xyz.end(), x, x + 3);
        }
      }
    }
  }
}

double SampleTriangles(
  const std::vector<double>& tri, double spacing, std::vector<double>& xyz, std::vector<double>& normals)
{
  const std::size_t first = normals.size();
  double volume6 = 0.0;
  for (std::size_t t = 0; t + 9 <= tri.size(); t += 9)
  {
    const double* a = &tri[t];
    const double* b = a + 3;
    const double* c = a + 6;
    double e1[3], e2[3], nrm[3];
    for (int i = 0; i < 3; ++i)
    {
      e1[i] = b[i] - a[i];
      e2[i] = c[i] - a[i];
    }
    nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
    nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
    nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const double area2 = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (!(area2 > 0.0) || !std::isfinite(area2))
    {
      continue;
    }
    // Signed volume of the tetrahedron (origin, a, b, c): summed, the volume enclosed by a closed surface.
    volume6 += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
      a[2] * (b[0] * c[1] - b[1] * c[0]);
    double longest = 0.0;
    for (int e = 0; e < 3; ++e)
    {
      const double* p = &tri[t + 3 * e];
      const double* q = &tri[t + 3 * ((e + 1) % 3)];
      longest = std::max(longest, std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                    (p[2] - q[2]) * (p[2] - q[2])));
    }
    const int n = Divisions(longest, spacing);
    for (int i = 0; i <= n; ++i)
    {
      for (int j = 0; i + j <= n; ++j)
      {
        const double u = static_cast<double>(i) / n, v = static_cast<double>(j) / n;
        xyz.insert(xyz.end(), { a[0] + u * e1[0] + v * e2[0], a[1] + u * e1[1] + v * e2[1],
                                a[2] + u * e1[2] + v * e2[2] });
        normals.insert(normals.end(), { nrm[0] / area2, nrm[1] / area2, nrm[2] / area2 });
      }
    }
  }
  if (volume6 < 0.0)
  {
    for (std::size_t i = first; i < normals.size(); ++i)
    {
      normals[i] = -normals[i];
    }
  }
  return std::fabs(volume6) / 6.0;
}

} // namespace meshfree
