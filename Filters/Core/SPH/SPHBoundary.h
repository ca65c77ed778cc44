// MeshFree core: boundary particles of the SPH fluid, VTK-free.
//
// Walls and obstacles are represented by static "dummy" particles (Adami, Hu & Adams 2012; the multi-layer
// variant of Akinci et al. 2012's boundary particles) on a lattice of the fluid's spacing, filling a shell as
// thick as the kernel support behind every wall and inside every obstacle. A fluid particle next to a wall then
// sees a complete neighbourhood: at rest its density is exactly the interior one, and the mirrored pressure of the
// dummies balances its own (SPHFluid.h). Obstacle surfaces are also sampled (positions and outward normals) for
// the inside test that guarantees no fluid particle crosses them.
#ifndef meshfree_SPHBoundary_h
#define meshfree_SPHBoundary_h

#include "Common/NeighborGrid.h"

#include <vector>

namespace meshfree
{

/// Dummy particles behind the walls of the box `bounds` (xmin, xmax, ymin, ymax, zmin, zmax): the nodes of a
/// lattice of about `spacing` (adjusted per axis to divide the box exactly, nodes half a spacing off the walls)
/// that lie outside the box within `layers` spacings of it, edges and corners included. Appends x y z triplets
/// to `xyz`. Dimension 2: the x-z rectangle, y = 0.
void BoxWallLayers(const double bounds[6], int dimension, double spacing, int layers, std::vector<double>& xyz);

/// Dummy particles inside closed obstacles: nodes of the lattice of `spacing` anchored at `origin` inside the
/// bounding box of the surface samples, kept when the nearest sample (positions `samples`, outward unit
/// `normals`, searched in `grid`, built over the samples) sees them behind the surface by less than `depth`.
/// Dimension 2: the y = 0 plane only. Appends to `xyz`.
void ObstacleLayers(const std::vector<double>& samples, const std::vector<double>& normals,
  const NeighborGrid& grid, const double origin[3], double spacing, double depth, int dimension,
  std::vector<double>& xyz);

/// Samples triangles (9 doubles each) with about `spacing` between samples, appending positions to `xyz` and
/// unit normals to `normals`. The normals are made to point outwards of the closed surface(s): if the
/// enclosed signed volume is negative every normal is flipped. Degenerate triangles are skipped. Returns the
/// enclosed volume (>= 0).
double SampleTriangles(
  const std::vector<double>& triangles, double spacing, std::vector<double>& xyz, std::vector<double>& normals);

} // namespace meshfree

#endif
