// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: topology of a triangle mesh - how closed it is (boundary and non-manifold edges), its Euler
// characteristic and connected components - for the surface filters' reports and the tests.
#ifndef meshfree_MeshTopology_h
#define meshfree_MeshTopology_h

#include "Common/NeighborGrid.h"

#include <vector>

namespace meshfree
{

struct MeshTopology
{
  Index Vertices = 0;         // vertices used by at least one triangle
  Index Edges = 0;
  Index Triangles = 0;
  Index BoundaryEdges = 0;    // edges of one triangle
  Index NonManifoldEdges = 0; // edges of more than two triangles
  Index InconsistentEdges = 0; // interior edges whose two triangles run through them the same way
  Index Components = 0;       // connected through edges
  Index EulerCharacteristic = 0; // V - E + F (2 per closed sphere-like component, 0 per torus)
  bool Closed() const { return this->Triangles > 0 && this->BoundaryEdges == 0 && this->NonManifoldEdges == 0; }
};

/// Topology of `triangles` (3 point indices each, in 0..numberOfPoints). Degenerate triangles (a repeated
/// index) are counted as given.
MeshTopology ComputeMeshTopology(const std::vector<Index>& triangles, Index numberOfPoints);

/// Component id (0, 1, ...) of every triangle, components connected through shared vertices, numbered in
/// the order of their first triangle. Returns the number of components.
Index TriangleComponents(const std::vector<Index>& triangles, Index numberOfPoints, std::vector<Index>& component);

/// Signed volume enclosed by a closed, consistently oriented mesh (divergence theorem): positive when the
/// triangles' normals point outward.
double EnclosedVolume(const std::vector<double>& points, const std::vector<Index>& triangles);

} // namespace meshfree

#endif
