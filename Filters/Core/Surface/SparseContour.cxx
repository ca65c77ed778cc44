// SPDX-License-Identifier: BSD-3-Clause
// Sparse continuation contouring; the method is described in SparseContour.h.
#include "Surface/SparseContour.h"

#include "Common/LargeArrays.h"
#include "Common/Parallel.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <unordered_map>

namespace meshfree
{

//------------------------------------------------------------------------------
// One cell: loops of crossing points, face by face.
namespace
{
/// Corners of each face in counter-clockwise order seen from outside the cell: -x, +x, -y, +y, -z, +z.
constexpr int FaceCorners[6][4] = { { 0, 4, 6, 2 }, { 1, 3, 7, 5 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 },
  { 0, 2, 3, 1 }, { 4, 5, 7, 6 } };

int LowerCorner(int e)
{
  const int axis = e / 4, r = e % 4;
  switch (axis)
  {
    case 0:
      return ((r & 1) << 1) | ((r >> 1) << 2);
    case 1:
      return (r & 1) | ((r >> 1) << 2);
    default:
      return r;
  }
}

/// Edge index of the corner pair (a, b), which differ in exactly one bit.
int EdgeOf(int a, int b)
{
  const int lower = std::min(a, b);
  const int bit = a ^ b;
  const int axis = bit == 1 ? 0 : (bit == 2 ? 1 : 2);
  switch (axis)
  {
    case 0:
      return 0 + ((lower >> 1) & 1) + (((lower >> 2) & 1) << 1);
    case 1:
      return 4 + (lower & 1) + (((lower >> 2) & 1) << 1);
    default:
      return 8 + (lower & 3);
  }
}

struct EdgeTable
{
  int Face[6][4]; // edge between FaceCorners[f][m] and FaceCorners[f][m + 1]
  int Faces[12];  // bit f set when the edge lies on face f
  EdgeTable()
  {
    std::fill(this->Faces, this->Faces + 12, 0);
    for (int f = 0; f < 6; ++f)
    {
      for (int m = 0; m < 4; ++m)
      {
        this->Face[f][m] = EdgeOf(FaceCorners[f][m], FaceCorners[f][(m + 1) % 4]);
        this->Faces[this->Face[f][m]] |= 1 << f;
      }
    }
  }
};

/// First apex of the loop from which every fan chord joins two edges that share no face of the cell (a
/// chord along a face could also be an edge of the neighbour's triangles there); -1 when there is none.
int FanApex(const EdgeTable& table, const int* loop, int length)
{
  for (int a = 0; a < length; ++a)
  {
    bool ok = true;
    for (int j = 2; j + 1 < length && ok; ++j)
    {
      ok = (table.Faces[loop[a]] & table.Faces[loop[(a + j) % length]]) == 0;
    }
    if (ok)
    {
      return a;
    }
  }
  return -1;
}
const EdgeTable& Edges()
{
  static const EdgeTable table;
  return table;
}
} // namespace

void CellEdgeCorners(int e, int& lower, int& upper)
{
  lower = LowerCorner(e);
  upper = lower | (1 << (e / 4));
}

int PolygonizeCell(const double v[8], CellPolygons& out)
{
  const EdgeTable& table = Edges();
  int next[12];
  std::fill(next, next + 12, -1);
  bool crossing[12] = { false };
  for (int f = 0; f < 6; ++f)
  {
    const int* c = FaceCorners[f];
    bool neg[4];
    for (int m = 0; m < 4; ++m)
    {
      neg[m] = v[c[m]] < 0.0;
    }
    int entries[2], exits[2], ne = 0, nx = 0;
    for (int m = 0; m < 4; ++m)
    {
      const bool a = neg[m], b = neg[(m + 1) % 4];
      if (!a && b)
      {
        entries[ne++] = m;
      }
      else if (a && !b)
      {
        exits[nx++] = m;
      }
    }
    if (ne == 1)
    {
      next[table.Face[f][entries[0]]] = table.Face[f][exits[0]];
    }
    else if (ne == 2)
    {
      // Negative corners on one diagonal: the asymptotic decider (see the header).
      double n0 = 0.0, n1 = 0.0, p0 = 0.0, p1 = 0.0;
      bool firstN = true, firstP = true;
      for (int m = 0; m < 4; ++m)
      {
        double& slot = neg[m] ? (firstN ? n0 : n1) : (firstP ? p0 : p1);
        slot = v[c[m]];
        (neg[m] ? firstN : firstP) = false;
      }
      const bool joined = n0 * n1 > p0 * p1;
      for (int q = 0; q < 2; ++q)
      {
        const int m = entries[q];
        const int target = joined ? (m + 3) % 4 : (m + 1) % 4;
        next[table.Face[f][m]] = table.Face[f][target];
      }
    }
    for (int q = 0; q < ne; ++q)
    {
      crossing[table.Face[f][entries[q]]] = true;
    }
  }
  out.TriangleCount = 0;
  out.LoopCount = 0;
  bool used[12] = { false };
  for (int s = 0; s < 12; ++s)
  {
    if (!crossing[s] || used[s])
    {
      continue;
    }
    int* loop = out.LoopEdges[out.LoopCount];
    int length = 0;
    int e = s;
    bool closed = false;
    while (e >= 0 && !used[e] && length < 12)
    {
      used[e] = true;
      loop[length++] = e;
      e = next[e];
      if (e == s)
      {
        closed = true;
        break;
      }
    }
    if (!closed || length < 3)
    {
      continue; // cannot happen for finite values; never emit a broken polygon
    }
    const int id = out.LoopCount++;
    out.LoopLength[id] = length;
    int* t = out.Triangles + 3 * out.TriangleCount;
    const int apex = FanApex(table, loop, length);
    if (apex >= 0)
    {
      for (int i = 1; i + 1 < length; ++i, t += 3)
      {
        t[0] = loop[apex];
        t[1] = loop[(apex + i) % length];
        t[2] = loop[(apex + i + 1) % length];
      }
      out.TriangleCount += length - 2;
    }
    else
    {
      for (int i = 0; i < length; ++i, t += 3)
      {
        t[0] = CellPolygons::LoopCentre + id;
        t[1] = loop[i];
        t[2] = loop[(i + 1) % length];
      }
      out.TriangleCount += length;
    }
  }
  return out.TriangleCount;
}

//------------------------------------------------------------------------------
// The sparse lattice.
namespace
{
constexpr int BlockBits = 3;
constexpr Index BlockEdge = Index(1) << BlockBits; // cells per block edge
constexpr int BlockCorners = 512;

enum CornerState : unsigned char
{
  Untouched = 0,
  Requested = 1,
  Defined = 2,
  Undefined = 3
};

struct Block
{
  Index Coord[3];
  double Value[BlockCorners];
  unsigned char State[BlockCorners];
  std::uint64_t Active[BlockCorners / 64];
  std::int32_t Next[8]; // blocks at offsets (dx, dy, dz) in {0, 1}^3, index dx + 2 dy + 4 dz; -1: none
  Index VertexBase = 0;
  std::vector<std::uint16_t> EdgeCodes; // local corner * 3 + axis of the crossing edges owned, ascending
  bool Pending = false;
};

inline int Local(Index li, Index lj, Index lk)
{
  return static_cast<int>(li + BlockEdge * (lj + BlockEdge * lk));
}

inline std::uint64_t BlockKey(Index bi, Index bj, Index bk)
{
  return static_cast<std::uint64_t>(bi) | (static_cast<std::uint64_t>(bj) << 18) |
    (static_cast<std::uint64_t>(bk) << 36);
}

void UnpackCell(std::uint64_t key, Index c[3])
{
  const std::uint64_t mask = (std::uint64_t(1) << 21) - 1;
  c[0] = static_cast<Index>(key & mask);
  c[1] = static_cast<Index>((key >> 21) & mask);
  c[2] = static_cast<Index>((key >> 42) & mask);
}

class Lattice
{
public:
  explicit Lattice(const ContourOptions& options)
    : Options(options)
  {
  }

  std::int32_t Find(Index bi, Index bj, Index bk) const
  {
    const auto it = this->Map.find(BlockKey(bi, bj, bk));
    return it == this->Map.end() ? -1 : it->second;
  }

  std::int32_t FindOrCreate(Index bi, Index bj, Index bk)
  {
    const auto inserted = this->Map.emplace(BlockKey(bi, bj, bk), static_cast<std::int32_t>(this->Blocks.size()));
    if (inserted.second)
    {
      this->Blocks.emplace_back();
      Block& b = this->Blocks.back();
      b.Coord[0] = bi;
      b.Coord[1] = bj;
      b.Coord[2] = bk;
      std::fill(b.State, b.State + BlockCorners, Untouched);
      std::fill(b.Active, b.Active + BlockCorners / 64, 0);
      std::fill(b.Next, b.Next + 8, -1);
    }
    return inserted.first->second;
  }

  /// The block owning corner (i, j, k) and the corner's local index; null when there is none.
  const Block* Corner(Index i, Index j, Index k, int& local) const
  {
    const std::int32_t b = this->Find(i >> BlockBits, j >> BlockBits, k >> BlockBits);
    if (b < 0)
    {
      return nullptr;
    }
    local = Local(i & (BlockEdge - 1), j & (BlockEdge - 1), k & (BlockEdge - 1));
    return &this->Blocks[b];
  }

  bool IsActive(Index i, Index j, Index k) const
  {
    int local = 0;
    const Block* b = this->Corner(i, j, k, local);
    return b && ((b->Active[local >> 6] >> (local & 63)) & 1);
  }

  /// The 8 corner values of cell (i, j, k); false when one is missing or undefined.
  bool CellValues(Index i, Index j, Index k, double v[8]) const
  {
    for (int c = 0; c < 8; ++c)
    {
      int local = 0;
      const Block* b = this->Corner(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1), local);
      if (!b || b->State[local] != Defined)
      {
        return false;
      }
      v[c] = b->Value[local];
    }
    return true;
  }

  /// Activates the cells (sorted, unique, not active yet) and requests their corners.
  void Activate(const std::vector<std::uint64_t>& cells)
  {
    for (std::uint64_t key : cells)
    {
      Index c[3];
      UnpackCell(key, c);
      const std::int32_t home = this->FindOrCreate(c[0] >> BlockBits, c[1] >> BlockBits, c[2] >> BlockBits);
      const int local = Local(c[0] & (BlockEdge - 1), c[1] & (BlockEdge - 1), c[2] & (BlockEdge - 1));
      this->Blocks[home].Active[local >> 6] |= std::uint64_t(1) << (local & 63);
      for (int q = 0; q < 8; ++q)
      {
        const Index i = c[0] + (q & 1), j = c[1] + ((q >> 1) & 1), k = c[2] + ((q >> 2) & 1);
        const std::int32_t b = this->FindOrCreate(i >> BlockBits, j >> BlockBits, k >> BlockBits);
        Block& block = this->Blocks[b];
        const int l = Local(i & (BlockEdge - 1), j & (BlockEdge - 1), k & (BlockEdge - 1));
        if (block.State[l] == Untouched)
        {
          block.State[l] = Requested;
          if (!block.Pending)
          {
            block.Pending = true;
            this->PendingBlocks.push_back(b);
          }
        }
      }
    }
  }

  void CornerPosition(const Block& b, int local, double x[3]) const
  {
    const Index l[3] = { local & (BlockEdge - 1), (local >> BlockBits) & (BlockEdge - 1), local >> (2 * BlockBits) };
    for (int a = 0; a < 3; ++a)
    {
      x[a] = this->Options.Origin[a] + static_cast<double>(b.Coord[a] * BlockEdge + l[a]) * this->Options.CellSize;
    }
  }

  void LinkNeighbors()
  {
    for (Block& b : this->Blocks)
    {
      for (int q = 0; q < 8; ++q)
      {
        b.Next[q] = this->Find(b.Coord[0] + (q & 1), b.Coord[1] + ((q >> 1) & 1), b.Coord[2] + ((q >> 2) & 1));
      }
    }
  }

  /// Block and local index of corner (li + d) of block b, d in {0, 1}^3, li in 0..7 (through Next).
  const Block* Offset(const Block& b, int li, int lj, int lk, int d, int& local) const
  {
    int q = 0;
    int l[3] = { li + (d & 1), lj + ((d >> 1) & 1), lk + ((d >> 2) & 1) };
    for (int a = 0; a < 3; ++a)
    {
      if (l[a] == BlockEdge)
      {
        q |= 1 << a;
        l[a] = 0;
      }
    }
    const std::int32_t id = b.Next[q];
    if (id < 0)
    {
      return nullptr;
    }
    local = Local(l[0], l[1], l[2]);
    return &this->Blocks[id];
  }

  const ContourOptions& Options;
  std::deque<Block> Blocks;
  std::unordered_map<std::uint64_t, std::int32_t> Map;
  std::vector<std::int32_t> PendingBlocks;
};

/// Evaluates the requested corners of the pending blocks, in chunks between which progress is reported.
bool EvaluatePending(Lattice& lattice, const ImplicitField& field, ContourReport& report,
  const ProgressCallback& progress, double fraction)
{
  std::vector<std::int32_t> pending;
  pending.swap(lattice.PendingBlocks);
  std::sort(pending.begin(), pending.end());
  const Index count = static_cast<Index>(pending.size());
  constexpr Index Chunk = 512;
  struct Counts
  {
    Index Evaluated = 0;
    Index Undefined = 0;
  };
  PerThread<FieldScratch> scratch;
  for (Index begin = 0; begin < count; begin += Chunk)
  {
    const Index end = std::min(count, begin + Chunk);
    // Ranges of one lattice block (up to 512 corners to evaluate).
    const Counts counts = ParallelReduce(end - begin, 1, Counts(),
      [&](Index b0, Index b1) {
        FieldScratch& s = scratch.Local();
        Counts mine;
        for (Index p = begin + b0; p < begin + b1; ++p)
        {
          Block& b = lattice.Blocks[pending[p]];
          b.Pending = false;
          for (int c = 0; c < BlockCorners; ++c)
          {
            if (b.State[c] != Requested)
            {
              continue;
            }
            double x[3], f = 0.0;
            lattice.CornerPosition(b, c, x);
            const bool ok = field.Evaluate(x, f, nullptr, s) && std::isfinite(f);
            b.Value[c] = ok ? f : 0.0;
            b.State[c] = ok ? Defined : Undefined;
            ++mine.Evaluated;
            mine.Undefined += ok ? 0 : 1;
          }
        }
        return mine;
      },
      [](Counts a, const Counts& b) {
        a.Evaluated += b.Evaluated;
        a.Undefined += b.Undefined;
        return a;
      });
    report.EvaluatedCorners += counts.Evaluated;
    report.UndefinedCorners += counts.Undefined;
    if (progress && !progress(fraction))
    {
      return false;
    }
  }
  return true;
}

/// The cells beyond the crossed faces of `cells` that are not active yet (sorted, unique).
std::vector<std::uint64_t> GrowthFront(const Lattice& lattice, const std::vector<std::uint64_t>& cells, bool& edge)
{
  const Index count = static_cast<Index>(cells.size());
  // Each thread collects its own cells; their union is sorted below, so the order of the ranges is irrelevant.
  const size_t threads = static_cast<size_t>(MaxThreads());
  std::vector<std::vector<std::uint64_t>> found(threads);
  std::vector<unsigned char> reachedEdge(threads, 0);
  ParallelFor(count, 1024, [&](Index begin, Index end) {
    const size_t t = static_cast<size_t>(ThreadIndex());
    std::vector<std::uint64_t>& mine = found[t];
    for (Index n = begin; n < end; ++n)
    {
      Index c[3];
      UnpackCell(cells[n], c);
      double v[8];
      if (!lattice.CellValues(c[0], c[1], c[2], v))
      {
        continue;
      }
      for (int f = 0; f < 6; ++f)
      {
        int negatives = 0;
        for (int m = 0; m < 4; ++m)
        {
          negatives += v[FaceCorners[f][m]] < 0.0 ? 1 : 0;
        }
        if (negatives == 0 || negatives == 4)
        {
          continue;
        }
        const int axis = f / 2;
        Index d[3] = { c[0], c[1], c[2] };
        d[axis] += (f % 2) ? 1 : -1;
        if (d[axis] < 0 || d[axis] + 1 > SparseContour::kMaximumCoordinate)
        {
          reachedEdge[t] = 1;
          continue;
        }
        if (!lattice.IsActive(d[0], d[1], d[2]))
        {
          mine.push_back(SparseContour::CellKey(d[0], d[1], d[2]));
        }
      }
    }
  });
  std::vector<std::uint64_t> front;
  size_t total = 0;
  for (const auto& mine : found)
  {
    total += mine.size();
  }
  front.reserve(total);
  for (size_t t = 0; t < threads; ++t)
  {
    front.insert(front.end(), found[t].begin(), found[t].end());
    std::vector<std::uint64_t>().swap(found[t]);
    edge = edge || reachedEdge[t];
  }
  std::sort(front.begin(), front.end());
  front.erase(std::unique(front.begin(), front.end()), front.end());
  return front;
}
} // namespace

std::uint64_t SparseContour::CellKey(Index i, Index j, Index k)
{
  return static_cast<std::uint64_t>(i) | (static_cast<std::uint64_t>(j) << 21) |
    (static_cast<std::uint64_t>(k) << 42);
}

bool SparseContour::CellOf(const double x[3], const ContourOptions& options, Index cell[3])
{
  for (int a = 0; a < 3; ++a)
  {
    const double t = std::floor((x[a] - options.Origin[a]) / options.CellSize);
    if (!(t >= 0.0) || !(t < static_cast<double>(kMaximumCoordinate)))
    {
      return false;
    }
    cell[a] = static_cast<Index>(t);
  }
  return true;
}

bool SparseContour::Run(const ImplicitField& field, std::vector<std::uint64_t> seeds, const ContourOptions& options,
  TriangleMesh& mesh, ContourReport& report, const ProgressCallback& progress, const Distribution* d)
{
  mesh = TriangleMesh();
  report = ContourReport();
  if (!(options.CellSize > 0.0) || !std::isfinite(options.CellSize))
  {
    return false;
  }
  Lattice lattice(options);
  // Seeds must leave room for their upper corners.
  seeds.erase(std::remove_if(seeds.begin(), seeds.end(),
                [](std::uint64_t key) {
                  Index c[3];
                  UnpackCell(key, c);
                  return c[0] + 1 > kMaximumCoordinate || c[1] + 1 > kMaximumCoordinate ||
                    c[2] + 1 > kMaximumCoordinate;
                }),
    seeds.end());
  // Distributed: the cells whose centre this process owns; the others are handed to their owners.
  const auto owns = [d, &options](std::uint64_t key) {
    Index c[3];
    UnpackCell(key, c);
    double x[3];
    for (int a = 0; a < 3; ++a)
    {
      x[a] = options.Origin[a] + (static_cast<double>(c[a]) + 0.5) * options.CellSize;
    }
    return d->OwnsPosition(x);
  };

  // Continuation rounds (evaluation is most of the work: progress 0 .. 0.85).
  std::vector<std::uint64_t> fresh = std::move(seeds);
  bool aborted = false;
  while (true)
  {
    if (d)
    {
      std::vector<std::uint64_t> mine, away;
      for (const std::uint64_t key : fresh)
      {
        (owns(key) ? mine : away).push_back(key);
      }
      for (const std::uint64_t key : GatherKeys(d, away))
      {
        Index c[3];
        UnpackCell(key, c);
        if (owns(key) && !lattice.IsActive(c[0], c[1], c[2]))
        {
          mine.push_back(key);
        }
      }
      fresh.swap(mine);
    }
    std::sort(fresh.begin(), fresh.end());
    fresh.erase(std::unique(fresh.begin(), fresh.end()), fresh.end());
    if (GlobalSum(d, static_cast<Index>(fresh.size())) == 0)
    {
      break;
    }
    if (report.Rounds >= options.MaximumRounds)
    {
      report.RoundLimitReached = true;
      break;
    }
    ++report.Rounds;
    lattice.Activate(fresh);
    report.ActiveCells += static_cast<Index>(fresh.size());
    const double fraction = 0.85 * (1.0 - 1.0 / (1.0 + report.Rounds));
    // Aborting is local: a distributed process stops growing but takes part in the rounds until all are done.
    aborted = aborted || !EvaluatePending(lattice, field, report, progress, fraction);
    if (aborted)
    {
      fresh.clear();
      lattice.PendingBlocks.clear();
      if (!d)
      {
        break;
      }
      continue;
    }
    fresh = GrowthFront(lattice, fresh, report.LatticeEdgeReached);
  }
  if (d)
  {
    report.LatticeEdgeReached = GlobalMax(d, report.LatticeEdgeReached ? 1.0 : 0.0) > 0.0;
  }
  if (aborted)
  {
    report.Aborted = true;
    mesh = TriangleMesh();
    return false;
  }
  report.Blocks = static_cast<Index>(lattice.Blocks.size());
  lattice.LinkNeighbors();

  // Vertices: one per crossing edge, created by the block owning the edge's lower corner.
  const Index nb = static_cast<Index>(lattice.Blocks.size());
  const double cell = options.CellSize;
  const double clamp = std::min(0.5, std::max(0.0, options.ClampFraction));
  ParallelFor(nb, 16, [&](Index begin, Index end) {
    for (Index bi = begin; bi < end; ++bi)
    {
      Block& b = lattice.Blocks[bi];
      b.EdgeCodes.clear();
      for (int c = 0; c < BlockCorners; ++c)
      {
        if (b.State[c] != Defined)
        {
          continue;
        }
        const int li = c & 7, lj = (c >> 3) & 7, lk = c >> 6;
        for (int axis = 0; axis < 3; ++axis)
        {
          int local = 0;
          const Block* o = lattice.Offset(b, li, lj, lk, 1 << axis, local);
          if (o && o->State[local] == Defined && ((b.Value[c] < 0.0) != (o->Value[local] < 0.0)))
          {
            b.EdgeCodes.push_back(static_cast<std::uint16_t>(3 * c + axis));
          }
        }
      }
    }
  });
  Index vertices = 0;
  for (Block& b : lattice.Blocks)
  {
    b.VertexBase = vertices;
    vertices += static_cast<Index>(b.EdgeCodes.size());
  }
  // The mesh's arrays are written once each, serially where they are assembled: scratch ones are Buffers and the
  // large public ones are reserved on huge pages (LargeArrays.h: their first touch would cost more than the writes).
  detail::Buffer<double> points;
  points.resize(static_cast<size_t>(3 * vertices));
  ParallelFor(nb, 16, [&](Index begin, Index end) {
    for (Index bi = begin; bi < end; ++bi)
    {
      const Block& b = lattice.Blocks[bi];
      for (size_t n = 0; n < b.EdgeCodes.size(); ++n)
      {
        const int c = b.EdgeCodes[n] / 3, axis = b.EdgeCodes[n] % 3;
        int local = 0;
        const Block* o = lattice.Offset(b, c & 7, (c >> 3) & 7, c >> 6, 1 << axis, local);
        const double f0 = b.Value[c], f1 = o->Value[local];
        double t = f0 / (f0 - f1);
        t = std::min(1.0 - clamp, std::max(clamp, t));
        double* x = &points[3 * (b.VertexBase + static_cast<Index>(n))];
        lattice.CornerPosition(b, c, x);
        x[axis] += t * cell;
      }
    }
  });
  if (progress && !progress(0.9))
  {
    report.Aborted = true;
    return false;
  }

  // Triangles, block by block in block order. Loop centres (rare, see PolygonizeCell) are extra vertices of
  // the cell's block, referred to as -(1 + their index in the block) until all blocks are done.
  std::vector<std::vector<Index>> blockTriangles(static_cast<size_t>(nb));
  std::vector<std::vector<double>> blockCentres(static_cast<size_t>(nb));
  ParallelFor(nb, 16, [&](Index begin, Index end) {
    for (Index bi = begin; bi < end; ++bi)
    {
      const Block& b = lattice.Blocks[bi];
      std::vector<Index>& out = blockTriangles[bi];
      std::vector<double>& centres = blockCentres[bi];
      for (int w = 0; w < BlockCorners / 64; ++w)
      {
        for (std::uint64_t bits = b.Active[w]; bits; bits &= bits - 1)
        {
          const int c = 64 * w + __builtin_ctzll(bits);
          const int li = c & 7, lj = (c >> 3) & 7, lk = c >> 6;
          double v[8];
          const Block* owner[8];
          int local[8];
          bool complete = true;
          int negatives = 0;
          for (int q = 0; q < 8 && complete; ++q)
          {
            owner[q] = lattice.Offset(b, li, lj, lk, q, local[q]);
            complete = owner[q] && owner[q]->State[local[q]] == Defined;
            if (complete)
            {
              v[q] = owner[q]->Value[local[q]];
              negatives += v[q] < 0.0 ? 1 : 0;
            }
          }
          if (!complete || negatives == 0 || negatives == 8)
          {
            continue;
          }
          CellPolygons polygons;
          PolygonizeCell(v, polygons);
          Index edgeVertex[12];
          bool found = true;
          for (int l = 0; l < polygons.LoopCount && found; ++l)
          {
            for (int m = 0; m < polygons.LoopLength[l] && found; ++m)
            {
              const int e = polygons.LoopEdges[l][m];
              int lower = 0, upper = 0;
              CellEdgeCorners(e, lower, upper);
              const Block* o = owner[lower];
              const std::uint16_t code = static_cast<std::uint16_t>(3 * local[lower] + e / 4);
              const auto it = std::lower_bound(o->EdgeCodes.begin(), o->EdgeCodes.end(), code);
              found = it != o->EdgeCodes.end() && *it == code;
              edgeVertex[e] = found ? o->VertexBase + static_cast<Index>(it - o->EdgeCodes.begin()) : -1;
            }
          }
          if (!found)
          {
            continue; // cannot happen: both corners of every crossing edge are defined
          }
          Index centre[4] = { 0, 0, 0, 0 };
          bool centred[4] = { false, false, false, false };
          for (int t = 0; t < 3 * polygons.TriangleCount; ++t)
          {
            const int code = polygons.Triangles[t];
            if (code < CellPolygons::LoopCentre)
            {
              out.push_back(edgeVertex[code]);
              continue;
            }
            const int l = code - CellPolygons::LoopCentre;
            if (!centred[l])
            {
              double sum[3] = { 0.0, 0.0, 0.0 };
              for (int m = 0; m < polygons.LoopLength[l]; ++m)
              {
                const double* x = &points[3 * edgeVertex[polygons.LoopEdges[l][m]]];
                for (int a = 0; a < 3; ++a)
                {
                  sum[a] += x[a];
                }
              }
              for (int a = 0; a < 3; ++a)
              {
                centres.push_back(sum[a] / polygons.LoopLength[l]);
              }
              centre[l] = -static_cast<Index>(centres.size() / 3);
              centred[l] = true;
            }
            out.push_back(centre[l]);
          }
        }
      }
    }
  });
  Index centreBase = vertices;
  for (Index bi = 0; bi < nb; ++bi)
  {
    for (Index& id : blockTriangles[bi])
    {
      id = id < 0 ? centreBase + (-id - 1) : id;
    }
    const std::vector<double>& centres = blockCentres[bi];
    points.insert(points.end(), centres.begin(), centres.end());
    centreBase += static_cast<Index>(centres.size() / 3);
  }
  vertices = centreBase;
  // The lattice's corner values (about 5 KB per block) are no longer needed: free them before the mesh's
  // final arrays are assembled (at 1M SPH particles this lowers the peak by a sixth).
  std::deque<Block>().swap(lattice.Blocks);
  std::unordered_map<std::uint64_t, std::int32_t>().swap(lattice.Map);
  std::vector<std::vector<double>>().swap(blockCentres);

  // Keep the vertices the triangles use, renumbered in order.
  detail::Buffer<Index> renumber;
  renumber.assign(static_cast<size_t>(vertices), -1);
  std::vector<size_t> blockStart(static_cast<size_t>(nb) + 1, 0);
  for (Index bi = 0; bi < nb; ++bi)
  {
    blockStart[bi + 1] = blockStart[bi] + blockTriangles[bi].size();
  }
  mesh.Triangles.clear();
  detail::ReserveLarge(mesh.Triangles, blockStart[nb]);
  mesh.Triangles.resize(blockStart[nb]);
  ParallelFor(nb, 16, [&](Index begin, Index end) {
    for (Index bi = begin; bi < end; ++bi)
    {
      std::vector<Index>& t = blockTriangles[bi];
      std::copy(t.begin(), t.end(), mesh.Triangles.begin() + static_cast<std::ptrdiff_t>(blockStart[bi]));
      std::vector<Index>().swap(t);
    }
  });
  for (Index id : mesh.Triangles)
  {
    renumber[id] = 0;
  }
  Index kept = 0;
  for (Index v = 0; v < vertices; ++v)
  {
    if (renumber[v] == 0)
    {
      renumber[v] = kept++;
    }
  }
  mesh.Points.clear();
  detail::ReserveLarge(mesh.Points, static_cast<size_t>(3 * kept));
  mesh.Points.resize(static_cast<size_t>(3 * kept));
  ParallelFor(vertices, 4096, [&](Index begin, Index end) {
    for (Index v = begin; v < end; ++v)
    {
      if (renumber[v] >= 0)
      {
        std::copy(&points[3 * v], &points[3 * v] + 3, &mesh.Points[3 * renumber[v]]);
      }
    }
  });
  ParallelFor(static_cast<Index>(mesh.Triangles.size()), 1 << 14, [&](Index begin, Index end) {
    for (Index k = begin; k < end; ++k)
    {
      mesh.Triangles[k] = renumber[mesh.Triangles[k]];
    }
  });
  if (progress)
  {
    progress(1.0);
  }
  return true;
}

} // namespace meshfree
