// SPDX-License-Identifier: BSD-3-Clause
// Distance to the data, trimming and supported pieces of a reconstructed surface (DataSupport.h).
#include "Surface/DataSupport.h"

#include "Common/Parallel.h"
#include "Surface/MeshTopology.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace meshfree
{

void DistanceToData(const NeighborGrid& grid, const std::vector<double>& vertices, std::vector<double>& distance,
  std::vector<Index>& nearest, const Distribution* d)
{
  const Index nv = static_cast<Index>(vertices.size() / 3);
  distance.assign(static_cast<size_t>(nv), std::numeric_limits<double>::infinity());
  nearest.assign(static_cast<size_t>(nv), -1);
  if (grid.NumberOfValidPoints() > 0)
  {
    ParallelFor(nv, 1024, [&](Index begin, Index end) {
      for (Index v = begin; v < end; ++v)
      {
        Index id = -1;
        double d2 = 0.0;
        if (grid.FindKNearest(&vertices[3 * v], 1, &id, &d2) == 1)
        {
          distance[v] = std::sqrt(d2);
          nearest[v] = id;
        }
      }
    });
  }
  if (!d)
  {
    return;
  }
  // Vertices far inside a filled hole: their nearest point may lie beyond the halo. Every process searches its own
  // points for all of them; the smallest distance wins (the same bits as the serial search's).
  std::vector<double> far;
  std::vector<Index> farVertices;
  for (Index v = 0; v < nv; ++v)
  {
    if (!(distance[v] <= d->Complete(&vertices[3 * v])))
    {
      far.insert(far.end(), &vertices[3 * v], &vertices[3 * v] + 3);
      farVertices.push_back(v);
    }
  }
  std::vector<double> all;
  d->Gather(far, all);
  const Index nq = static_cast<Index>(all.size() / 3);
  if (nq == 0)
  {
    return;
  }
  std::vector<double> own;
  const std::vector<Index>& order = grid.SortedOrder();
  const double* sorted = grid.SortedPoints();
  for (size_t s = 0; s < order.size(); ++s)
  {
    if (d->Owned(order[s]))
    {
      own.insert(own.end(), sorted + 3 * s, sorted + 3 * s + 3);
    }
  }
  NeighborGrid mine;
  mine.Build(own.data(), static_cast<Index>(own.size() / 3));
  std::vector<double> best(static_cast<size_t>(nq), -std::numeric_limits<double>::infinity());
  ParallelFor(nq, 256, [&](Index begin, Index end) {
    for (Index q = begin; q < end; ++q)
    {
      Index id = -1;
      double d2 = 0.0;
      if (mine.NumberOfValidPoints() > 0 && mine.FindKNearest(&all[3 * q], 1, &id, &d2) == 1)
      {
        best[q] = -std::sqrt(d2);
      }
    }
  });
  d->Max(best.data(), nq);
  // This process' queries are its block of the gathered ones.
  std::vector<double> counts;
  d->Gather(std::vector<double>(1, static_cast<double>(farVertices.size())), counts);
  Index offset = 0;
  for (int r = 0; r < d->Rank(); ++r)
  {
    offset += static_cast<Index>(counts[r]);
  }
  for (size_t k = 0; k < farVertices.size(); ++k)
  {
    const Index v = farVertices[k];
    const double found = -best[static_cast<size_t>(offset) + k];
    if (found < distance[v])
    {
      distance[v] = found;
      nearest[v] = -1;
    }
  }
}

Index KeepTriangles(TriangleMesh& mesh, const std::vector<unsigned char>& keep, const std::vector<VertexAttribute>& attributes)
{
  const Index nt = mesh.NumberOfTriangles();
  const Index nv = mesh.NumberOfPoints();
  std::vector<Index> index(static_cast<size_t>(nv), -1);
  Index kept = 0;
  for (Index t = 0; t < nt; ++t)
  {
    if (!keep[t])
    {
      continue;
    }
    for (int c = 0; c < 3; ++c)
    {
      mesh.Triangles[3 * kept + c] = mesh.Triangles[3 * t + c];
      index[mesh.Triangles[3 * t + c]] = 0;
    }
    ++kept;
  }
  if (kept == nt)
  {
    return 0;
  }
  mesh.Triangles.resize(static_cast<size_t>(3 * kept));
  Index used = 0;
  for (Index v = 0; v < nv; ++v)
  {
    if (index[v] < 0)
    {
      continue;
    }
    index[v] = used;
    std::copy_n(&mesh.Points[3 * v], 3, &mesh.Points[3 * used]);
    for (const VertexAttribute& a : attributes)
    {
      std::copy_n(&(*a.Values)[static_cast<size_t>(a.Components) * v], a.Components,
        &(*a.Values)[static_cast<size_t>(a.Components) * used]);
    }
    ++used;
  }
  mesh.Points.resize(static_cast<size_t>(3 * used));
  for (const VertexAttribute& a : attributes)
  {
    a.Values->resize(static_cast<size_t>(a.Components) * used);
  }
  for (Index& id : mesh.Triangles)
  {
    id = index[id];
  }
  return nt - kept;
}

namespace
{
/// Union-find over n nodes; each set is named by its smallest node.
struct Union
{
  explicit Union(Index n)
    : Parent(static_cast<size_t>(n))
  {
    for (Index i = 0; i < n; ++i)
    {
      this->Parent[i] = i;
    }
  }
  Index Find(Index i)
  {
    while (this->Parent[i] != i)
    {
      this->Parent[i] = this->Parent[this->Parent[i]];
      i = this->Parent[i];
    }
    return i;
  }
  void Join(Index a, Index b)
  {
    a = this->Find(a);
    b = this->Find(b);
    if (a != b)
    {
      this->Parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<Index> Parent;
};

bool PositionBefore(const double* a, const double* b)
{
  return std::lexicographical_compare(a, a + 3, b, b + 3);
}

/// The records of `stride` values each in `all`, ordered by their first `key` values (lexicographically; ties in
/// their order in `all`).
std::vector<size_t> RecordOrder(const std::vector<double>& all, size_t stride, size_t key)
{
  std::vector<size_t> order(all.size() / stride);
  for (size_t k = 0; k < order.size(); ++k)
  {
    order[k] = k;
  }
  std::stable_sort(order.begin(), order.end(), [&all, stride, key](size_t a, size_t b) {
    return std::lexicographical_compare(&all[stride * a], &all[stride * a] + key, &all[stride * b], &all[stride * b] + key);
  });
  return order;
}

/// Joins the nodes of records (`stride` values each in `all`: a position, then a node of `joined`) that stand at the
/// same position: the same seam vertex gathered from two processes.
void JoinSamePositions(const std::vector<double>& all, size_t stride, Union& joined)
{
  const std::vector<size_t> byPosition = RecordOrder(all, stride, 3);
  for (size_t k = 1; k < byPosition.size(); ++k)
  {
    const double* a = &all[stride * byPosition[k - 1]];
    const double* b = &all[stride * byPosition[k]];
    if (std::equal(a, a + 3, b))
    {
      joined.Join(static_cast<Index>(a[3]), static_cast<Index>(b[3]));
    }
  }
}

/// Gaps the limit bridges only part of the way are opened again (TrimmedTriangles): the vertices kept only because
/// samples surround them (bridged[v], farther than their near limit) form connected stretches; a stretch that
/// borders a vertex off the data lies in a gap wider than the limit closes and is dropped with it (on[v] = 0).
/// Distributed (d; collective): stretches are joined across the processes through their seam vertices (within
/// `band` of another process' region; the same point on both sides), and a stretch is dropped on every process
/// when any of its parts borders a vertex off the data.
void OpenPartlyBridgedGaps(const TriangleMesh& mesh, const std::vector<unsigned char>& bridged,
  std::vector<unsigned char>& on, const Distribution* d, double band)
{
  const Index nv = mesh.NumberOfPoints();
  Union joinedVertices(nv);
  std::vector<unsigned char> borders(static_cast<size_t>(nv), 0); // a bridged vertex beside one off the data
  for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    for (int c = 0; c < 3; ++c)
    {
      const Index a = mesh.Triangles[3 * t + c], b = mesh.Triangles[3 * t + (c + 1) % 3];
      if (bridged[a] && bridged[b])
      {
        joinedVertices.Join(a, b);
      }
      else if (bridged[a] != bridged[b])
      {
        const Index inside = bridged[a] ? a : b, other = bridged[a] ? b : a;
        borders[inside] = borders[inside] || !on[other];
      }
    }
  }
  // The stretches numbered in the order of their smallest vertex (a set's name, met first), and whether each
  // borders the off-data region.
  std::vector<Index> stretch(static_cast<size_t>(nv), -1);
  std::vector<unsigned char> open;
  for (Index v = 0; v < nv; ++v)
  {
    if (bridged[v])
    {
      const Index root = joinedVertices.Find(v);
      if (root == v)
      {
        stretch[v] = static_cast<Index>(open.size());
        open.push_back(0);
      }
      stretch[v] = stretch[root];
      open[stretch[v]] = open[stretch[v]] || borders[v];
    }
  }
  if (d)
  {
    // Every process' stretches after the earlier processes'; a seam vertex carries its stretch and whether that
    // stretch borders the off-data region there.
    std::vector<double> counts;
    d->Gather(std::vector<double>(1, static_cast<double>(open.size())), counts);
    Index first = 0, nodes = 0;
    for (size_t r = 0; r < counts.size(); ++r)
    {
      first += static_cast<int>(r) < d->Rank() ? static_cast<Index>(counts[r]) : 0;
      nodes += static_cast<Index>(counts[r]);
    }
    std::vector<double> seam;
    for (Index v = 0; v < nv; ++v)
    {
      if (bridged[v] && !d->OwnsBall(&mesh.Points[3 * v], band))
      {
        seam.insert(seam.end(), &mesh.Points[3 * v], &mesh.Points[3 * v] + 3);
        seam.push_back(static_cast<double>(first + stretch[v]));
        seam.push_back(open[stretch[v]] ? 1.0 : 0.0);
      }
    }
    std::vector<double> all;
    d->Gather(seam, all);
    Union joined(nodes);
    JoinSamePositions(all, 5, joined);
    std::vector<unsigned char> joinedOpen(static_cast<size_t>(nodes), 0);
    for (size_t k = 0; k < all.size() / 5; ++k)
    {
      const Index root = joined.Find(static_cast<Index>(all[5 * k + 3]));
      joinedOpen[root] = joinedOpen[root] || all[5 * k + 4] != 0.0;
    }
    for (size_t q = 0; q < open.size(); ++q)
    {
      open[q] = open[q] || joinedOpen[joined.Find(first + static_cast<Index>(q))];
    }
  }
  for (Index v = 0; v < nv; ++v)
  {
    if (bridged[v] && open[stretch[v]])
    {
      on[v] = 0;
    }
  }
}
} // namespace

std::vector<unsigned char> TrimmedTriangles(const TriangleMesh& mesh, const std::vector<double>& normals,
  const NeighborGrid& grid, const std::vector<double>& distance, const std::vector<double>& near,
  const std::vector<double>& limit, const Distribution* d, double band)
{
  const Index nv = mesh.NumberOfPoints();
  std::vector<unsigned char> on(static_cast<size_t>(nv), 0), bridged(static_cast<size_t>(nv), 0);
  struct Buffers
  {
    std::vector<Index> Positions;
    std::vector<double> Dist2;
  };
  PerThread<Buffers> buffers;
  const double* sorted = grid.SortedPoints();
  ParallelFor(nv, 256, [&](Index begin, Index end) {
    Buffers& b = buffers.Local();
    for (Index v = begin; v < end; ++v)
    {
      if (distance[v] <= near[v])
      {
        on[v] = 1;
        continue;
      }
      if (!(distance[v] <= limit[v]))
      {
        continue;
      }
      const double* x = &mesh.Points[3 * v];
      const double* n = &normals[3 * v];
      grid.FindWithinRadiusPositions(x, 1.5 * limit[v], b.Positions, b.Dist2);
      double mean[3] = { 0.0, 0.0, 0.0 };
      Index count = 0;
      for (size_t j = 0; j < b.Positions.size(); ++j)
      {
        const double* p = sorted + 3 * b.Positions[j];
        double d[3] = { p[0] - x[0], p[1] - x[1], p[2] - x[2] };
        const double along = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
        for (int a = 0; a < 3; ++a)
        {
          d[a] -= along * n[a];
        }
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (len > 0.0)
        {
          for (int a = 0; a < 3; ++a)
          {
            mean[a] += d[a] / len;
          }
          ++count;
        }
      }
      const double spread = count > 0 ? std::sqrt(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]) / count : 1.0;
      on[v] = spread < OneSided ? 1 : 0;
      bridged[v] = on[v];
    }
  });
  OpenPartlyBridgedGaps(mesh, bridged, on, d, band);
  const Index nt = mesh.NumberOfTriangles();
  std::vector<unsigned char> keep(static_cast<size_t>(nt), 1);
  for (Index t = 0; t < nt; ++t)
  {
    keep[t] = on[mesh.Triangles[3 * t]] && on[mesh.Triangles[3 * t + 1]] && on[mesh.Triangles[3 * t + 2]];
  }
  return keep;
}


std::vector<unsigned char> SupportedPieces(const TriangleMesh& mesh, const NeighborGrid& grid,
  const std::vector<double>& sampleLimit, Index minimumSamples, Index& pieces, Index& removedPieces,
  const Distribution* d)
{
  const Index nt = mesh.NumberOfTriangles();
  const Index nv = mesh.NumberOfPoints();
  std::vector<Index> component;
  const Index local = TriangleComponents(mesh.Triangles, nv, component);
  pieces = local;
  removedPieces = 0;
  std::vector<unsigned char> keep(static_cast<size_t>(nt), 1);
  if (!d && (pieces <= 1 || nv == 0))
  {
    return keep; // one piece is always kept (the best-supported one)
  }
  std::vector<Index> vertexPiece(static_cast<size_t>(nv), -1);
  for (Index t = 0; t < nt; ++t)
  {
    for (int c = 0; c < 3; ++c)
    {
      vertexPiece[mesh.Triangles[3 * t + c]] = component[t];
    }
  }
  // Pieces as nodes: this process' local pieces follow the earlier processes' (serial: the local pieces). Each
  // node's smallest vertex by position decides ties of support.
  Index first = 0, nodes = local;
  std::vector<double> smallest(static_cast<size_t>(3 * local), std::numeric_limits<double>::infinity());
  for (Index v = 0; v < nv; ++v)
  {
    const Index p = vertexPiece[v];
    if (p >= 0 && PositionBefore(&mesh.Points[3 * v], &smallest[3 * p]))
    {
      std::copy(&mesh.Points[3 * v], &mesh.Points[3 * v] + 3, &smallest[3 * p]);
    }
  }
  std::vector<double> points(mesh.Points);
  std::vector<Index> pointPiece(vertexPiece);
  std::vector<double> allSmallest(smallest);
  std::vector<Index> root;
  if (d)
  {
    std::vector<double> counts;
    d->Gather(std::vector<double>(1, static_cast<double>(local)), counts);
    nodes = 0;
    for (size_t r = 0; r < counts.size(); ++r)
    {
      first += static_cast<int>(r) < d->Rank() ? static_cast<Index>(counts[r]) : 0;
      nodes += static_cast<Index>(counts[r]);
    }
    d->Gather(smallest, allSmallest);
    // The vertices other processes' samples may find nearest (within the largest limit of this process' region's
    // border) and the seam vertices (on cells of two processes) with their node; gathered by every process.
    double reach = 0.0;
    for (size_t s = 0; s < sampleLimit.size(); ++s)
    {
      reach = std::max(reach, std::isfinite(sampleLimit[s]) ? sampleLimit[s] : 0.0);
    }
    reach = GlobalMax(d, reach);
    std::vector<double> border;
    for (Index v = 0; v < nv; ++v)
    {
      if (vertexPiece[v] >= 0 && !d->OwnsBall(&mesh.Points[3 * v], reach))
      {
        border.insert(border.end(), &mesh.Points[3 * v], &mesh.Points[3 * v] + 3);
        border.push_back(static_cast<double>(first + vertexPiece[v]));
      }
    }
    std::vector<double> all;
    d->Gather(border, all);
    const size_t nb = all.size() / 4;
    // Pieces joined through the seams: the same point on two processes.
    Union joined(nodes);
    JoinSamePositions(all, 4, joined);
    root.resize(static_cast<size_t>(nodes));
    for (Index q = 0; q < nodes; ++q)
    {
      root[q] = joined.Find(q);
    }
    // The other processes' border vertices join the search for the nearest vertex.
    for (size_t b = 0; b < nb; ++b)
    {
      const Index node = static_cast<Index>(all[4 * b + 3]);
      if (node < first || node >= first + local)
      {
        points.insert(points.end(), &all[4 * b], &all[4 * b] + 3);
        pointPiece.push_back(node - first);
      }
    }
  }
  else
  {
    root.resize(static_cast<size_t>(nodes));
    for (Index q = 0; q < nodes; ++q)
    {
      root[q] = q;
    }
  }
  // Each own sample's nearest vertex, through a grid over the vertices.
  NeighborGrid vertices;
  vertices.Build(points.data(), static_cast<Index>(points.size() / 3));
  const std::vector<Index>& order = grid.SortedOrder();
  const double* sorted = grid.SortedPoints();
  const Index ns = static_cast<Index>(order.size());
  std::vector<Index> owner(static_cast<size_t>(ns), -1);
  ParallelFor(ns, 1024, [&](Index begin, Index end) {
    for (Index s = begin; s < end; ++s)
    {
      Index id = -1;
      double d2 = 0.0;
      const double limit = sampleLimit[order[s]];
      if (IsOwn(d, order[s]) && vertices.NumberOfValidPoints() > 0 &&
        vertices.FindKNearest(sorted + 3 * s, 1, &id, &d2) == 1 && d2 <= limit * limit)
      {
        owner[s] = root[first + pointPiece[id]];
      }
    }
  });
  std::vector<std::int64_t> support(static_cast<size_t>(nodes), 0);
  for (Index s = 0; s < ns; ++s)
  {
    if (owner[s] >= 0)
    {
      ++support[owner[s]];
    }
  }
  if (d)
  {
    d->Sum(support.data(), nodes);
  }
  // Per connected piece (named by its smallest node): its support and its smallest vertex.
  Index best = -1;
  std::vector<double> pieceSmallest(static_cast<size_t>(3 * nodes), std::numeric_limits<double>::infinity());
  pieces = 0;
  for (Index q = 0; q < nodes; ++q)
  {
    const Index r = root[q];
    pieces += r == q ? 1 : 0;
    if (PositionBefore(&allSmallest[3 * q], &pieceSmallest[3 * r]))
    {
      std::copy(&allSmallest[3 * q], &allSmallest[3 * q] + 3, &pieceSmallest[3 * r]);
    }
  }
  // The best-supported piece is always kept (a cloud of fewer samples than minimumSamples still has a surface).
  for (Index q = 0; q < nodes; ++q)
  {
    if (root[q] == q &&
      (best < 0 || support[q] > support[best] ||
        (support[q] == support[best] && PositionBefore(&pieceSmallest[3 * q], &pieceSmallest[3 * best]))))
    {
      best = q;
    }
  }
  std::vector<unsigned char> kept(static_cast<size_t>(nodes), 0);
  for (Index q = 0; q < nodes; ++q)
  {
    if (root[q] == q)
    {
      kept[q] = q == best || support[q] >= minimumSamples ? 1 : 0;
      removedPieces += kept[q] ? 0 : 1;
    }
  }
  for (Index t = 0; t < nt; ++t)
  {
    keep[t] = kept[root[first + component[t]]];
  }
  return keep;
}

Index BoundaryEdges(const TriangleMesh& mesh, double band, const Distribution* d)
{
  std::vector<std::pair<Index, Index>> edges;
  edges.reserve(mesh.Triangles.size());
  for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    for (int c = 0; c < 3; ++c)
    {
      const Index a = mesh.Triangles[3 * t + c], b = mesh.Triangles[3 * t + (c + 1) % 3];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  Index inner = 0;
  std::vector<double> seam; // per edge near another region: its two end points, the smaller first
  for (size_t e = 0; e < edges.size();)
  {
    size_t f = e;
    while (f < edges.size() && edges[f] == edges[e])
    {
      ++f;
    }
    if (f - e == 1)
    {
      const double* p = &mesh.Points[3 * edges[e].first];
      const double* q = &mesh.Points[3 * edges[e].second];
      const double middle[3] = { 0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2]) };
      if (!d || d->OwnsBall(middle, band))
      {
        ++inner;
      }
      else
      {
        const bool swap = PositionBefore(q, p);
        seam.insert(seam.end(), swap ? q : p, (swap ? q : p) + 3);
        seam.insert(seam.end(), swap ? p : q, (swap ? p : q) + 3);
      }
    }
    e = f;
  }
  if (!d)
  {
    return inner;
  }
  std::vector<double> all;
  d->Gather(seam, all);
  const size_t n = all.size() / 6;
  const std::vector<size_t> order = RecordOrder(all, 6, 6);
  Index unmatched = 0;
  for (size_t k = 0; k < n;)
  {
    size_t m = k;
    while (m < n && std::equal(&all[6 * order[k]], &all[6 * order[k]] + 6, &all[6 * order[m]]))
    {
      ++m;
    }
    unmatched += (m - k) == 1 ? 1 : 0;
    k = m;
  }
  return GlobalSum(d, inner) + unmatched;
}

} // namespace meshfree
