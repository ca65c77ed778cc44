// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class meshfree::WindingNumber
 * @brief The generalized winding number of an oriented point cloud, a smooth global inside/outside estimate
 *        (Barill, Dickson, Schmidt, Levin & Jacobson 2018, "Fast winding numbers for soups and clouds").
 *
 * Every point p_i carries an area a_i and a unit outward normal n_i; the cloud's winding number at x is
 *
 *   w(x) = sum_i a_i n_i . (p_i - x) / (4 pi |p_i - x|^3),
 *
 * the solid angle the sampled surface subtends at x over 4 pi: about 1 inside a closed sampled surface, 0
 * outside, and across a hole in the sampling a smooth, harmonic interpolation between the two (its 1/2 level
 * spans the hole like a soap film, without bulging).
 *
 * Barnes-Hut evaluation: a binary tree over the points (median splits along the widest axis, leaves of at most
 * 32 points); every node keeps its area-weighted centre c, its dipole moment M = sum a_i n_i, the second moment
 * Q = sum a_i (p_i - c) n_i^T and its radius r (largest |p_i - c|). A node with |x - c| > Beta r is summed by
 * its Taylor expansion to second order in the points' offsets d = p - c, M . g(r) + tr(J(r) Q) + 1/2 H(r)[C]
 * with r = c - x, g(r) = r / (4 pi |r|^3), J and H its first and second derivatives and C = sum a n (x) d (x) d
 * (the normals vary within a node as much as the points do, so the H term is of the same order as the Q term:
 * without it the expansion was worse than the first order alone, 8.7 % against 2.9 % at a sphere's centre);
 * nearer nodes are opened, leaves summed directly. The gradient uses the first-order term. The
 * direct terms are regularised within sqrt(a_i / pi) of a point (the disc it stands for), so w stays finite on
 * the data. Cost per evaluation O(log n) for points far from the data, a few leaves more near them.
 *
 * Cubes (Build with WindingCubes): the points are first bucketed in cubes of a fixed lattice (edge Size, from
 * Origin), each cube gets its own tree, and a top tree (median splits of the cubes' centres) joins the cubes' roots
 * by the same moment formulas. The tree then depends on the set of points and the lattice only, which lets
 * processes that each hold a region of the cloud and a halo (Common/Distribution.h) evaluate the whole cloud's w
 * with the serial bits: a process builds the cubes it holds completely (every point within Size sqrt(3) / 2 of the
 * cube's centre: Distribution::Complete), the owner of each cube's centre (OwnsPosition) contributes its root's
 * moments, every process gathers them and builds the same top tree; a cube it does not hold is a leaf summed by its
 * expansion. An evaluation that would need to open such a cube is counted (Incomplete()): the halo was too narrow.
 */
#ifndef meshfree_WindingNumber_h
#define meshfree_WindingNumber_h

#include "Common/Distribution.h"
#include "Common/LargeArrays.h"
#include "Common/NeighborGrid.h"

#include <atomic>
#include <cmath>

#include <vector>

namespace meshfree
{

/// The cube lattice of a WindingNumber (see the class comment); Size <= 0: one cube (a single tree).
struct WindingCubes
{
  double Size = 0.0;
  double Origin[3] = { 0.0, 0.0, 0.0 };
  const Distribution* Processes = nullptr; // distributed (collective Build); null: serial
};

class WindingNumber
{
public:
  /// Points (3 per point), unit outward normals (3 per point) and areas (1 per point); points with a zero or
  /// non-finite normal, area or coordinate are left out. Beta >= 1 is the opening criterion (default 2).
  void Build(const double* points, const double* normals, const double* areas, Index count, double beta = 2.0);
  /// The same over a cube lattice (collective when distributed).
  void Build(const double* points, const double* normals, const double* areas, Index count, const WindingCubes& cubes,
    double beta = 2.0);

  /// Distributed: how far the halo fell short of a cube this process owns (<= 0: complete; -infinity serial), and
  /// whether an evaluation needed a cube this process does not hold (then its expansion was used).
  double Shortfall() const { return this->BuildShortfall; }
  bool Incomplete() const { return this->Opened.load(); }

  /// w(x); when gradient is not null, grad w(x) (first order in the far nodes).
  double Evaluate(const double x[3], double gradient[3] = nullptr) const;

  /// The exact sum over every point (O(n), for tests).
  double EvaluateDirect(const double x[3]) const;

  Index NumberOfPoints() const { return static_cast<Index>(this->Areas.size()); }
  /// sum a_i and |sum a_i n_i|: a closed surface's normals cancel (its integral of n dA is 0), so their
  /// ratio is the share of the sampled area left uncovered by holes, as seen through their flat projection.
  double TotalArea() const { return this->Total; }
  double DipoleLength() const;

private:
  struct Node
  {
    double Centre[3];
    double Moment[3];
    double Second[9]; // row-major sum a (p - c) n^T
    double Third[27]; // [a][b][c]: sum area n_a d_b d_c, d = p - c
    double Radius;     // bounds |p - c| over the node's points
    double Area;
    Index Begin, End;  // points [Begin, End) in this->Points' order
    Index Left, Right; // children (-1 for a leaf; -2 for a cube another process holds)
  };
  struct Item
  {
    double P[3];
    Index Id;
  };
  Index BuildNode(Index begin, Index end, detail::Buffer<Item>& items);
  /// A leaf of the top tree: a cube's root this process built (Held, an index in Nodes) or the gathered record of
  /// another process' cube (Record: centre, moment, second, third, radius, area).
  struct TopLeaf
  {
    Index Held = -1;
    const double* Record = nullptr;
  };
  struct TopShape
  {
    double Centre[3];
    double Radius;
    double Area;
  };
  TopShape LeafShape(const TopLeaf& leaf) const;
  Node LeafNode(const TopLeaf& leaf) const;
  /// The top tree's internal nodes' shapes over leaves[begin, end), in pre-order from `index` (ordering the leaves
  /// by the splits: median of the centres along the widest axis, ties in key order).
  TopShape ShapeTop(std::vector<TopLeaf>& leaves, size_t begin, size_t end, size_t index,
    std::vector<TopShape>& shapes) const;
  /// The moments of the top node over leaves[begin, end), not stored.
  Node TopMoments(const std::vector<TopLeaf>& leaves, size_t begin, size_t end) const;
  /// Stores the top node over leaves[begin, end) and the descendants this process needs (d: see the definition).
  Index EmitTop(const std::vector<TopLeaf>& leaves, size_t begin, size_t end, size_t index,
    const std::vector<TopShape>& shapes, const Distribution* d);
  /// Whether this process never opens the top node of that shape (every evaluation is made where its cloud is
  /// complete, and the node lies farther than Beta radii from there); serial (d null): never pruned.
  bool Pruned(const TopShape& shape, const Distribution* d) const;
  /// How many nodes EmitTop stores over leaves[begin, end) (reserved at once: issue 24's memory per rank).
  size_t CountTop(const std::vector<TopLeaf>& leaves, size_t begin, size_t end, size_t index,
    const std::vector<TopShape>& shapes, const Distribution* d) const;
  /// A node by index: the cubes' trees first (Nodes), then the top tree's (Top).
  const Node& NodeAt(Index k) const
  {
    const size_t cube = this->Nodes.size();
    return static_cast<size_t>(k) < cube ? this->Nodes[static_cast<size_t>(k)] : this->Top[static_cast<size_t>(k) - cube];
  }
  /// `node`'s moments from its two children's.
  void Combine(Node& node, const Node& left, const Node& right) const;
  // The cubes' trees (each allocated at its exact size), the top tree over them; they and the points below are
  // scratch-sized arrays on huge pages (LargeArrays.h): built serially while the contour's other threads wait.
  detail::Buffer<Node> Nodes, Top;
  Index Root = 0;
  double BuildShortfall = -HUGE_VAL;
  mutable std::atomic<bool> Opened{ false };
  detail::Buffer<double> Points, Normals, Areas; // tree order (a point's regularisation radius squared: Areas / pi)
  double Beta2 = 4.0;
  double Total = 0.0;
};

} // namespace meshfree

#endif
