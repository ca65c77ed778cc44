// SPDX-License-Identifier: BSD-3-Clause
// Threads standing in for processes (Common/Distribution.h) in the core's tests: a barrier, the shared slots of
// the collective steps, the pieces (own points first, then the halo) and a Distribution over them.
#ifndef meshfree_testing_ThreadProcesses_h
#define meshfree_testing_ThreadProcesses_h

#include "Common/Distribution.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <vector>

namespace meshfree
{
namespace testing
{
/// A reusable barrier for P threads.
class Barrier
{
public:
  explicit Barrier(int count)
    : Count(count)
  {
  }
  void Wait()
  {
    std::unique_lock<std::mutex> lock(this->Mutex);
    const long generation = this->Generation;
    if (++this->Arrived == this->Count)
    {
      this->Arrived = 0;
      ++this->Generation;
      this->Ready.notify_all();
      return;
    }
    this->Ready.wait(lock, [&] { return generation != this->Generation; });
  }

private:
  std::mutex Mutex;
  std::condition_variable Ready;
  int Count;
  int Arrived = 0;
  long Generation = 0;
};

/// What the "processes" share: one slot per process for each collective step.
struct World
{
  explicit World(int size)
    : Size(size)
    , Sync(size)
    , Slots(size)
    , Pointers(size, nullptr)
  {
  }
  int Size;
  Barrier Sync;
  std::vector<std::vector<double>> Slots;
  std::vector<double*> Pointers;
};

/// A piece: its points (own first, then the halo), per point its owner and the owner's local index, its region.
struct Piece
{
  std::vector<double> Points;
  std::vector<int> Owner;
  std::vector<Index> OwnerIndex;
  std::vector<std::int64_t> Keys;
  Index OwnCount = 0;
  double Region[6];
  double Radius = 0.0;
  // Positions owned (slab partitions): Lower <= x[Axis] < Upper (the whole space by default).
  int Axis = 0;
  double Lower = -HUGE_VAL;
  double Upper = HUGE_VAL;
};

class ThreadDistribution : public Distribution
{
public:
  ThreadDistribution(World& world, int rank, const std::vector<Piece>& pieces)
    : W(world)
    , Me(rank)
    , Pieces(pieces)
  {
  }
  int Rank() const override { return this->Me; }
  int Size() const override { return this->W.Size; }
  bool Owned(Index i) const override { return i < this->Pieces[this->Me].OwnCount; }
  std::int64_t Key(Index i) const override { return this->Pieces[this->Me].Keys[i]; }
  void Sum(double* values, Index count) const override
  {
    this->Reduce(values, count, [](double a, double b) { return a + b; });
  }
  void Sum(std::int64_t* values, Index count) const override
  {
    // Exact: the integers travel as their bits.
    this->W.Slots[this->Me].resize(static_cast<size_t>(count));
    std::memcpy(this->W.Slots[this->Me].data(), values, sizeof(double) * static_cast<size_t>(count));
    this->W.Sync.Wait();
    for (Index j = 0; j < count; ++j)
    {
      std::int64_t sum = 0;
      for (int r = 0; r < this->W.Size; ++r)
      {
        std::int64_t v;
        std::memcpy(&v, &this->W.Slots[r][j], sizeof v);
        sum += v;
      }
      values[j] = sum;
    }
    this->W.Sync.Wait();
  }
  void Max(double* values, Index count) const override
  {
    this->Reduce(values, count, [](double a, double b) { return std::max(a, b); });
  }
  void Gather(const std::vector<double>& mine, std::vector<double>& all) const override
  {
    this->W.Slots[this->Me] = mine;
    this->W.Sync.Wait();
    all.clear();
    for (const std::vector<double>& slot : this->W.Slots)
    {
      all.insert(all.end(), slot.begin(), slot.end());
    }
    this->W.Sync.Wait();
  }
  void UpdateHalo(double* values, int components) const override
  {
    this->W.Pointers[this->Me] = values;
    this->W.Sync.Wait();
    const Piece& p = this->Pieces[this->Me];
    for (size_t i = static_cast<size_t>(p.OwnCount); i < p.Points.size() / 3; ++i)
    {
      const double* from = this->W.Pointers[p.Owner[i]] + p.OwnerIndex[i] * components;
      std::copy(from, from + components, values + i * components);
    }
    this->W.Sync.Wait();
  }
  double Complete(const double x[3]) const override
  {
    // The radius plus x's depth inside the region, minus its distance to the region when outside.
    const Piece& p = this->Pieces[this->Me];
    double depth = HUGE_VAL, outside = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      const double below = p.Region[2 * a] - x[a], above = x[a] - p.Region[2 * a + 1];
      depth = std::min(depth, -std::max(below, above));
      const double gap = std::max(0.0, std::max(below, above));
      outside += gap * gap;
    }
    return p.Radius + (outside > 0.0 ? -std::sqrt(outside) : std::max(depth, 0.0));
  }
  bool OwnsPosition(const double x[3]) const override
  {
    const Piece& p = this->Pieces[this->Me];
    return p.Lower <= x[p.Axis] && x[p.Axis] < p.Upper;
  }
  bool OwnsBall(const double x[3], double radius) const override
  {
    const Piece& p = this->Pieces[this->Me];
    return p.Lower <= x[p.Axis] - radius && x[p.Axis] + radius < p.Upper;
  }

private:
  template <class Op>
  void Reduce(double* values, Index count, Op op) const
  {
    this->W.Slots[this->Me].assign(values, values + count);
    this->W.Sync.Wait();
    for (Index j = 0; j < count; ++j)
    {
      double v = this->W.Slots[0][j];
      for (int r = 1; r < this->W.Size; ++r)
      {
        v = op(v, this->W.Slots[r][j]);
      }
      values[j] = v;
    }
    this->W.Sync.Wait();
  }
  World& W;
  int Me;
  const std::vector<Piece>& Pieces;
};

/// The whole cloud's frame as the VTK layer reduces it: the bounds of its finite points and their number.
inline Index WholeFrame(const std::vector<double>& xyz, double frame[6])
{
  GlobalBounds(nullptr, xyz.data(), static_cast<Index>(xyz.size() / 3), frame);
  Index finite = 0;
  for (size_t i = 0; i < xyz.size(); i += 3)
  {
    finite += std::isfinite(xyz[i]) && std::isfinite(xyz[i + 1]) && std::isfinite(xyz[i + 2]) ? 1 : 0;
  }
  return finite;
}

} // namespace testing
} // namespace meshfree

#endif
