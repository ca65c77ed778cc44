// SPDX-License-Identifier: BSD-3-Clause
// Barnes-Hut generalized winding number of an oriented cloud (WindingNumber.h).
#include "Surface/WindingNumber.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

namespace meshfree
{

namespace
{
constexpr double kInverseFourPi = 0.25 / M_PI;
constexpr Index kLeafSize = 32; // a node holds 44 doubles: bigger leaves keep the tree at about 1.5 doubles per point

/// The number of nodes BuildNode makes over `size` points (halves until a node holds at most kLeafSize).
size_t TreeNodes(Index size)
{
  return size <= kLeafSize ? 1 : 1 + TreeNodes(size / 2) + TreeNodes(size - size / 2);
}
} // namespace

void WindingNumber::Build(const double* points, const double* normals, const double* areas, Index count, double beta)
{
  this->Build(points, normals, areas, count, WindingCubes(), beta);
}

namespace
{
constexpr Index kCubeCoordinates = Index(1) << 21;
constexpr int kRecord = 2 + 44; // a gathered cube root: its key (two halves) and its node's 44 doubles

std::uint64_t CubeKey(const double* p, const WindingCubes& cubes)
{
  if (!(cubes.Size > 0.0))
  {
    return 0;
  }
  std::uint64_t key = 0;
  for (int a = 0; a < 3; ++a)
  {
    const double t = std::floor((p[a] - cubes.Origin[a]) / cubes.Size);
    const Index c = static_cast<Index>(std::min(std::max(t, 0.0), static_cast<double>(kCubeCoordinates - 1)));
    key |= static_cast<std::uint64_t>(c) << (21 * a);
  }
  return key;
}

void CubeCentre(std::uint64_t key, const WindingCubes& cubes, double centre[3])
{
  for (int a = 0; a < 3; ++a)
  {
    const Index c = static_cast<Index>((key >> (21 * a)) & (kCubeCoordinates - 1));
    centre[a] = cubes.Origin[a] + (static_cast<double>(c) + 0.5) * cubes.Size;
  }
}
} // namespace

void WindingNumber::Build(const double* points, const double* normals, const double* areas, Index count,
  const WindingCubes& cubes, double beta)
{
  const Distribution* d = cubes.Processes;
  this->Nodes.clear();
  this->Top.clear();
  this->Points.clear();
  this->Normals.clear();
  this->Areas.clear();
  this->Total = 0.0;
  this->Root = 0;
  this->BuildShortfall = -HUGE_VAL;
  this->Opened = false;
  this->Beta2 = std::max(1.0, beta) * std::max(1.0, beta);
  const bool lattice = cubes.Size > 0.0 && std::isfinite(cubes.Size);
  const double halfDiagonal = lattice ? 0.5 * std::sqrt(3.0) * cubes.Size : HUGE_VAL;
  // The valid points with their cube, sorted by cube (then by position, as the trees order them).
  struct Keyed
  {
    std::uint64_t Key;
    Item It;
  };
  detail::Buffer<Keyed> keyed;
  keyed.reserve(static_cast<size_t>(std::max<Index>(count, 0)));
  for (Index i = 0; i < count; ++i)
  {
    const double* p = points + 3 * i;
    const double* n = normals + 3 * i;
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (std::isfinite(p[0] + p[1] + p[2]) && len > 0.0 && std::isfinite(len) && areas[i] > 0.0 &&
      std::isfinite(areas[i]))
    {
      keyed.push_back(Keyed{ lattice ? CubeKey(p, cubes) : 0, Item{ { p[0], p[1], p[2] }, i } });
    }
  }
  std::sort(keyed.begin(), keyed.end(), [](const Keyed& a, const Keyed& b) {
    return a.Key < b.Key ||
      (a.Key == b.Key &&
        (std::lexicographical_compare(a.It.P, a.It.P + 3, b.It.P, b.It.P + 3) ||
          (std::equal(a.It.P, a.It.P + 3, b.It.P) && a.It.Id < b.It.Id)));
  });
  // The cubes this process holds completely (all of them when serial): their points, in cube order. The groups are
  // found first so that the points and the trees' nodes are allocated once at their exact size (a rank's peak
  // memory falls in this build: issue 24).
  detail::Buffer<Item> items;
  std::vector<std::pair<std::uint64_t, std::pair<Index, Index>>> held; // key, [begin, end) in items
  std::vector<size_t> heldStart;                                        // where each held cube starts in keyed
  std::vector<std::uint64_t> seen;                                      // every cube with a local point
  Index heldPoints = 0;
  size_t cubeNodes = 0;
  for (size_t g = 0; g < keyed.size();)
  {
    size_t h = g;
    while (h < keyed.size() && keyed[h].Key == keyed[g].Key)
    {
      ++h;
    }
    const std::uint64_t key = keyed[g].Key;
    seen.push_back(key);
    bool complete = true;
    if (d && lattice)
    {
      double centre[3];
      CubeCentre(key, cubes, centre);
      const double reach = d->Complete(centre);
      complete = reach >= halfDiagonal;
      if (!complete && d->OwnsPosition(centre))
      {
        this->BuildShortfall = std::max(this->BuildShortfall, halfDiagonal - reach);
      }
    }
    if (complete)
    {
      const Index size = static_cast<Index>(h - g);
      held.emplace_back(key, std::make_pair(heldPoints, heldPoints + size));
      heldStart.push_back(g);
      heldPoints += size;
      cubeNodes += TreeNodes(size);
    }
    g = h;
  }
  items.reserve(static_cast<size_t>(heldPoints));
  for (size_t c = 0; c < held.size(); ++c)
  {
    const size_t g = heldStart[c];
    for (Index k = 0; k < held[c].second.second - held[c].second.first; ++k)
    {
      items.push_back(keyed[g + static_cast<size_t>(k)].It);
    }
  }
  std::vector<size_t>().swap(heldStart);
  detail::Buffer<Keyed>().swap(keyed);
  this->Nodes.reserve(cubeNodes);
  std::vector<Index> heldRoot(held.size());
  for (size_t c = 0; c < held.size(); ++c)
  {
    heldRoot[c] = this->BuildNode(held[c].second.first, held[c].second.second, items);
  }
  // Copy the points in tree order (leaves read them contiguously): the positions and ids first, so that the items
  // go before the normals and areas are allocated.
  const size_t m = items.size();
  this->Points.resize(3 * m);
  detail::Buffer<Index> ids;
  ids.resize(m);
  for (size_t s = 0; s < m; ++s)
  {
    std::copy(items[s].P, items[s].P + 3, &this->Points[3 * s]);
    ids[s] = items[s].Id;
  }
  detail::Buffer<Item>().swap(items);
  this->Normals.resize(3 * m);
  this->Areas.resize(m);
  for (size_t s = 0; s < m; ++s)
  {
    const Index i = ids[s];
    const double* n = normals + 3 * i;
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int a = 0; a < 3; ++a)
    {
      this->Normals[3 * s + a] = n[a] / len;
    }
    this->Areas[s] = areas[i];
  }
  detail::Buffer<Index>().swap(ids);
  // Moments bottom-up (within a cube's tree children always follow their parent in this->Nodes): leaves sum their
  // points, inner nodes combine their children's moments moved to their own centre (O(n) in all).
  for (size_t k = this->Nodes.size(); k-- > 0;)
  {
    Node& node = this->Nodes[k];
    if (node.Left >= 0)
    {
      this->Combine(node, this->Nodes[node.Left], this->Nodes[node.Right]);
      continue;
    }
    std::fill(node.Moment, node.Moment + 3, 0.0);
    std::fill(node.Second, node.Second + 9, 0.0);
    std::fill(node.Third, node.Third + 27, 0.0);
    double area = 0.0, c[3] = { 0, 0, 0 };
    for (Index s = node.Begin; s < node.End; ++s)
    {
      area += this->Areas[s];
      for (int a = 0; a < 3; ++a)
      {
        c[a] += this->Areas[s] * this->Points[3 * s + a];
      }
    }
    for (int a = 0; a < 3; ++a)
    {
      node.Centre[a] = c[a] / area;
    }
    double r2 = 0.0;
    for (Index s = node.Begin; s < node.End; ++s)
    {
      const double a = this->Areas[s];
      const double* p = &this->Points[3 * s];
      const double* n = &this->Normals[3 * s];
      const double dd[3] = { p[0] - node.Centre[0], p[1] - node.Centre[1], p[2] - node.Centre[2] };
      for (int i = 0; i < 3; ++i)
      {
        node.Moment[i] += a * n[i];
        for (int j = 0; j < 3; ++j)
        {
          node.Second[3 * i + j] += a * dd[i] * n[j];
          for (int l = 0; l < 3; ++l)
          {
            node.Third[9 * i + 3 * j + l] += a * n[i] * dd[j] * dd[l];
          }
        }
      }
      r2 = std::max(r2, dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2]);
    }
    node.Radius = std::sqrt(r2);
    node.Area = area;
  }
  // Every cube's root: this process' own cubes' (by their centre) from the trees just built, the others' from the
  // processes that own them (serial: all of them here).
  std::vector<double> mine, all;
  detail::ReserveLarge(mine, held.size() * kRecord);
  for (size_t c = 0; c < held.size(); ++c)
  {
    double centre[3];
    CubeCentre(held[c].first, cubes, centre);
    if (d && lattice && !d->OwnsPosition(centre))
    {
      continue;
    }
    const Node& root = this->Nodes[heldRoot[c]];
    mine.push_back(static_cast<double>(held[c].first >> 32));
    mine.push_back(static_cast<double>(held[c].first & 0xffffffffu));
    mine.insert(mine.end(), root.Centre, root.Centre + 3);
    mine.insert(mine.end(), root.Moment, root.Moment + 3);
    mine.insert(mine.end(), root.Second, root.Second + 9);
    mine.insert(mine.end(), root.Third, root.Third + 27);
    mine.push_back(root.Radius);
    mine.push_back(root.Area);
  }
  if (d)
  {
    d->Gather(mine, all);
  }
  else
  {
    all.swap(mine);
  }
  const size_t nc = all.size() / kRecord;
  std::vector<std::pair<std::uint64_t, size_t>> gathered(nc);
  for (size_t c = 0; c < nc; ++c)
  {
    const double* r = &all[kRecord * c];
    gathered[c] = { (static_cast<std::uint64_t>(r[0]) << 32) | static_cast<std::uint64_t>(r[1]), c };
  }
  std::sort(gathered.begin(), gathered.end());
  // A cube with local points that no process contributed: its owner did not see it (the halo fell short).
  for (const std::uint64_t key : seen)
  {
    const auto it = std::lower_bound(gathered.begin(), gathered.end(), std::make_pair(key, size_t(0)));
    if (it == gathered.end() || it->first != key)
    {
      this->BuildShortfall = std::max(this->BuildShortfall, halfDiagonal);
    }
  }
  if (nc == 0)
  {
    this->Nodes.clear();
    return;
  }
  // The top tree's leaves in key order: the held cubes' roots, the others' gathered records.
  std::vector<TopLeaf> leaves(nc);
  size_t next = 0;
  for (size_t c = 0; c < nc; ++c)
  {
    const std::uint64_t key = gathered[c].first;
    while (next < held.size() && held[next].first < key)
    {
      ++next;
    }
    const bool mine = next < held.size() && held[next].first == key;
    leaves[c].Held = mine ? heldRoot[next] : Index(-1);
    leaves[c].Record = mine ? nullptr : &all[kRecord * gathered[c].second + 2];
  }
  std::vector<std::pair<std::uint64_t, size_t>>().swap(gathered);
  // The top tree's shapes first (centre, radius, area: its splits and which nodes this process needs), then its
  // nodes: distributed, a node no evaluation of this process can open keeps only its moments (EmitTop).
  std::vector<TopShape> shapes(nc - 1);
  this->ShapeTop(leaves, 0, nc, 0, shapes);
  const Distribution* prune = d && lattice ? d : nullptr;
  this->Top.reserve(this->CountTop(leaves, 0, nc, 0, shapes, prune));
  this->Root = this->EmitTop(leaves, 0, nc, 0, shapes, prune);
  this->Total = this->NodeAt(this->Root).Area;
}

namespace
{
/// A node's centre (area-weighted), area and radius bound from its two children's (WindingNumber::Combine adds the
/// moments).
template <typename Child, typename Parent>
void CombineShape(const Child& left, const Child& right, Parent& node)
{
  const double area = left.Area + right.Area;
  for (int a = 0; a < 3; ++a)
  {
    node.Centre[a] = (left.Area * left.Centre[a] + right.Area * right.Centre[a]) / area;
  }
  node.Area = area;
  node.Radius = 0.0;
  for (const Child* child : { &left, &right })
  {
    const double e[3] = { child->Centre[0] - node.Centre[0], child->Centre[1] - node.Centre[1],
      child->Centre[2] - node.Centre[2] };
    node.Radius = std::max(node.Radius, std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) + child->Radius);
  }
}
} // namespace

WindingNumber::TopShape WindingNumber::LeafShape(const TopLeaf& leaf) const
{
  TopShape shape;
  if (leaf.Held >= 0)
  {
    const Node& node = this->Nodes[leaf.Held];
    std::copy(node.Centre, node.Centre + 3, shape.Centre);
    shape.Radius = node.Radius;
    shape.Area = node.Area;
  }
  else
  {
    std::copy(leaf.Record, leaf.Record + 3, shape.Centre);
    shape.Radius = leaf.Record[42];
    shape.Area = leaf.Record[43];
  }
  return shape;
}

WindingNumber::Node WindingNumber::LeafNode(const TopLeaf& leaf) const
{
  if (leaf.Held >= 0)
  {
    return this->Nodes[leaf.Held];
  }
  const double* r = leaf.Record;
  Node node;
  std::copy(r, r + 3, node.Centre);
  std::copy(r + 3, r + 6, node.Moment);
  std::copy(r + 6, r + 15, node.Second);
  std::copy(r + 15, r + 42, node.Third);
  node.Radius = r[42];
  node.Area = r[43];
  node.Begin = node.End = 0;
  node.Left = node.Right = -2;
  return node;
}

WindingNumber::TopShape WindingNumber::ShapeTop(
  std::vector<TopLeaf>& leaves, size_t begin, size_t end, size_t index, std::vector<TopShape>& shapes) const
{
  if (end - begin == 1)
  {
    return this->LeafShape(leaves[begin]);
  }
  // Median split of the leaves' centres along the widest axis; the leaves are in key order, and a stable sort by
  // the centre keeps ties in key order. A node's internal descendants follow it (pre-order): its left child at
  // index + 1, its right child after the left's mid - begin - 1 internal nodes.
  double lo[3] = { HUGE_VAL, HUGE_VAL, HUGE_VAL }, hi[3] = { -HUGE_VAL, -HUGE_VAL, -HUGE_VAL };
  for (size_t k = begin; k < end; ++k)
  {
    const TopShape shape = this->LeafShape(leaves[k]);
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], shape.Centre[a]);
      hi[a] = std::max(hi[a], shape.Centre[a]);
    }
  }
  int axis = 0;
  for (int a = 1; a < 3; ++a)
  {
    axis = hi[a] - lo[a] > hi[axis] - lo[axis] ? a : axis;
  }
  std::stable_sort(leaves.begin() + static_cast<std::ptrdiff_t>(begin), leaves.begin() + static_cast<std::ptrdiff_t>(end),
    [this, axis](const TopLeaf& a, const TopLeaf& b) {
      return this->LeafShape(a).Centre[axis] < this->LeafShape(b).Centre[axis];
    });
  const size_t mid = begin + (end - begin) / 2;
  const TopShape left = this->ShapeTop(leaves, begin, mid, index + 1, shapes);
  const TopShape right = this->ShapeTop(leaves, mid, end, index + (mid - begin), shapes);
  CombineShape(left, right, shapes[index]);
  return shapes[index];
}

WindingNumber::Node WindingNumber::TopMoments(const std::vector<TopLeaf>& leaves, size_t begin, size_t end) const
{
  if (end - begin == 1)
  {
    return this->LeafNode(leaves[begin]);
  }
  const size_t mid = begin + (end - begin) / 2;
  const Node left = this->TopMoments(leaves, begin, mid);
  const Node right = this->TopMoments(leaves, mid, end);
  Node node;
  node.Begin = node.End = 0;
  this->Combine(node, left, right);
  return node;
}

Index WindingNumber::EmitTop(const std::vector<TopLeaf>& leaves, size_t begin, size_t end, size_t index,
  const std::vector<TopShape>& shapes, const Distribution* d)
{
  if (end - begin == 1 && leaves[begin].Held >= 0)
  {
    return leaves[begin].Held;
  }
  Node node;
  if (end - begin == 1)
  {
    node = this->LeafNode(leaves[begin]);
  }
  else if (this->Pruned(shapes[index], d))
  {
    // Every evaluation is made where the local cloud is complete (Distribution::Complete(x) >= 0); a node whose
    // centre lies farther than Beta radii from there is never opened: its moments stand for its subtree, whose nodes
    // this process does not keep (a leaf of another process, -2; the sums and their bits are the same).
    node = this->TopMoments(leaves, begin, end);
    node.Left = node.Right = -2;
  }
  else
  {
    const size_t mid = begin + (end - begin) / 2;
    node.Begin = node.End = 0;
    node.Left = this->EmitTop(leaves, begin, mid, index + 1, shapes, d);
    node.Right = this->EmitTop(leaves, mid, end, index + (mid - begin), shapes, d);
    this->Combine(node, this->NodeAt(node.Left), this->NodeAt(node.Right));
  }
  this->Top.push_back(node);
  return static_cast<Index>(this->Nodes.size() + this->Top.size() - 1);
}

bool WindingNumber::Pruned(const TopShape& shape, const Distribution* d) const
{
  return d && -d->Complete(shape.Centre) > 1.001 * std::sqrt(this->Beta2) * shape.Radius;
}

size_t WindingNumber::CountTop(const std::vector<TopLeaf>& leaves, size_t begin, size_t end, size_t index,
  const std::vector<TopShape>& shapes, const Distribution* d) const
{
  if (end - begin == 1)
  {
    return leaves[begin].Held >= 0 ? 0 : 1;
  }
  if (this->Pruned(shapes[index], d))
  {
    return 1;
  }
  const size_t mid = begin + (end - begin) / 2;
  return 1 + this->CountTop(leaves, begin, mid, index + 1, shapes, d) +
    this->CountTop(leaves, mid, end, index + (mid - begin), shapes, d);
}

void WindingNumber::Combine(Node& node, const Node& left, const Node& right) const
{
  CombineShape(left, right, node);
  std::fill(node.Moment, node.Moment + 3, 0.0);
  std::fill(node.Second, node.Second + 9, 0.0);
  std::fill(node.Third, node.Third + 27, 0.0);
  for (const Node* child : { &left, &right })
  {
    // With d = d_child + e, e = c_child - c: Q = Q_child + e M^T, and
    // C_abl = C_child,abl + Q_child,ba e_l + e_b Q_child,la + e_b e_l M_a.
    const double e[3] = { child->Centre[0] - node.Centre[0], child->Centre[1] - node.Centre[1],
      child->Centre[2] - node.Centre[2] };
    const double* m = child->Moment;
    const double* q = child->Second;
    for (int i = 0; i < 3; ++i)
    {
      node.Moment[i] += m[i];
      for (int j = 0; j < 3; ++j)
      {
        node.Second[3 * i + j] += q[3 * i + j] + e[i] * m[j];
        for (int l = 0; l < 3; ++l)
        {
          node.Third[9 * i + 3 * j + l] +=
            child->Third[9 * i + 3 * j + l] + q[3 * j + i] * e[l] + e[j] * q[3 * l + i] + e[j] * e[l] * m[i];
        }
      }
    }
  }
}

Index WindingNumber::BuildNode(Index begin, Index end, detail::Buffer<Item>& items)
{
  const Index id = static_cast<Index>(this->Nodes.size());
  this->Nodes.push_back(Node());
  this->Nodes[id].Begin = begin;
  this->Nodes[id].End = end;
  this->Nodes[id].Left = this->Nodes[id].Right = -1;
  // Ties by position, then by id (exact duplicates), so that the tree, and the order in which leaves and moments
  // sum, depend on the set of points, not on their input order (issue 24).
  const auto before = [](const Item& a, const Item& b) {
    return std::lexicographical_compare(a.P, a.P + 3, b.P, b.P + 3) ||
      (a.P[0] == b.P[0] && a.P[1] == b.P[1] && a.P[2] == b.P[2] && a.Id < b.Id);
  };
  if (end - begin <= kLeafSize)
  {
    std::sort(items.begin() + begin, items.begin() + end, before);
    return id;
  }
  double lo[3] = { items[begin].P[0], items[begin].P[1], items[begin].P[2] };
  double hi[3] = { lo[0], lo[1], lo[2] };
  for (Index s = begin; s < end; ++s)
  {
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], items[s].P[a]);
      hi[a] = std::max(hi[a], items[s].P[a]);
    }
  }
  int axis = 0;
  for (int a = 1; a < 3; ++a)
  {
    axis = hi[a] - lo[a] > hi[axis] - lo[axis] ? a : axis;
  }
  const Index mid = begin + (end - begin) / 2;
  std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
    [axis, &before](const Item& a, const Item& b) {
      return a.P[axis] < b.P[axis] || (a.P[axis] == b.P[axis] && before(a, b));
    });
  const Index left = this->BuildNode(begin, mid, items);
  const Index right = this->BuildNode(mid, end, items);
  this->Nodes[id].Left = left;
  this->Nodes[id].Right = right;
  return id;
}

double WindingNumber::DipoleLength() const
{
  if (this->Nodes.empty() && this->Top.empty())
  {
    return 0.0;
  }
  const double* m = this->NodeAt(this->Root).Moment;
  return std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
}

double WindingNumber::Evaluate(const double x[3], double gradient[3]) const
{
  double w = 0.0, g[3] = { 0.0, 0.0, 0.0 };
  if (this->Nodes.empty() && this->Top.empty())
  {
    if (gradient)
    {
      std::fill(gradient, gradient + 3, 0.0);
    }
    return 0.0;
  }
  Index stack[128];
  int top = 0;
  stack[top++] = this->Root;
  while (top > 0)
  {
    const Node& node = this->NodeAt(stack[--top]);
    const double r[3] = { node.Centre[0] - x[0], node.Centre[1] - x[1], node.Centre[2] - x[2] };
    const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    if (r2 > this->Beta2 * node.Radius * node.Radius)
    {
      const double inv2 = 1.0 / r2;
      const double inv3 = inv2 * std::sqrt(inv2);
      const double* m = node.Moment;
      const double* q = node.Second;
      const double mr = m[0] * r[0] + m[1] * r[1] + m[2] * r[2];
      const double trace = q[0] + q[4] + q[8];
      double rqr = 0.0;
      for (int i = 0; i < 3; ++i)
      {
        rqr += r[i] * (q[3 * i] * r[0] + q[3 * i + 1] * r[1] + q[3 * i + 2] * r[2]);
      }
      // 1/2 H[C]: H_abc = -3 (delta_ab r_c + delta_ac r_b + delta_bc r_a) / |r|^5 + 15 r_a r_b r_c / |r|^7.
      const double* t = node.Third;
      double crrr = 0.0, ur = 0.0, vr = 0.0;
      for (int a = 0; a < 3; ++a)
      {
        const double* ta = t + 9 * a;
        double rtr = 0.0;
        for (int b = 0; b < 3; ++b)
        {
          rtr += r[b] * (ta[3 * b] * r[0] + ta[3 * b + 1] * r[1] + ta[3 * b + 2] * r[2]);
          ur += ta[3 * a + b] * r[b]; // u_b = sum_a C_aab
        }
        crrr += r[a] * rtr;
        vr += r[a] * (ta[0] + ta[4] + ta[8]); // v_a = sum_b C_abb
      }
      const double third = 0.5 * inv2 * (-3.0 * (2.0 * ur + vr) + 15.0 * crrr * inv2);
      w += kInverseFourPi * inv3 * (mr + trace - 3.0 * rqr * inv2 + third);
      if (gradient)
      {
        for (int a = 0; a < 3; ++a)
        {
          g[a] += kInverseFourPi * inv3 * (-m[a] + 3.0 * mr * r[a] * inv2);
        }
      }
      continue;
    }
    if (node.Left == -2)
    {
      // A cube another process holds, too near to be summed by its expansion: the halo fell short (counted; the
      // caller widens it and evaluates again). Its expansion stands in meanwhile.
      this->Opened = true;
      const double inv2 = 1.0 / std::max(r2, 1e-300);
      const double* m = node.Moment;
      w += kInverseFourPi * inv2 * std::sqrt(inv2) * (m[0] * r[0] + m[1] * r[1] + m[2] * r[2]);
      continue;
    }
    if (node.Left < 0)
    {
      for (Index s = node.Begin; s < node.End; ++s)
      {
        const double* p = &this->Points[3 * s];
        const double* n = &this->Normals[3 * s];
        const double d[3] = { p[0] - x[0], p[1] - x[1], p[2] - x[2] };
        const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        const double soft2 = this->Areas[s] / M_PI; // the regularisation radius squared (class comment)
        const double soft = d2 < soft2;
        const double e2 = soft ? soft2 : d2;
        const double inv3 = 1.0 / (e2 * std::sqrt(e2));
        const double nd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
        const double a = this->Areas[s] * kInverseFourPi * inv3;
        w += a * nd;
        if (gradient)
        {
          for (int k = 0; k < 3; ++k)
          {
            g[k] += a * (-n[k] + (soft ? 0.0 : 3.0 * nd * d[k] / e2));
          }
        }
      }
      continue;
    }
    stack[top++] = node.Left;
    stack[top++] = node.Right;
  }
  if (gradient)
  {
    std::copy(g, g + 3, gradient);
  }
  return w;
}

double WindingNumber::EvaluateDirect(const double x[3]) const
{
  double w = 0.0;
  for (size_t s = 0; s < this->Areas.size(); ++s)
  {
    const double* p = &this->Points[3 * s];
    const double* n = &this->Normals[3 * s];
    const double d[3] = { p[0] - x[0], p[1] - x[1], p[2] - x[2] };
    const double e2 = std::max(d[0] * d[0] + d[1] * d[1] + d[2] * d[2], this->Areas[s] / M_PI);
    w += this->Areas[s] * kInverseFourPi * (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / (e2 * std::sqrt(e2));
  }
  return w;
}

} // namespace meshfree
