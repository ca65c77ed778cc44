// SPDX-License-Identifier: BSD-3-Clause
#include "Common/Distribution.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <tuple>
#include <unordered_map>

namespace meshfree
{

double GlobalSum(const Distribution* d, double value)
{
  if (d)
  {
    d->Sum(&value, 1);
  }
  return value;
}

Index GlobalSum(const Distribution* d, Index value)
{
  std::int64_t v = value;
  if (d)
  {
    d->Sum(&v, 1);
  }
  return static_cast<Index>(v);
}

std::vector<std::uint64_t> GatherKeys(const Distribution* d, const std::vector<std::uint64_t>& mine)
{
  if (!d)
  {
    return mine;
  }
  // Two exact 32-bit halves per key (a double holds integers up to 2^53).
  std::vector<double> halves(2 * mine.size()), all;
  for (size_t i = 0; i < mine.size(); ++i)
  {
    halves[2 * i] = static_cast<double>(mine[i] >> 32);
    halves[2 * i + 1] = static_cast<double>(mine[i] & 0xffffffffu);
  }
  d->Gather(halves, all);
  std::vector<std::uint64_t> keys(all.size() / 2);
  for (size_t i = 0; i < keys.size(); ++i)
  {
    keys[i] = (static_cast<std::uint64_t>(all[2 * i]) << 32) | static_cast<std::uint64_t>(all[2 * i + 1]);
  }
  return keys;
}

double Shortfall(const Distribution* d, const double x[3], double reach)
{
  return d ? reach - d->Complete(x) : -HUGE_VAL;
}

double GlobalMax(const Distribution* d, double value)
{
  if (d)
  {
    d->Max(&value, 1);
  }
  return value;
}

namespace
{
/// The bits of a double as an unsigned key in the same order as the values (-0 before +0; NaN are not given).
std::uint64_t OrderedBits(double value)
{
  std::uint64_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return (bits >> 63) ? ~bits : bits | (std::uint64_t(1) << 63);
}

double FromOrderedBits(std::uint64_t key)
{
  const std::uint64_t bits = (key >> 63) ? key & ~(std::uint64_t(1) << 63) : ~key;
  double value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}
} // namespace

double GlobalMedian(const Distribution* d, std::vector<double> values)
{
  const Index total = GlobalSum(d, static_cast<Index>(values.size()));
  return GlobalSelect(d, std::move(values), total / 2); // Median's upper median (0 when there are none)
}

void GlobalBounds(const Distribution* d, const double* xyz, Index n, double bounds[6])
{
  // (-min, max) per axis, reduced with one maximum.
  double both[6] = { -HUGE_VAL, -HUGE_VAL, -HUGE_VAL, -HUGE_VAL, -HUGE_VAL, -HUGE_VAL };
  for (Index i = 0; i < n; ++i)
  {
    const double* x = xyz + 3 * i;
    if (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]))
    {
      for (int a = 0; a < 3; ++a)
      {
        both[2 * a] = std::max(both[2 * a], -x[a]);
        both[2 * a + 1] = std::max(both[2 * a + 1], x[a]);
      }
    }
  }
  if (d)
  {
    d->Max(both, 6);
  }
  for (int a = 0; a < 3; ++a)
  {
    bounds[2 * a] = -both[2 * a];
    bounds[2 * a + 1] = both[2 * a + 1];
  }
}

double GlobalSelect(const Distribution* d, std::vector<double> values, Index rank)
{
  if (!d)
  {
    if (values.empty())
    {
      return 0.0;
    }
    rank = std::min<Index>(std::max<Index>(rank, 0), static_cast<Index>(values.size()) - 1);
    std::nth_element(values.begin(), values.begin() + rank, values.end());
    return values[static_cast<size_t>(rank)];
  }
  const Index total = GlobalSum(d, static_cast<Index>(values.size()));
  if (total == 0)
  {
    return 0.0;
  }
  rank = std::min<Index>(std::max<Index>(rank, 0), total - 1);
  // By the key's 16-bit digits from the top: each round counts the keys that share the digits found so far, per
  // next digit, over all processes.
  std::vector<std::uint64_t> keys(values.size());
  std::transform(values.begin(), values.end(), keys.begin(), OrderedBits);
  std::uint64_t prefix = 0;
  std::vector<std::int64_t> counts(65536);
  for (int shift = 48; shift >= 0; shift -= 16)
  {
    std::fill(counts.begin(), counts.end(), 0);
    const std::uint64_t high = shift == 48 ? 0 : ~std::uint64_t(0) << (shift + 16);
    for (std::uint64_t key : keys)
    {
      if ((key & high) == prefix)
      {
        ++counts[(key >> shift) & 0xffff];
      }
    }
    d->Sum(counts.data(), static_cast<Index>(counts.size()));
    std::uint64_t digit = 0;
    while (rank >= counts[digit])
    {
      rank -= counts[digit];
      ++digit;
    }
    prefix |= digit << shift;
  }
  return FromOrderedBits(prefix);
}

void UpdateHalo(const Distribution* d, std::vector<double>& values, int components)
{
  if (d)
  {
    d->UpdateHalo(values.data(), components);
  }
}

void UpdateHalo(const Distribution* d, std::vector<unsigned char>& values)
{
  if (!d)
  {
    return;
  }
  std::vector<double> wide(values.begin(), values.end());
  d->UpdateHalo(wide.data(), 1);
  std::transform(wide.begin(), wide.end(), values.begin(), [](double v) { return static_cast<unsigned char>(v); });
}

void UpdateHaloRows(const Distribution* d, detail::Buffer<std::int32_t>& rows, int width)
{
  if (!d || width <= 0)
  {
    return;
  }
  const Index n = static_cast<Index>(rows.size()) / width;
  // Keys travel as doubles: exact below 2^53 (global ids).
  std::vector<double> keys(rows.size(), -1.0);
  std::unordered_map<std::int64_t, std::int32_t> local;
  local.reserve(static_cast<size_t>(n));
  for (Index i = 0; i < n; ++i)
  {
    local.emplace(d->Key(i), static_cast<std::int32_t>(i));
    for (int j = 0; j < width; ++j)
    {
      const std::int32_t v = rows[static_cast<size_t>(i) * width + j];
      keys[static_cast<size_t>(i) * width + j] = v >= 0 ? static_cast<double>(d->Key(v)) : -1.0;
    }
  }
  d->UpdateHalo(keys.data(), width);
  for (Index i = 0; i < n; ++i)
  {
    if (d->Owned(i))
    {
      continue;
    }
    for (int j = 0; j < width; ++j)
    {
      const double key = keys[static_cast<size_t>(i) * width + j];
      const auto found = key >= 0.0 ? local.find(static_cast<std::int64_t>(key)) : local.end();
      rows[static_cast<size_t>(i) * width + j] = found != local.end() ? found->second : -1;
    }
  }
}

void UpdateHaloInOrder(const Distribution* d, const std::vector<Index>& order, Index n,
  std::initializer_list<std::vector<double>*> sorted)
{
  if (!d)
  {
    return;
  }
  const int components = static_cast<int>(sorted.size());
  const size_t nv = order.size();
  std::vector<double> perPoint(static_cast<size_t>(n) * components, 0.0);
  int c = 0;
  for (const std::vector<double>* values : sorted)
  {
    for (size_t s = 0; s < nv; ++s)
    {
      perPoint[static_cast<size_t>(order[s]) * components + c] = (*values)[s];
    }
    ++c;
  }
  d->UpdateHalo(perPoint.data(), components);
  c = 0;
  for (std::vector<double>* values : sorted)
  {
    for (size_t s = 0; s < nv; ++s)
    {
      (*values)[s] = perPoint[static_cast<size_t>(order[s]) * components + c];
    }
    ++c;
  }
}

std::uint64_t CloudSample::Hash(const double x[3])
{
  // splitmix64's finaliser over the three coordinates' bits (+0 and -0 alike).
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (int a = 0; a < 3; ++a)
  {
    const double v = x[a] == 0.0 ? 0.0 : x[a];
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    h ^= bits + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h ^= h >> 30;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 27;
    h *= 0x94d049bb133111ebull;
    h ^= h >> 31;
  }
  return h;
}

void CloudSample::Select(const Distribution* d, const double* xyz, detail::Buffer<Candidate>& candidates, Index count)
{
  // Ties of the hash (distinct positions) by the coordinates: a total order on positions.
  auto before = [xyz](const Candidate& a, const Candidate& b) {
    const double* p = xyz + 3 * a.Point;
    const double* q = xyz + 3 * b.Point;
    return std::tie(a.Hash, p[0], p[1], p[2]) < std::tie(b.Hash, q[0], q[1], q[2]);
  };
  const size_t keep = std::min(candidates.size(), static_cast<size_t>(std::max<Index>(count, 0)));
  std::partial_sort(candidates.begin(), candidates.begin() + keep, candidates.end(), before);
  candidates.resize(keep);
  this->Mine.clear();
  this->Rank.clear();
  if (!d)
  {
    for (size_t r = 0; r < keep; ++r)
    {
      this->Mine.push_back(candidates[r].Point);
      this->Rank.push_back(static_cast<Index>(r));
    }
    this->Total = static_cast<Index>(keep);
    return;
  }
  // Every process' first `count`; the whole sample is the first `count` of their union. A hash travels as two
  // 32-bit halves (exact in doubles).
  std::vector<double> mine, all;
  for (const Candidate& c : candidates)
  {
    const double* p = xyz + 3 * c.Point;
    mine.insert(mine.end(), { static_cast<double>(c.Hash >> 32), static_cast<double>(c.Hash & 0xffffffffull), p[0],
                              p[1], p[2] });
  }
  d->Gather(mine, all);
  const size_t m = all.size() / 5;
  struct Entry
  {
    std::uint64_t Hash;
    double X[3];
  };
  std::vector<Entry> entries(m);
  for (size_t e = 0; e < m; ++e)
  {
    const double* v = &all[5 * e];
    entries[e].Hash = (static_cast<std::uint64_t>(v[0]) << 32) | static_cast<std::uint64_t>(v[1]);
    std::copy(v + 2, v + 5, entries[e].X);
  }
  auto entryBefore = [](const Entry& a, const Entry& b) {
    return std::tie(a.Hash, a.X[0], a.X[1], a.X[2]) < std::tie(b.Hash, b.X[0], b.X[1], b.X[2]);
  };
  const size_t total = std::min(m, static_cast<size_t>(std::max<Index>(count, 0)));
  std::partial_sort(entries.begin(), entries.begin() + total, entries.end(), entryBefore);
  entries.resize(total);
  this->Total = static_cast<Index>(total);
  // This process' candidates among them (positions are distinct among the processes' eligible points), in order.
  for (const Candidate& c : candidates)
  {
    const double* p = xyz + 3 * c.Point;
    const Entry probe{ c.Hash, { p[0], p[1], p[2] } };
    const auto at = std::lower_bound(entries.begin(), entries.end(), probe, entryBefore);
    if (at != entries.end() && !entryBefore(probe, *at))
    {
      this->Mine.push_back(c.Point);
      this->Rank.push_back(static_cast<Index>(at - entries.begin()));
    }
  }
}

std::vector<double> CloudSample::Gather(const Distribution* d, const std::vector<double>& mine) const
{
  if (!d)
  {
    return mine;
  }
  std::vector<double> pairs, all;
  for (size_t j = 0; j < this->Mine.size() && j < mine.size(); ++j)
  {
    pairs.push_back(static_cast<double>(this->Rank[j]));
    pairs.push_back(mine[j]);
  }
  d->Gather(pairs, all);
  std::vector<double> values(static_cast<size_t>(this->Total), 0.0);
  for (size_t e = 0; e + 1 < all.size(); e += 2)
  {
    values[static_cast<size_t>(all[e])] = all[e + 1];
  }
  return values;
}

} // namespace meshfree
