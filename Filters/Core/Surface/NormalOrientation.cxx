// SPDX-License-Identifier: BSD-3-Clause
// Minimum-spanning-tree propagation of normal orientation (NormalOrientation.h).
#include "Surface/NormalOrientation.h"

#include "Common/LargeArrays.h"
#include "Common/Parallel.h"

#include <algorithm>
#include <array>
#include <tuple>
#include <cmath>
#include <cstdint>
#include <limits>

namespace meshfree
{

namespace
{
/// The largest cost 1 - |cos| of an edge followed inside a block (45 degrees). Neighbours on a smooth surface
/// differ by far less; a sharp ridge's two faces (normals 100-150 degrees apart) passed the earlier 60 degrees as
/// "nearly opposite, turn one" and Prim's single edge turned one face of the block. Measured (issue 23): on the
/// dragon scan 1.7 % of the samples pointed inward with 60 degrees, 0.8 % with 45, 0.6 % with 30; on noise-free
/// prisms with 40- and 80-degree ridges (TestSurfaceNormals) 0.996 / 0.968 outward with 60, 0.996 / 0.996 with 45
/// and 30; with noise (0.125 % of the diagonal) 0.65 / 0.79 with 60, 0.63 / 0.78 with 45, 0.50 / 0.58 with 30, all
/// before the jets' own normals were propagated instead of the sharp features' donors (OrientNormals): 0.950 / 0.970.
constexpr float kBlockEdgeCost = 0.2928932f; // 1 - cos(45 degrees)

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

/// How far two normals agree as normals of one smooth surface through their points, for the votes between nodes:
/// n_j against n_i reflected in the plane that bisects the chord e = p_j - p_i, n_i . n_j - 2 (n_i . e)(n_j . e) /
/// |e|^2, the relation of two consistently oriented normals on a circular arc through both points (the arc
/// consistency of König & Gumhold 2009, "Consistent propagation of normal orientations in point clouds"). Along a
/// gently curved surface (e in the tangent planes) it is n_i . n_j; across a ridge or a part thinner than the
/// neighbourhood (e across the normals) it is about +1 where n_i . n_j is near -1, so a sharp ridge's faces are not
/// turned to agree. The components of e along the normals are first shrunk by `noise` (the cloud's spread about the
/// surface), so that noise and layered views do not read as curvature.
inline double ArcAgreement(const double* ni, const double* nj, const double* pi, const double* pj, double noise)
{
  const double e[3] = { pj[0] - pi[0], pj[1] - pi[1], pj[2] - pi[2] };
  const double e2 = Dot(e, e);
  const double c = Dot(ni, nj);
  if (!(e2 > 0.0))
  {
    return c;
  }
  auto shrink = [noise](double a) { return a > noise ? a - noise : (a < -noise ? a + noise : 0.0); };
  const double a = shrink(Dot(ni, e));
  const double b = shrink(Dot(nj, e));
  return c - 2.0 * a * b / e2;
}

/// A piece of the orientation: component c of the block with key Block (BlockKey).
struct Node
{
  std::uint64_t Block = 0;
  std::int64_t Component = 0;
  bool operator<(const Node& o) const { return std::tie(this->Block, this->Component) < std::tie(o.Block, o.Component); }
  bool operator==(const Node& o) const { return this->Block == o.Block && this->Component == o.Component; }
  /// As three doubles (exact: the key's two 32-bit halves and the component), for the processes' exchanges.
  void Write(double* out) const
  {
    out[0] = static_cast<double>(this->Block >> 32);
    out[1] = static_cast<double>(this->Block & 0xffffffffull);
    out[2] = static_cast<double>(this->Component);
  }
  static Node Read(const double* in)
  {
    return Node{ (static_cast<std::uint64_t>(in[0]) << 32) | static_cast<std::uint64_t>(in[1]),
      static_cast<std::int64_t>(in[2]) };
  }
};

/// Blocks: cubes of edge `edge` anchored at the frame's minimum (the whole cloud's, NeighborGrid::SetFrame), keyed
/// by their three 21-bit coordinates.
struct Blocks
{
  double Origin[3] = { 0.0, 0.0, 0.0 };
  double Inverse = 1.0;
  std::uint64_t Key(const double* x) const
  {
    std::uint64_t key = 0;
    for (int a = 0; a < 3; ++a)
    {
      const double t = (x[a] - this->Origin[a]) * this->Inverse;
      const std::uint64_t c = t > 0.0 ? std::min<std::uint64_t>(static_cast<std::uint64_t>(t), (1u << 21) - 1) : 0;
      key = (key << 21) | c;
    }
    return key;
  }
};

/// A node's sums over its own points, positions relative to the blocks' origin: count, x (3), the turned normal n
/// (3), n . x, x . x.
constexpr int kSums = 9;
using NodeSums = std::array<double, kSums>;

/// Votes (c . 2^24, rounded: integer sums are exact in any order) of the graph edges between two nodes.
constexpr double VoteScale = 16777216.0;

/// A weak link: two nodes whose summed votes are below this many agreeing edges' (|sum c| < 10). A piece of the
/// cloud that such links alone tie to the rest (a part seen by other views, reached across a sparse strip) is
/// oriented on its own when it is an anchor, at least kAnchorPoints points: on the dragon scan one side of a
/// limb (18,000 samples, 4 % of the cloud) hung on a chain of nodes of 2-8 points with votes of 1-8, and a single
/// wrong vote there turned the whole side inward.
constexpr std::int64_t kWeakLink = static_cast<std::int64_t>(10 * VoteScale);
constexpr double kAnchorPoints = 2000.0;

/// A piece's flux about a centre (relative to the blocks' origin): sum_i n_i . (x_i - c) = sum n.x - c . sum n.
double FluxAbout(const NodeSums& piece, const double centre[3])
{
  return piece[7] - (centre[0] * piece[4] + centre[1] * piece[5] + centre[2] * piece[6]);
}

/// A piece's centroid (relative to the blocks' origin).
void Centroid(const NodeSums& piece, double centre[3])
{
  for (int a = 0; a < 3; ++a)
  {
    centre[a] = piece[1 + a] / std::max(piece[0], 1.0);
  }
}

/// Whether a piece's own flux about its centroid, |sum n . (x - c)|, decides its side: at least a quarter of
/// N x its rms radius (1 for a closed sphere, about 0.6 for half a cylinder as long as wide; a flat face's is its
/// noise, and such a face, a cube's or a prism's, is no anchor: it follows its links).
bool OwnFluxDecides(const NodeSums& piece)
{
  double c[3];
  Centroid(piece, c);
  const double count = std::max(piece[0], 1.0);
  const double radius = std::sqrt(std::max(piece[8] / count - Dot(c, c), 0.0));
  return std::fabs(FluxAbout(piece, c)) >= 0.25 * count * radius;
}

/// Union-find with the parity of each element relative to its set's root (Kruskal over the nodes).
class ParityForest
{
public:
  explicit ParityForest(size_t n)
    : Parent(n)
    , Parity(n, 0)
  {
    for (size_t i = 0; i < n; ++i)
    {
      this->Parent[i] = i;
    }
  }
  /// The root of i, and i's parity relative to it.
  size_t Find(size_t i, int& parity)
  {
    parity = 0;
    size_t r = i;
    while (this->Parent[r] != r)
    {
      parity ^= this->Parity[r];
      r = this->Parent[r];
    }
    // Path compression, keeping parities relative to the root.
    int p = parity;
    while (this->Parent[i] != r && this->Parent[i] != i)
    {
      const size_t next = this->Parent[i];
      const int own = this->Parity[i];
      this->Parent[i] = r;
      this->Parity[i] = p;
      p ^= own;
      i = next;
    }
    return r;
  }
  /// Joins the sets of a and b so that parity(a) ^ parity(b) == relation; false when already joined. The smaller
  /// root stays the root (the result depends on the edges only, not on their order of equal weight).
  bool Join(size_t a, size_t b, int relation)
  {
    int pa, pb;
    const size_t ra = this->Find(a, pa);
    const size_t rb = this->Find(b, pb);
    if (ra == rb)
    {
      return false;
    }
    const size_t root = std::min(ra, rb), child = std::max(ra, rb);
    this->Parent[child] = root;
    this->Parity[child] = pa ^ pb ^ relation;
    return true;
  }

private:
  std::vector<size_t> Parent;
  std::vector<int> Parity;
};

/// Blocks of the propagation: this many times the median distance to the NeighborCount-th neighbour (about ten
/// spacings: a few hundred points of a surface per block).
constexpr double BlockNeighborhoods = 4.0;

/// The nodes of the blocks oriented here (sorted, each once) and their sums over own points -> every process'
/// nodes, each once, sums added (in gathered order: process by process); nodes sorted.
void ReduceNodes(const Distribution* d, const std::vector<Node>& localNodes,
  const std::vector<NodeSums>& localSums, std::vector<Node>& nodes, std::vector<NodeSums>& sums)
{
  if (!d)
  {
    nodes = localNodes;
    sums = localSums;
    return;
  }
  constexpr size_t width = 3 + kSums; // the node (3 doubles) and its sums
  std::vector<double> mine(width * localNodes.size()), all;
  for (size_t m = 0; m < localNodes.size(); ++m)
  {
    localNodes[m].Write(&mine[width * m]);
    std::copy(localSums[m].begin(), localSums[m].end(), &mine[width * m + 3]);
  }
  d->Gather(mine, all);
  std::vector<std::pair<Node, NodeSums>> entries;
  for (size_t e = 0; e + width <= all.size(); e += width)
  {
    NodeSums values;
    std::copy(&all[e + 3], &all[e + width], values.begin());
    entries.push_back({ Node::Read(&all[e]), values });
  }
  std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  nodes.clear();
  sums.clear();
  for (const auto& e : entries)
  {
    if (nodes.empty() || !(nodes.back() == e.first))
    {
      nodes.push_back(e.first);
      sums.push_back(e.second);
      continue;
    }
    for (int c = 0; c < kSums; ++c)
    {
      sums.back()[c] += e.second[c];
    }
  }
}

/// Votes (a, b, q) sorted and summed per pair (q: integers, exact in any order), appended to `links` (or
/// replacing them).
void SumVotes(std::vector<std::tuple<Node, Node, std::int64_t>>& votes,
  std::vector<std::tuple<Node, Node, std::int64_t>>& links, bool append)
{
  std::sort(votes.begin(), votes.end());
  if (!append)
  {
    links.clear();
  }
  const size_t first = links.size();
  for (const auto& v : votes)
  {
    if (links.size() > first && std::get<0>(links.back()) == std::get<0>(v) &&
      std::get<1>(links.back()) == std::get<1>(v))
    {
      std::get<2>(links.back()) += std::get<2>(v);
    }
    else
    {
      links.push_back(v);
    }
  }
}

/// Votes (a, b, q) -> one per pair, q added, every process' included; pairs sorted.
void ReduceVotes(const Distribution* d, std::vector<std::tuple<Node, Node, std::int64_t>>& votes,
  std::vector<std::tuple<Node, Node, std::int64_t>>& links)
{
  SumVotes(votes, links, false);
  if (!d)
  {
    return;
  }
  std::vector<double> mine(7 * links.size()), all;
  for (size_t l = 0; l < links.size(); ++l)
  {
    std::get<0>(links[l]).Write(&mine[7 * l]);
    std::get<1>(links[l]).Write(&mine[7 * l + 3]);
    mine[7 * l + 6] = static_cast<double>(std::get<2>(links[l]));
  }
  d->Gather(mine, all);
  votes.clear();
  for (size_t e = 0; e + 7 <= all.size(); e += 7)
  {
    votes.emplace_back(Node::Read(&all[e]), Node::Read(&all[e + 3]), static_cast<std::int64_t>(all[e + 6]));
  }
  SumVotes(votes, links, false);
}

/// OrientNormals over field.Normals as they are.
OrientationReport OrientGivenNormals(const NeighborGrid& grid, NormalField& field, const OrientationOptions& options,
  std::vector<double>& confidence)
{
  OrientationReport report;
  const Index n = static_cast<Index>(field.Valid.size());
  detail::AssignLarge(confidence, static_cast<size_t>(n), 0.0);
  const Distribution* d = options.Processes;


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
      report.Ambiguous += confidence[i] < 0.5 && IsOwn(d, i) ? 1 : 0;
    }
    report.Ambiguous = GlobalSum(d, report.Ambiguous);
    return report;
  }

  const std::vector<Index>& order = grid.SortedOrder();
  const double* xyz = grid.SortedPoints();
  const Index nv = static_cast<Index>(order.size());
  const int k = field.GraphDegree;
  const double noise = std::max(field.Scale.Noise, field.Scale.FitNoise); // the same on every process
  // The per-point arrays below on huge pages (detail::Buffer, Common/LargeArrays.h): fresh pages' faults were a
  // large part of the orientation's time.
  detail::Buffer<std::int32_t> rank(static_cast<size_t>(n), -1);
  detail::Buffer<double> normals(static_cast<size_t>(3 * nv), 0.0);
  detail::Buffer<unsigned char> valid(static_cast<size_t>(nv), 0);
  detail::Buffer<double> sortedDistance(static_cast<size_t>(nv), 0.0);
  // In parallel (the reads by original index miss the cache: serially a third of the orientation's time at 1M
  // points), then the own valid points' r_k listed in sorted order as before.
  ParallelFor(nv, 4096, [&](Index b0, Index b1) {
    for (Index s = b0; s < b1; ++s)
    {
      const Index id = order[s];
      rank[id] = static_cast<std::int32_t>(s);
      std::copy(&field.Normals[3 * id], &field.Normals[3 * id] + 3, &normals[3 * s]);
      valid[s] = field.Valid[id] && !field.Outlier[id];
      sortedDistance[s] = field.NeighborDistance[id];
    }
  });
  std::vector<double> distances;
  detail::ReserveLarge(distances, static_cast<size_t>(nv));
  for (Index s = 0; s < nv; ++s)
  {
    if (valid[s] && IsOwn(d, order[s]))
    {
      distances.push_back(sortedDistance[s]);
    }
  }
  detail::Buffer<double>().swap(sortedDistance);

  // The blocks: BlockNeighborhoods x the median r_k of the whole cloud, over the frame's cells.
  double frame[6];
  Index framePoints = 0;
  grid.GetFrame(frame, framePoints);
  const double extent = std::max({ frame[1] - frame[0], frame[3] - frame[2], frame[5] - frame[4], 0.0 });
  double edge = std::max(BlockNeighborhoods * GlobalMedian(d, std::move(distances)), extent / (1 << 20));
  if (!(edge > 0.0) || !std::isfinite(edge))
  {
    edge = extent > 0.0 && std::isfinite(extent) ? extent : 1.0;
  }
  Blocks blocks;
  for (int a = 0; a < 3; ++a)
  {
    blocks.Origin[a] = std::isfinite(frame[2 * a]) ? frame[2 * a] : 0.0;
  }
  blocks.Inverse = 1.0 / edge;
  detail::Buffer<std::uint64_t> blockOf(static_cast<size_t>(nv), 0);
  ParallelFor(nv, 4096, [&](Index b0, Index b1) {
    for (Index s = b0; s < b1; ++s)
    {
      blockOf[s] = valid[s] ? blocks.Key(xyz + 3 * s) : 0;
    }
  });
  // The blocks holding an own point: oriented here. Sorted points near in memory share their block: a key is
  // listed when it differs from the last one listed, then sorted and made unique (the same list as every own
  // point's key sorted, at a fraction of the cost).
  std::vector<std::uint64_t> wanted;
  for (Index s = 0; s < nv; ++s)
  {
    if (valid[s] && IsOwn(d, order[s]))
    {
      if (wanted.empty() || wanted.back() != blockOf[s])
      {
        wanted.push_back(blockOf[s]);
      }
      // The whole block lies within its diagonal of the point.
      if (d)
      {
        report.Shortfall = std::max(report.Shortfall, Shortfall(d, xyz + 3 * s, edge * std::sqrt(3.0)));
      }
    }
  }
  std::sort(wanted.begin(), wanted.end());
  wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
  // Their points, block by block, each block's in sorted order: (block key, sorted position) ascending, by a
  // counting sort over the blocks' indices in `wanted` (-1: not a wanted block).
  detail::Buffer<std::int32_t> blockIndex(static_cast<size_t>(nv), -1);
  ParallelFor(nv, 4096, [&](Index b0, Index b1) {
    std::uint64_t lastKey = 0;
    std::int32_t last = -2; // none looked up yet
    for (Index s = b0; s < b1; ++s)
    {
      if (!valid[s])
      {
        continue;
      }
      if (last == -2 || blockOf[s] != lastKey)
      {
        const auto at = std::lower_bound(wanted.begin(), wanted.end(), blockOf[s]);
        last = at != wanted.end() && *at == blockOf[s] ? static_cast<std::int32_t>(at - wanted.begin()) : -1;
        lastKey = blockOf[s];
      }
      blockIndex[s] = last;
    }
  });
  std::vector<size_t> blockBegin(wanted.size() + 1, 0);
  detail::Buffer<unsigned char> inBlock(static_cast<size_t>(nv), 0);
  for (Index s = 0; s < nv; ++s)
  {
    if (blockIndex[s] >= 0)
    {
      ++blockBegin[blockIndex[s] + 1];
      inBlock[s] = 1;
    }
  }
  for (size_t b = 0; b < wanted.size(); ++b)
  {
    blockBegin[b + 1] += blockBegin[b];
  }
  // (Sorted positions only, 4 bytes each: the block is known by its range in blockBegin.)
  detail::Buffer<std::int32_t> members(blockBegin.back(), 0);
  {
    std::vector<size_t> fill(blockBegin.begin(), blockBegin.end() - 1);
    for (Index s = 0; s < nv; ++s)
    {
      if (blockIndex[s] >= 0)
      {
        members[fill[blockIndex[s]]++] = static_cast<std::int32_t>(s);
      }
    }
  }
  detail::Buffer<std::int32_t>().swap(blockIndex);

  // The graph's edges inside each block, symmetric, in compressed rows by sorted position (visited in sorted
  // order: a block's lists are the same on every process that holds the block).
  detail::Buffer<Index> offsets(static_cast<size_t>(nv + 1), 0);
  // A chunk of sorted positions at a time: each point's graph neighbours in its block (as sorted positions, -1 when
  // not) found in parallel (reads by original index, which miss the cache), then visited in order.
  const Index edgeChunk = 65536;
  detail::Buffer<std::int32_t> linked(static_cast<size_t>(std::min(nv, edgeChunk)) * static_cast<size_t>(k), 0);
  auto edges = [&](auto&& visit) {
    for (Index c0 = 0; c0 < nv; c0 += edgeChunk)
    {
      const Index c1 = std::min(nv, c0 + edgeChunk);
      ParallelFor(c1 - c0, 1024, [&](Index b0, Index b1) {
        for (Index s = c0 + b0; s < c0 + b1; ++s)
        {
          std::int32_t* row = &linked[static_cast<size_t>(s - c0) * k];
          const Index id = order[s];
          for (int j = 0; j < k; ++j)
          {
            const std::int32_t v = inBlock[s] ? field.Graph[static_cast<size_t>(id) * k + j] : -1;
            const std::int32_t t = v >= 0 ? rank[v] : -1;
            row[j] = t >= 0 && inBlock[t] && blockOf[t] == blockOf[s] ? t : -1;
          }
        }
      });
      for (Index s = c0; s < c1; ++s)
      {
        const std::int32_t* row = &linked[static_cast<size_t>(s - c0) * k];
        for (int j = 0; j < k; ++j)
        {
          if (row[j] >= 0)
          {
            visit(static_cast<std::int32_t>(s), row[j]);
          }
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
  detail::Buffer<std::int32_t> adjacent(static_cast<size_t>(offsets[nv]), 0);
  {
    detail::Buffer<Index> fill(offsets.begin(), offsets.end() - 1);
    edges([&](std::int32_t a, std::int32_t b) {
      adjacent[fill[a]++] = b;
      adjacent[fill[b]++] = a;
    });
  }
  detail::Buffer<std::int32_t>().swap(linked);
  // (The positions by id stay: the votes read their neighbours' positions, the halo's too.)
  detail::Buffer<unsigned char>().swap(inBlock);
  detail::Buffer<unsigned char>().swap(valid);

  // Prim's propagation inside each block (blocks in parallel): components numbered in the block from its first
  // point in sorted order. Only edges whose normals agree up to sign within 45 degrees (kBlockEdgeCost) are
  // followed: a block across a sharp crease (a cube's edge, a ridge) would otherwise turn one side by the sign of a
  // single ambiguous pair; the crease's sides become separate nodes, joined by the nodes' summed votes, strongest first.
  detail::Buffer<double> sortedConfidence(static_cast<size_t>(nv), 0.0);
  detail::Buffer<unsigned char> done(static_cast<size_t>(nv), 0);
  detail::Buffer<std::int32_t> parent(static_cast<size_t>(nv), -1);
  detail::Buffer<std::int32_t> component(static_cast<size_t>(nv), -1);
  detail::Buffer<float> key(static_cast<size_t>(nv), std::numeric_limits<float>::infinity());
  std::vector<std::int64_t> blockComponents(wanted.size(), 0);
  PerThread<BucketQueue> queues;
  ParallelFor(static_cast<Index>(wanted.size()), 1, [&](Index b0, Index b1) {
    BucketQueue& heap = queues.Local();
    for (Index b = b0; b < b1; ++b)
    {
      std::int64_t count = 0;
      for (size_t m = blockBegin[b]; m < blockBegin[b + 1]; ++m)
      {
        const std::int32_t seed = members[m];
        if (done[seed])
        {
          continue;
        }
        heap.Push(seed, 0.0f);
        key[seed] = 0.0f;
        while (!heap.Empty())
        {
          const std::int32_t u = heap.Pop();
          if (done[u])
          {
            continue; // an entry left behind when its key was lowered
          }
          done[u] = 1;
          component[u] = static_cast<std::int32_t>(count);
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
            if (cost < key[v] && cost <= kBlockEdgeCost)
            {
              key[v] = cost;
              parent[v] = u;
              heap.Push(v, cost);
            }
          }
        }
        ++count;
      }
      blockComponents[b] = count;
    }
  });
  // The propagation's graph and queues go before the nodes' state and votes are allocated.
  detail::Buffer<std::int32_t>().swap(adjacent);
  detail::Buffer<Index>().swap(offsets);
  detail::Buffer<float>().swap(key);
  detail::Buffer<unsigned char>().swap(done);
  detail::Buffer<std::int32_t>().swap(parent);
  // The nodes of the blocks oriented here, numbered block by block (sorted: blocks, then components).
  std::vector<size_t> nodeBegin(wanted.size() + 1, 0);
  for (size_t b = 0; b < wanted.size(); ++b)
  {
    nodeBegin[b + 1] = nodeBegin[b] + static_cast<size_t>(blockComponents[b]);
  }

  // Per point: whether the propagation turned it (-1 or 1; 0: no node) and its node (block, component). Serially
  // from the blocks' arrays; distributed, in `state` (the halo's from their owners).
  std::vector<double> state(d ? static_cast<size_t>(4 * n) : 0, 0.0);
  auto turnedInBlock = [&](Index s) { return Dot(&normals[3 * s], &field.Normals[3 * order[s]]) < 0.0; };
  ParallelFor(d ? nv : 0, 4096, [&](Index b0, Index b1) {
    for (Index s = b0; s < b1; ++s)
    {
      if (component[s] >= 0)
      {
        double* st = &state[4 * order[s]];
        st[0] = turnedInBlock(s) ? -1.0 : 1.0;
        Node{ blockOf[s], component[s] }.Write(st + 1);
      }
    }
  });
  UpdateHalo(d, state, 4);
  auto hasNode = [&](Index id) { return d ? state[4 * id] != 0.0 : rank[id] >= 0 && component[rank[id]] >= 0; };
  auto nodeOf = [&](Index id) {
    return d ? Node::Read(&state[4 * id + 1]) : Node{ blockOf[rank[id]], component[rank[id]] };
  };
  auto signOf = [&](Index id) { return d ? state[4 * id] : (turnedInBlock(rank[id]) ? -1.0 : 1.0); };

  // Each node's sums over own points (count, position relative to the blocks' origin, turned normal, n . x) and
  // the votes of the graph's edges between nodes (n_i . n_j rounded to integers: exact sums in any order), block
  // by block in parallel.
  std::vector<Node> localNodes(nodeBegin.back());
  std::vector<NodeSums> localSums(nodeBegin.back(), NodeSums{});
  struct Votes
  {
    std::vector<std::tuple<Node, Node, std::int64_t>> Block, Kept; // one block's, and the reduced ones
  };
  PerThread<Votes> threadVotes;
  ParallelFor(static_cast<Index>(wanted.size()), 4, [&](Index b0, Index b1) {
    Votes& mine = threadVotes.Local();
    std::vector<std::tuple<Node, Node, std::int64_t>>& votes = mine.Block;
    for (Index b = b0; b < b1; ++b)
    {
      votes.clear();
      for (std::int64_t c = 0; c < blockComponents[b]; ++c)
      {
        localNodes[nodeBegin[b] + c] = Node{ wanted[b], c };
      }
      for (size_t m = blockBegin[b]; m < blockBegin[b + 1]; ++m)
      {
        const std::int32_t s = members[m];
        const Index id = order[s];
        if (!IsOwn(d, id))
        {
          continue;
        }
        const Node a{ wanted[b], component[s] };
        const double x[3] = { xyz[3 * s] - blocks.Origin[0], xyz[3 * s + 1] - blocks.Origin[1],
          xyz[3 * s + 2] - blocks.Origin[2] };
        const double* ni = &normals[3 * s];
        NodeSums& sum = localSums[nodeBegin[b] + component[s]];
        const double add[kSums] = { 1.0, x[0], x[1], x[2], ni[0], ni[1], ni[2], Dot(ni, x), Dot(x, x) };
        for (int c = 0; c < kSums; ++c)
        {
          sum[c] += add[c];
        }
        for (int j = 0; j < k; ++j)
        {
          const std::int32_t v = field.Graph[static_cast<size_t>(id) * k + j];
          if (v < 0 || !hasNode(v))
          {
            continue;
          }
          const Node other = nodeOf(v);
          if (other == a)
          {
            continue;
          }
          const double c = signOf(v) *
            ArcAgreement(ni, &field.Normals[3 * static_cast<size_t>(v)], xyz + 3 * s, xyz + 3 * static_cast<size_t>(rank[v]), noise);
          votes.emplace_back(std::min(a, other), std::max(a, other), std::llround(c * VoteScale));
        }
      }
      // A block's edges vote for a few dozen pairs: reduced here (integer sums), the memory stays per block.
      SumVotes(votes, mine.Kept, true);
    }
  });
  std::vector<std::tuple<Node, Node, std::int64_t>> votes;
  for (const Votes& mine : threadVotes)
  {
    votes.insert(votes.end(), mine.Kept.begin(), mine.Kept.end());
  }
  // Reduced here, then over the processes (every process gets the same node list and votes).
  std::vector<Node> nodes;
  std::vector<NodeSums> sums;
  std::vector<std::tuple<Node, Node, std::int64_t>> links;
  ReduceNodes(d, localNodes, localSums, nodes, sums);
  ReduceVotes(d, votes, links);

  // The nodes' relative turns: a maximum spanning forest of the votes (Kruskal; the strongest agreement or
  // disagreement first, ties by the nodes), each node's parity relative to its tree's root.
  std::sort(links.begin(), links.end(), [](const auto& a, const auto& b) {
    const std::int64_t wa = std::llabs(std::get<2>(a)), wb = std::llabs(std::get<2>(b));
    return wa != wb ? wa > wb : std::tie(std::get<0>(a), std::get<1>(a)) < std::tie(std::get<0>(b), std::get<1>(b));
  });
  ParityForest forest(nodes.size());
  auto indexOf = [&nodes](const Node& x) {
    return static_cast<size_t>(std::lower_bound(nodes.begin(), nodes.end(), x) - nodes.begin());
  };
  // Strong links first (Kruskal, as sorted); the anchors found then are turned outward by themselves, and the weak
  // links join the rest without ever joining two anchors: a small piece follows its strongest link, a large one
  // its own flux.
  for (const auto& link : links)
  {
    if (std::llabs(std::get<2>(link)) >= kWeakLink)
    {
      forest.Join(indexOf(std::get<0>(link)), indexOf(std::get<1>(link)), std::get<2>(link) < 0 ? 1 : 0);
    }
  }
  std::vector<size_t> root(nodes.size());
  std::vector<int> parity(nodes.size());
  std::vector<NodeSums> pieces;
  auto sumPieces = [&]() {
    pieces.assign(nodes.size(), NodeSums{});
    for (size_t m = 0; m < nodes.size(); ++m)
    {
      root[m] = forest.Find(m, parity[m]);
      const double sign = parity[m] ? -1.0 : 1.0;
      NodeSums& piece = pieces[root[m]];
      for (int c = 0; c < kSums; ++c)
      {
        piece[c] += (c >= 4 && c < 8 ? sign : 1.0) * sums[m][c]; // the normals' sums turn with the node
      }
    }
  };
  // Whether a piece is turned as a whole: outward, or towards the viewpoint.
  auto turnPiece = [&](const NodeSums& piece) {
    double centre[3];
    if (options.Mode == OrientationMode::Viewpoint)
    {
      for (int a = 0; a < 3; ++a)
      {
        centre[a] = options.Viewpoint[a] - blocks.Origin[a];
      }
      return FluxAbout(piece, centre) > 0.0;
    }
    Centroid(piece, centre);
    return FluxAbout(piece, centre) < 0.0;
  };
  sumPieces();
  std::vector<int> anchorTurn(nodes.size(), -1); // per anchor's root after the strong links: its turn
  std::vector<unsigned char> anchored(nodes.size(), 0); // per root: holds an anchor
  for (size_t m = 0; m < nodes.size(); ++m)
  {
    if (root[m] == m && pieces[m][0] >= kAnchorPoints && OwnFluxDecides(pieces[m]))
    {
      anchorTurn[m] = turnPiece(pieces[m]) ? 1 : 0;
      anchored[m] = 1;
    }
  }
  for (const auto& link : links)
  {
    const std::int64_t vote = std::get<2>(link);
    if (vote == 0 || std::llabs(vote) >= kWeakLink)
    {
      continue;
    }
    const size_t a = indexOf(std::get<0>(link)), b = indexOf(std::get<1>(link));
    int pa, pb;
    const size_t ra = forest.Find(a, pa), rb = forest.Find(b, pb);
    if (ra == rb || (anchored[ra] && anchored[rb]))
    {
      continue;
    }
    forest.Join(a, b, vote < 0 ? 1 : 0);
    anchored[forest.Find(a, pa)] = anchored[ra] | anchored[rb];
  }
  // Each tree turned as a whole: as its anchor asks (the anchor's parity in the tree taken out), else by its flux.
  sumPieces();
  std::vector<int> treeTurn(nodes.size(), -1);
  for (size_t m = 0; m < nodes.size(); ++m)
  {
    if (anchorTurn[m] >= 0)
    {
      treeTurn[root[m]] = anchorTurn[m] ^ parity[m];
    }
  }
  std::vector<unsigned char> turned(nodes.size(), 0);
  for (size_t m = 0; m < nodes.size(); ++m)
  {
    if (root[m] != m)
    {
      continue;
    }
    ++report.Components;
    turned[m] = treeTurn[m] >= 0 ? static_cast<unsigned char>(treeTurn[m]) : turnPiece(pieces[m]);
    report.FlippedComponents += turned[m];
  }

  // The final normals: as propagated in the block, turned with its node (the halo's from their owners).
  std::vector<double> turn(nodes.size());
  for (size_t m = 0; m < nodes.size(); ++m)
  {
    turn[m] = (parity[m] ? -1.0 : 1.0) * (turned[root[m]] ? -1.0 : 1.0);
  }
  ParallelFor(static_cast<Index>(wanted.size()), 4, [&](Index b0, Index b1) {
    for (Index b = b0; b < b1; ++b)
    {
      const size_t first = indexOf(Node{ wanted[b], 0 });
      for (size_t m = blockBegin[b]; m < blockBegin[b + 1]; ++m)
      {
        const std::int32_t s = members[m];
        const Index i = order[s];
        const double sign = signOf(i) * turn[first + static_cast<size_t>(component[s])];
        for (int a = 0; a < 3; ++a)
        {
          field.Normals[3 * i + a] *= sign;
        }
        confidence[i] = sortedConfidence[s];
      }
    }
  });
  UpdateHalo(d, field.Normals, 3);
  // Outliers follow their nearest oriented neighbour.
  Index ambiguous = 0;
  for (Index i = 0; i < n; ++i)
  {
    if (!field.Valid[i] || !IsOwn(d, i))
    {
      continue;
    }
    if (field.Outlier[i])
    {
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
    }
    ambiguous += confidence[i] < 0.5 ? 1 : 0;
  }
  UpdateHalo(d, field.Normals, 3);
  report.Ambiguous = GlobalSum(d, ambiguous);
  return report;
}
} // namespace

OrientationReport OrientNormals(const NeighborGrid& grid, NormalField& field, const OrientationOptions& options,
  std::vector<double>& confidence)
{
  if (field.JetNormals.size() != field.Normals.size())
  {
    std::vector<double>().swap(field.JetNormals);
    return OrientGivenNormals(grid, field, options, confidence);
  }
  // Sharp features gave some points a neighbour's normal (SharpFeatures): the jets' own normals are oriented, and
  // each point's final normal is its donor's turned to agree with its own oriented one (every point has both; the
  // halo's too, so every process turns them alike).
  field.Normals.swap(field.JetNormals);
  const OrientationReport report = OrientGivenNormals(grid, field, options, confidence);
  const Index n = static_cast<Index>(field.Valid.size());
  ParallelFor(n, 4096, [&](Index b0, Index b1) {
    for (Index i = b0; i < b1; ++i)
    {
      const double* own = &field.Normals[3 * i];
      const double* donor = &field.JetNormals[3 * i];
      const double sign = Dot(own, donor) < 0.0 ? -1.0 : 1.0;
      for (int a = 0; a < 3; ++a)
      {
        field.JetNormals[3 * i + a] = sign * donor[a];
      }
    }
  });
  field.Normals.swap(field.JetNormals);
  std::vector<double>().swap(field.JetNormals);
  return report;
}

} // namespace meshfree
