// SPDX-License-Identifier: BSD-3-Clause
// Minimum-spanning-tree propagation of normal orientation (NormalOrientation.h).
#include "Surface/NormalOrientation.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace meshfree
{

namespace
{
/// Monotone-enough priority queue for Prim's propagation: costs 1 - |cos| in [0, 1] fall into buckets
/// uniform in sqrt(cost) (about the angle: 1024 buckets, 0.08 degrees each near 0), popped lowest first.
/// Lowering a key pushes the point again; the caller skips points already taken (lazy deletion). Against a
/// binary heap: O(1) per operation, and the same tree up to the order of edges within one bucket.
class BucketQueue
{
public:
  static constexpr int Buckets = 1024;
  BucketQueue()
    : Bucket(Buckets)
  {
  }
  bool Empty() const { return this->Queued == 0; }
  void Push(std::int32_t i, float cost)
  {
    const double r = std::sqrt(std::max(0.0, static_cast<double>(cost)));
    const int b = std::min(Buckets - 1, static_cast<int>(r * Buckets));
    this->Bucket[b].push_back(i);
    this->Lowest = std::min(this->Lowest, b);
    ++this->Queued;
  }
  std::int32_t Pop()
  {
    while (this->Bucket[this->Lowest].empty())
    {
      ++this->Lowest;
    }
    const std::int32_t i = this->Bucket[this->Lowest].back();
    this->Bucket[this->Lowest].pop_back();
    --this->Queued;
    return i;
  }

private:
  std::vector<std::vector<std::int32_t>> Bucket;
  int Lowest = 0;
  size_t Queued = 0;
};

inline double Dot(const double* a, const double* b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// The neighbour graph of the valid points, outliers left out (a random normal in the tree would flip the
/// whole subtree beyond it), made symmetric, in compressed rows indexed by sorted position.
void SymmetricGraph(const NormalField& field, const std::vector<Index>& order, const std::vector<std::int32_t>& rank,
  std::vector<Index>& offsets, std::vector<std::int32_t>& adjacent)
{
  const int k = field.GraphDegree;
  const Index nv = static_cast<Index>(order.size());
  offsets.assign(static_cast<size_t>(nv + 1), 0);
  auto edges = [&](auto&& visit) {
    for (Index s = 0; s < nv; ++s)
    {
      const Index id = order[s];
      if (!field.Valid[id] || field.Outlier[id])
      {
        continue;
      }
      for (int j = 0; j < k; ++j)
      {
        const std::int32_t v = field.Graph[static_cast<size_t>(id) * k + j];
        if (v >= 0 && field.Valid[v] && !field.Outlier[v])
        {
          visit(static_cast<std::int32_t>(s), rank[v]);
        }
      }
    }
  };
  edges([&](std::int32_t a, std::int32_t b) {
    ++offsets[a + 1];
    ++offsets[b + 1];
  });
  for (Index s = 0; s < nv; ++s)
  {
    offsets[s + 1] += offsets[s];
  }
  adjacent.resize(static_cast<size_t>(offsets[nv]));
  std::vector<Index> fill(offsets.begin(), offsets.end() - 1);
  edges([&](std::int32_t a, std::int32_t b) {
    adjacent[fill[a]++] = b;
    adjacent[fill[b]++] = a;
  });
}
} // namespace

OrientationReport OrientNormals(const NeighborGrid& grid, NormalField& field, const OrientationOptions& options,
  std::vector<double>& confidence)
{
  OrientationReport report;
  const Index n = static_cast<Index>(field.Valid.size());
  confidence.assign(static_cast<size_t>(n), 0.0);

  if (options.Mode == OrientationMode::Reference && options.Reference)
  {
    for (Index i = 0; i < n; ++i)
    {
      const double* r = options.Reference + 3 * i;
      const double len = std::sqrt(Dot(r, r));
      if (!field.Valid[i] || !(len > 0.0) || !std::isfinite(len))
      {
        continue;
      }
      double* m = &field.Normals[3 * i];
      const double c = Dot(m, r) / len;
      if (c < 0.0)
      {
        m[0] = -m[0];
        m[1] = -m[1];
        m[2] = -m[2];
      }
      confidence[i] = std::fabs(c);
      report.Ambiguous += confidence[i] < 0.5 ? 1 : 0;
    }
    return report;
  }

  // Everything in the grid's sorted order.
  const std::vector<Index>& order = grid.SortedOrder();
  const double* xyz = grid.SortedPoints();
  const Index nv = static_cast<Index>(order.size());
  std::vector<std::int32_t> rank(static_cast<size_t>(n), -1);
  std::vector<double> normals(static_cast<size_t>(3 * nv));
  std::vector<unsigned char> valid(static_cast<size_t>(nv));
  for (Index s = 0; s < nv; ++s)
  {
    rank[order[s]] = static_cast<std::int32_t>(s);
    std::copy(&field.Normals[3 * order[s]], &field.Normals[3 * order[s]] + 3, &normals[3 * s]);
    valid[s] = field.Valid[order[s]] && !field.Outlier[order[s]];
  }
  std::vector<Index> offsets;
  std::vector<std::int32_t> adjacent;
  SymmetricGraph(field, order, rank, offsets, adjacent);
  std::vector<double> sortedConfidence(static_cast<size_t>(nv), 0.0);
  std::vector<unsigned char> done(static_cast<size_t>(nv), 0);
  std::vector<std::int32_t> parent(static_cast<size_t>(nv), -1);
  std::vector<float> key(static_cast<size_t>(nv), std::numeric_limits<float>::infinity());
  std::vector<std::int32_t> members;
  BucketQueue heap;
  for (Index seed = 0; seed < nv; ++seed)
  {
    if (!valid[seed] || done[seed])
    {
      continue;
    }
    ++report.Components;
    members.clear();
    heap.Push(static_cast<std::int32_t>(seed), 0.0f);
    key[seed] = 0.0f;
    while (!heap.Empty())
    {
      const std::int32_t u = heap.Pop();
      if (done[u])
      {
        continue; // an entry left behind when its key was lowered
      }
      done[u] = 1;
      members.push_back(u);
      double* nu = &normals[3 * u];
      if (parent[u] >= 0)
      {
        const double c = Dot(nu, &normals[3 * parent[u]]);
        if (c < 0.0)
        {
          nu[0] = -nu[0];
          nu[1] = -nu[1];
          nu[2] = -nu[2];
        }
        sortedConfidence[u] = std::fabs(c);
      }
      else
      {
        sortedConfidence[u] = 1.0;
      }
      for (Index e = offsets[u]; e < offsets[u + 1]; ++e)
      {
        const std::int32_t v = adjacent[e];
        if (done[v])
        {
          continue;
        }
        const float cost = static_cast<float>(1.0 - std::fabs(Dot(nu, &normals[3 * v])));
        if (cost < key[v])
        {
          key[v] = cost;
          parent[v] = u;
          heap.Push(v, cost);
        }
      }
    }
    // The component as a whole: outward (or towards the viewpoint).
    double centre[3] = { 0.0, 0.0, 0.0 };
    if (options.Mode == OrientationMode::Viewpoint)
    {
      std::copy(options.Viewpoint, options.Viewpoint + 3, centre);
    }
    else
    {
      // Relative to the seed, so that clouds far from the origin keep their precision.
      const double* o = xyz + 3 * seed;
      for (std::int32_t m : members)
      {
        for (int a = 0; a < 3; ++a)
        {
          centre[a] += xyz[3 * m + a] - o[a];
        }
      }
      for (int a = 0; a < 3; ++a)
      {
        centre[a] = o[a] + centre[a] / static_cast<double>(members.size());
      }
    }
    double flux = 0.0;
    for (std::int32_t m : members)
    {
      const double d[3] = { xyz[3 * m] - centre[0], xyz[3 * m + 1] - centre[1], xyz[3 * m + 2] - centre[2] };
      flux += Dot(&normals[3 * m], d);
    }
    const bool flip = options.Mode == OrientationMode::Viewpoint ? flux > 0.0 : flux < 0.0;
    if (flip)
    {
      ++report.FlippedComponents;
      for (std::int32_t m : members)
      {
        for (int a = 0; a < 3; ++a)
        {
          normals[3 * m + a] = -normals[3 * m + a];
        }
      }
    }
  }
  for (Index s = 0; s < nv; ++s)
  {
    const Index id = order[s];
    std::copy(&normals[3 * s], &normals[3 * s] + 3, &field.Normals[3 * id]);
    confidence[id] = valid[s] ? sortedConfidence[s] : 0.0;
    report.Ambiguous += valid[s] && sortedConfidence[s] < 0.5 ? 1 : 0;
  }
  // Outliers follow their nearest oriented neighbour.
  const int k = field.GraphDegree;
  for (Index i = 0; i < n; ++i)
  {
    if (!field.Valid[i] || !field.Outlier[i])
    {
      continue;
    }
    for (int j = 0; j < k; ++j)
    {
      const std::int32_t v = field.Graph[static_cast<size_t>(i) * k + j];
      if (v >= 0 && field.Valid[v] && !field.Outlier[v])
      {
        double* m = &field.Normals[3 * i];
        const double c = Dot(m, &field.Normals[3 * v]);
        if (c < 0.0)
        {
          m[0] = -m[0];
          m[1] = -m[1];
          m[2] = -m[2];
        }
        confidence[i] = std::fabs(c);
        break;
      }
    }
    report.Ambiguous += confidence[i] < 0.5 ? 1 : 0;
  }
  return report;
}

} // namespace meshfree
