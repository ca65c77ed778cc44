// SPDX-License-Identifier: BSD-3-Clause
// Geometry of the meshless elastic solid, VTK-free: built-in shapes (phyxel sampling and triangulated
// surfaces), filling a closed triangle mesh with phyxels, and the embedded surface that follows the MLS
// displacement field of the phyxels (thesis 4.43-4.44).
#ifndef meshfree_ElasticShapes_h
#define meshfree_ElasticShapes_h

#include "Common/NeighborGrid.h"

#include <algorithm>
#include <string>
#include <vector>

namespace meshfree
{
class ElasticSolid;

enum class ElasticShape
{
  Octahedron,
  Ellipsoid,
  Box,
  Sphere
};

/// Whether p lies inside the shape inscribed in bounds [x0,x1,y0,y1,z0,z1] (the sphere is centred, with the
/// smallest half-width as radius). Boundary points count as inside.
bool InsideShape(ElasticShape shape, const double bounds[6], const double p[3]);
/// Volume of that shape.
double ShapeVolume(ElasticShape shape, const double bounds[6]);

/// Centres of a cubic lattice of the given spacing, centred in bounds (round(extent/spacing) cells per axis,
/// at least one: flat bounds give one layer), that satisfy `inside`. Returns false (and no points) when the
/// lattice would exceed maxPoints or the spacing is not positive.
template <class Inside>
bool SampleLattice(const double bounds[6], double spacing, Inside&& inside, std::vector<double>& points,
  Index maxPoints = 20000000);

/// Triangulated surface of a built-in shape, outward oriented. `resolution` is the number of segments around
/// the equator (ellipsoid, sphere) or along an edge pattern (octahedron, box); 38 gives the thesis' ellipsoid
/// surface of 990 vertices and 1976 triangles.
void ShapeSurface(ElasticShape shape, const double bounds[6], int resolution, std::vector<double>& points,
  std::vector<Index>& triangles);

/// Signed volume enclosed by a closed triangle mesh (positive when outward oriented).
double MeshVolume(const std::vector<double>& points, const std::vector<Index>& triangles);

/// For each query point, whether it is inside the closed triangle mesh (generalised winding number > 1/2,
/// robust to small holes and either orientation).
void InsideMesh(const std::vector<double>& points, const std::vector<Index>& triangles,
  const std::vector<double>& queries, std::vector<char>& inside);

/// Area-weighted vertex normals of a triangle mesh.
void VertexNormals(
  const std::vector<double>& points, const std::vector<Index>& triangles, std::vector<double>& normals);

/**
 * A surface embedded in the solid [4.43-4.44]: every vertex follows the first-order MLS displacement field of
 * its k nearest phyxels (at rest), u = sum_i w_i (u_i + (F_i - I)(X - X_i)) / sum_i w_i, w_i = exp(-r_i^2/h^2)
 * with h the mean distance to those phyxels. Affine motions of the phyxels move every vertex exactly.
 */
class ElasticSurface
{
public:
  void Bind(const ElasticSolid& solid, const std::vector<double>& restVertices, int neighbors = 8);
  /// Deformed positions and displacements of the vertices for the solid's current positions and the
  /// deformation gradients F (9 per phyxel, as ElasticSolid::ComputeDeformation gives them).
  void Deform(const ElasticSolid& solid, const std::vector<double>& F, std::vector<double>& points,
    std::vector<double>& displacement) const;
  Index Size() const { return static_cast<Index>(this->RestVertices.size() / 3); }

private:
  std::vector<double> RestVertices;
  int K = 0;
  std::vector<Index> Phyxel; // Size() * K, -1 pads
  std::vector<double> Weight;
};

//------------------------------------------------------------------------------
template <class Inside>
bool SampleLattice(const double bounds[6], double spacing, Inside&& inside, std::vector<double>& points,
  Index maxPoints)
{
  points.clear();
  if (!(spacing > 0.0))
  {
    return false;
  }
  Index count[3];
  double start[3];
  double total = 1.0;
  for (int a = 0; a < 3; ++a)
  {
    const double extent = bounds[2 * a + 1] - bounds[2 * a];
    const double cells = extent > 0.0 ? extent / spacing + 0.5 : 1.0;
    if (!(cells < 1e7))
    {
      return false;
    }
    count[a] = std::max<Index>(1, static_cast<Index>(cells));
    total *= static_cast<double>(count[a]);
    start[a] = 0.5 * (bounds[2 * a] + bounds[2 * a + 1]) - 0.5 * static_cast<double>(count[a] - 1) * spacing;
  }
  if (total > static_cast<double>(maxPoints))
  {
    return false;
  }
  for (Index k = 0; k < count[2]; ++k)
  {
    for (Index j = 0; j < count[1]; ++j)
    {
      for (Index i = 0; i < count[0]; ++i)
      {
        const double p[3] = { start[0] + i * spacing, start[1] + j * spacing, start[2] + k * spacing };
        if (inside(p))
        {
          points.insert(points.end(), p, p + 3);
        }
      }
    }
  }
  return true;
}

} // namespace meshfree

#endif
