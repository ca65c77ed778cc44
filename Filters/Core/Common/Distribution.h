// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief What a computation over a cloud split among several processes needs from them, so that the core stays
 *        free of MPI (the VTK layer implements it with vtkMultiProcessController: vtkMeshFreeHalo).
 *
 * A process' local cloud is its own points and a halo: copies of other processes' points near its own, enough
 * for every neighbourhood its own points' computations read. Each local point is owned by exactly one process
 * (Owned()); the values the computation writes for halo points are replaced by their owners' (UpdateHalo), so a
 * value that depends on the neighbours' values (a second level) is the same everywhere. Global statistics are
 * reductions over the owned points; the medians are exact (GlobalMedian selects the same element a serial
 * median selects), so every process takes the same decisions as a serial run.
 *
 * Every method is collective: every process calls it, in the same order, with an empty piece too. A null
 * Distribution means a serial computation: every point is owned and the helpers below are the local operations.
 */
#ifndef meshfree_Distribution_h
#define meshfree_Distribution_h

#include "Common/LargeArrays.h"

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <vector>

namespace meshfree
{
using Index = std::int64_t;

class Distribution
{
public:
  virtual ~Distribution() = default;
  /// This process' number (0 .. Size() - 1) and the number of processes.
  virtual int Rank() const = 0;
  virtual int Size() const = 0;
  /// Whether local point i is this process' own (every point of the whole cloud is owned by one process).
  virtual bool Owned(Index i) const = 0;
  /// A key of local point i unique over the whole cloud and the same on every process (the global id).
  virtual std::int64_t Key(Index i) const = 0;
  /// Element-wise sums and maxima over the processes, in place (count the same on every process).
  virtual void Sum(double* values, Index count) const = 0;
  virtual void Sum(std::int64_t* values, Index count) const = 0;
  virtual void Max(double* values, Index count) const = 0;
  /// The concatenation of every process' `mine`, in process order (the same on every process).
  virtual void Gather(const std::vector<double>& mine, std::vector<double>& all) const = 0;
  /// The halo points' `components` values (interleaved, one tuple per local point) replaced by their owners'.
  virtual void UpdateHalo(double* values, int components) const = 0;
  /// How far around x the local cloud is complete: every point of the whole cloud within this distance of x is in
  /// it (the halo's radius plus x's depth inside the region it was grown from, minus x's distance to that region
  /// when x lies outside it; negative: nothing is known to be complete around x).
  virtual double Complete(const double x[3]) const = 0;
  /// Computations that partition space rather than points (the surface's contouring lattice: each cell is
  /// contoured by the process owning its centre) ask which process owns a position: every position of space by
  /// exactly one process, the same answer on every process, and the local cloud complete around the positions a
  /// process owns (Complete). The default (every position) suits one process only.
  virtual bool OwnsPosition(const double x[3]) const
  {
    (void)x;
    return true;
  }
  /// Whether every position within `radius` of x is this process' (OwnsPosition); it may answer false for a ball
  /// it owns only where that costs exactness nowhere (a caller then merely exchanges more).
  virtual bool OwnsBall(const double x[3], double radius) const
  {
    (void)x;
    (void)radius;
    return true;
  }
};

/// Whether local point i is this process' own (every point when serial).
inline bool IsOwn(const Distribution* d, Index i)
{
  return !d || d->Owned(i);
}

/// How far a query of radius `reach` around x exceeds what the local cloud holds (<= 0: it found every point
/// the whole cloud has there); -infinity when serial. A computation reports the largest: a halo that is wider
/// by that much gives the same result as the serial run.
double Shortfall(const Distribution* d, const double x[3], double reach);

/// Sums and maxima over the processes (the value itself when serial).
double GlobalSum(const Distribution* d, double value);
Index GlobalSum(const Distribution* d, Index value);
double GlobalMax(const Distribution* d, double value);
/// The median of the values of every process (Statistics.h's Median of their union: the upper median), exact:
/// a radix selection over the values' bits, four rounds of 65,536 counts.
double GlobalMedian(const Distribution* d, std::vector<double> values);
/// The element of 0-based rank `rank` in the ascending order of every process' values (the same selection); 0 when
/// there are none.
double GlobalSelect(const Distribution* d, std::vector<double> values, Index rank);
/// The bounds (xmin, xmax, ...) of every process' finite points among n interleaved xyz (min > max when none).
void GlobalBounds(const Distribution* d, const double* xyz, Index n, double bounds[6]);

/// Every process' keys, concatenated in process order (the keys themselves when serial). Collective.
std::vector<std::uint64_t> GatherKeys(const Distribution* d, const std::vector<std::uint64_t>& mine);

/// UpdateHalo for per-point vectors of other types (values converted exactly through double).
void UpdateHalo(const Distribution* d, std::vector<double>& values, int components = 1);
void UpdateHalo(const Distribution* d, std::vector<unsigned char>& values);
/// Rows of `width` local point indices per point (-1 pads, as neighbour graphs store them): the halo points' rows
/// replaced by their owners', translated through Key() (an entry whose point is not in the local cloud: -1).
void UpdateHaloRows(const Distribution* d, detail::Buffer<std::int32_t>& rows, int width);
/// UpdateHalo for values kept in a grid's sorted order (one per sorted position s, of local point order[s]):
/// each vector of `sorted` is one component; n is the number of local points.
void UpdateHaloInOrder(const Distribution* d, const std::vector<Index>& order, Index n,
  std::initializer_list<std::vector<double>*> sorted);

/// A sample of a cloud's points that does not depend on their order nor on how they are split among the
/// processes: the `count` points (of the whole cloud) with the smallest hash of their coordinates' bits, among
/// each process' candidates (Choose: its points xyz, e.g. a grid's sorted points, with eligible(i)).
class CloudSample
{
public:
  /// Chooses the sample among the points xyz[3 i] with eligible(i) (this process' own points). Collective.
  template <class Eligible>
  void Choose(const Distribution* d, const double* xyz, Index n, Index count, const Eligible& eligible)
  {
    detail::Buffer<Candidate> candidates;
    detail::ReserveLarge(candidates, static_cast<std::size_t>(n > 0 ? n : 0)); // no regrowth, pooled or huge pages
    for (Index i = 0; i < n; ++i)
    {
      if (eligible(i))
      {
        candidates.push_back({ Hash(xyz + 3 * i), i });
      }
    }
    this->Select(d, xyz, candidates, count);
  }
  /// This process' sample points (indices given to Choose), in the sample's order.
  const std::vector<Index>& Local() const { return this->Mine; }
  /// The number of points in the whole sample.
  Index Size() const { return this->Total; }
  /// One value per local sample point (in Local()'s order) -> the whole sample's values in the sample's order.
  std::vector<double> Gather(const Distribution* d, const std::vector<double>& mine) const;

private:
  struct Candidate
  {
    std::uint64_t Hash;
    Index Point;
  };
  static std::uint64_t Hash(const double x[3]);
  void Select(const Distribution* d, const double* xyz, detail::Buffer<Candidate>& candidates, Index count);
  std::vector<Index> Mine;
  std::vector<Index> Rank; // per local sample point: its place in the whole sample
  Index Total = 0;
};

} // namespace meshfree

#endif
