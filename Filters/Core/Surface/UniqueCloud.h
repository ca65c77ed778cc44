// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: a surface cloud without its exact duplicates. A point repeated m times would count m times
// among its neighbours' k nearest and shrink every neighbourhood to 1/m of the sampling it stands for (holes
// in the surface); the normals and surface filters work on the distinct points and give duplicates their
// representative's results.
#ifndef meshfree_UniqueCloud_h
#define meshfree_UniqueCloud_h

#include "Common/Distribution.h"
#include "Common/NeighborGrid.h"

#include <memory>
#include <vector>

namespace meshfree
{

struct UniqueCloud
{
  std::vector<double> Points;  // the distinct valid points, 3 each, in the order of their first occurrence
  std::vector<double> Normals; // their normals (when the input had normals)
  std::vector<Index> Unique;   // per input point: its distinct point, or -1 (invalid coordinates)
  Index Duplicates = 0;
};

/// Fills `unique` from the points the grid was built over (xyz, and normals or null) when they hold exact
/// duplicates, or always with `always` (then without duplicates it is the valid points themselves); returns
/// whether it filled it (unique untouched otherwise).
bool MergeDuplicates(
  const NeighborGrid& grid, const double* xyz, const double* normals, UniqueCloud& unique, bool always = false);

/// A distributed cloud's distinct points (UniqueCloud over a process' piece and halo): each is owned where its
/// member with the smallest key is, and its halo values are that member's owner's; positions belong to the
/// processes as in the base distribution.
class DistinctDistribution : public Distribution
{
public:
  /// `base` and `unique` (filled from the n local points) must outlive this object.
  DistinctDistribution(const Distribution& base, const UniqueCloud& unique, Index n);
  int Rank() const override { return this->Base.Rank(); }
  int Size() const override { return this->Base.Size(); }
  bool Owned(Index u) const override { return this->Base.Owned(this->Representative[u]); }
  std::int64_t Key(Index u) const override { return this->Base.Key(this->Representative[u]); }
  void Sum(double* values, Index count) const override { this->Base.Sum(values, count); }
  void Sum(std::int64_t* values, Index count) const override { this->Base.Sum(values, count); }
  void Max(double* values, Index count) const override { this->Base.Max(values, count); }
  void Gather(const std::vector<double>& mine, std::vector<double>& all) const override
  {
    this->Base.Gather(mine, all);
  }
  double Complete(const double x[3]) const override { return this->Base.Complete(x); }
  bool OwnsPosition(const double x[3]) const override { return this->Base.OwnsPosition(x); }
  bool OwnsBall(const double x[3], double radius) const override { return this->Base.OwnsBall(x, radius); }
  void UpdateHalo(double* values, int components) const override;
  /// This process' own input points that are not their distinct point's representative.
  Index OwnDuplicates() const;

private:
  const Distribution& Base;
  const UniqueCloud& Unique;
  std::vector<Index> Representative;
};

/// MergeDuplicates over a cloud that may be distributed (d; collective): when any process has duplicates, every
/// process fills `unique` (with its points as they are when it has none), distributed with `processes` wrapping
/// `d` (so the surface and the normals see one distinct cloud), and `duplicates` counts the duplicates this
/// process owns (serial: all of them). Returns false, leaving the outputs untouched, when no process has any.
bool MergeDuplicates(const NeighborGrid& grid, const double* xyz, const double* normals, Index n, const Distribution* d,
  UniqueCloud& unique, std::unique_ptr<DistinctDistribution>& processes, Index& duplicates);

} // namespace meshfree

#endif
