// Bounded cache of simulation states keyed by output-step index, shared by the time-dependent sources.
//
// The sources report output times t_k = k * OutputInterval (OutputTimes() below); a requested time is placed
// among them by PlaceRequestedTime(). A request for step k restores the cached state of
// the largest cached step <= k and simulates forward from there, so scrubbing the time slider backwards or
// revisiting a time never re-simulates from t = 0. The cache holds at most `capacity` states; when full it
// evicts so that the kept steps stay spread over the timeline (it drops the entry whose removal leaves the
// smallest gap, never step 0), which bounds the forward re-simulation after a jump back.
// A property change must call Clear().
#ifndef meshfree_StateCache_h
#define meshfree_StateCache_h

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>
#include <map>
#include <utility>
#include <vector>

namespace meshfree
{

template <typename State>
class StateCache
{
public:
  explicit StateCache(std::size_t capacity = 16)
    : Capacity(capacity < 2 ? 2 : capacity)
  {
  }

  void SetCapacity(std::size_t capacity)
  {
    this->Capacity = capacity < 2 ? 2 : capacity;
    while (this->States.size() > this->Capacity)
    {
      this->EvictOne();
    }
  }
  std::size_t GetCapacity() const { return this->Capacity; }
  std::size_t Size() const { return this->States.size(); }
  void Clear() { this->States.clear(); }
  bool Contains(long step) const { return this->States.count(step) != 0; }

  /// The cached state with the largest step <= `step`, or nullptr. `foundStep` receives its step.
  const State* FindAtOrBefore(long step, long& foundStep) const
  {
    auto it = this->States.upper_bound(step);
    if (it == this->States.begin())
    {
      return nullptr;
    }
    --it;
    foundStep = it->first;
    return &it->second;
  }

  void Insert(long step, State state)
  {
    this->States[step] = std::move(state);
    while (this->States.size() > this->Capacity)
    {
      this->EvictOne();
    }
  }

private:
  // Remove the interior entry whose neighbours are closest together (the least informative checkpoint);
  // keep the first (step 0, the initial state) and the last (the most recent) entries.
  void EvictOne()
  {
    if (this->States.size() <= 2)
    {
      return;
    }
    auto best = this->States.end();
    long bestGap = std::numeric_limits<long>::max();
    for (auto it = std::next(this->States.begin()); std::next(it) != this->States.end(); ++it)
    {
      const long gap = std::next(it)->first - std::prev(it)->first;
      if (gap < bestGap)
      {
        bestGap = gap;
        best = it;
      }
    }
    this->States.erase(best);
  }

  std::size_t Capacity;
  std::map<long, State> States;
};

/// The output times of a time-dependent source: 0, interval, 2 interval, ..., and `end` itself as the last one
/// when it is not a multiple (within 1e-9 of an interval); at most 10^6 steps. Just {0} when end or interval
/// is not positive and finite.
inline std::vector<double> OutputTimes(double end, double interval)
{
  std::vector<double> times{ 0.0 };
  if (!(interval > 0.0) || !(end > 0.0) || !std::isfinite(end) || !std::isfinite(interval))
  {
    return times;
  }
  const double count = std::min(std::ceil(end / interval - 1e-9), 1e6);
  for (long k = 1; k <= static_cast<long>(count); ++k)
  {
    times.push_back(std::min(k * interval, end));
  }
  return times;
}

/// Where a requested time falls among the output times `times` (from OutputTimes()): returns the time to
/// produce and sets `step` to the last output time at or before it. A request within 1e-9 of an interval of an
/// output time gets that output time; one before the first or after the last output time (or not finite) gets
/// the first or the last; any other request gets itself, exactly: the sources then simulate from the output
/// state `step` (cached) to it, without caching the result, so it does not depend on earlier requests.
inline double PlaceRequestedTime(const std::vector<double>& times, double requested, long& step)
{
  step = 0;
  if (times.empty())
  {
    return 0.0;
  }
  const long last = static_cast<long>(times.size()) - 1;
  const double tolerance = last > 0 ? 1e-9 * (times[1] - times[0]) : 0.0;
  if (!(requested > times[0] + tolerance)) // also NaN
  {
    return times[0];
  }
  if (requested >= times[last] - tolerance)
  {
    step = last;
    return times[last];
  }
  step = static_cast<long>(std::upper_bound(times.begin(), times.end(), requested + tolerance) - times.begin()) - 1;
  return requested - times[step] <= tolerance ? times[step] : requested;
}

} // namespace meshfree

#endif
