// SPDX-License-Identifier: BSD-3-Clause
// Barnes-Hut generalized winding number of an oriented cloud (WindingNumber.h).
#include "Surface/WindingNumber.h"

#include <algorithm>
#include <cmath>

namespace meshfree
{

namespace
{
constexpr double kInverseFourPi = 0.25 / M_PI;
constexpr Index kLeafSize = 32; // a node holds 44 doubles: bigger leaves keep the tree at about 1.5 doubles per point
} // namespace

void WindingNumber::Build(const double* points, const double* normals, const double* areas, Index count, double beta)
{
  this->Nodes.clear();
  this->Points.clear();
  this->Normals.clear();
  this->Areas.clear();
  this->Soft2.clear();
  this->Total = 0.0;
  this->Beta2 = std::max(1.0, beta) * std::max(1.0, beta);
  std::vector<Index> order;
  for (Index i = 0; i < count; ++i)
  {
    const double* p = points + 3 * i;
    const double* n = normals + 3 * i;
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (std::isfinite(p[0] + p[1] + p[2]) && len > 0.0 && std::isfinite(len) && areas[i] > 0.0 &&
      std::isfinite(areas[i]))
    {
      order.push_back(i);
    }
  }
  if (order.empty())
  {
    return;
  }
  // The splits move the points themselves (contiguous, cache-friendly), not indices into them.
  std::vector<Item> items(order.size());
  for (size_t s = 0; s < order.size(); ++s)
  {
    const Index i = order[s];
    items[s] = Item{ { points[3 * i], points[3 * i + 1], points[3 * i + 2] }, i };
  }
  this->Nodes.reserve(static_cast<size_t>(4 * (order.size() / kLeafSize + 1)));
  this->BuildNode(0, static_cast<Index>(items.size()), items);
  for (size_t s = 0; s < items.size(); ++s)
  {
    order[s] = items[s].Id;
  }
  // Copy the points in tree order (leaves read them contiguously).
  const size_t m = order.size();
  this->Points.resize(3 * m);
  this->Normals.resize(3 * m);
  this->Areas.resize(m);
  this->Soft2.resize(m);
  for (size_t s = 0; s < m; ++s)
  {
    const Index i = order[s];
    const double* n = normals + 3 * i;
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int a = 0; a < 3; ++a)
    {
      this->Points[3 * s + a] = points[3 * i + a];
      this->Normals[3 * s + a] = n[a] / len;
    }
    this->Areas[s] = areas[i];
    this->Soft2[s] = areas[i] / M_PI;
    this->Total += areas[i];
  }
  // Moments bottom-up (children always follow their parent in this->Nodes): leaves sum their points, inner
  // nodes combine their children's moments moved to their own centre (O(n) in all).
  for (size_t k = this->Nodes.size(); k-- > 0;)
  {
    Node& node = this->Nodes[k];
    std::fill(node.Moment, node.Moment + 3, 0.0);
    std::fill(node.Second, node.Second + 9, 0.0);
    std::fill(node.Third, node.Third + 27, 0.0);
    double area = 0.0, c[3] = { 0, 0, 0 };
    if (node.Left < 0)
    {
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
        const double d[3] = { p[0] - node.Centre[0], p[1] - node.Centre[1], p[2] - node.Centre[2] };
        for (int i = 0; i < 3; ++i)
        {
          node.Moment[i] += a * n[i];
          for (int j = 0; j < 3; ++j)
          {
            node.Second[3 * i + j] += a * d[i] * n[j];
            for (int l = 0; l < 3; ++l)
            {
              node.Third[9 * i + 3 * j + l] += a * n[i] * d[j] * d[l];
            }
          }
        }
        r2 = std::max(r2, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      }
      node.Radius = std::sqrt(r2);
      node.Area = area;
      continue;
    }
    const Node* children[2] = { &this->Nodes[node.Left], &this->Nodes[node.Right] };
    for (const Node* child : children)
    {
      area += child->Area;
      for (int a = 0; a < 3; ++a)
      {
        c[a] += child->Area * child->Centre[a];
      }
    }
    for (int a = 0; a < 3; ++a)
    {
      node.Centre[a] = c[a] / area;
    }
    node.Area = area;
    node.Radius = 0.0;
    for (const Node* child : children)
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
      node.Radius = std::max(node.Radius, std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) + child->Radius);
    }
  }
}

Index WindingNumber::BuildNode(Index begin, Index end, std::vector<Item>& items)
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
  if (this->Nodes.empty())
  {
    return 0.0;
  }
  const double* m = this->Nodes[0].Moment;
  return std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
}

double WindingNumber::Evaluate(const double x[3], double gradient[3]) const
{
  double w = 0.0, g[3] = { 0.0, 0.0, 0.0 };
  if (this->Nodes.empty())
  {
    if (gradient)
    {
      std::fill(gradient, gradient + 3, 0.0);
    }
    return 0.0;
  }
  Index stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0)
  {
    const Node& node = this->Nodes[stack[--top]];
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
    if (node.Left < 0)
    {
      for (Index s = node.Begin; s < node.End; ++s)
      {
        const double* p = &this->Points[3 * s];
        const double* n = &this->Normals[3 * s];
        const double d[3] = { p[0] - x[0], p[1] - x[1], p[2] - x[2] };
        const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        const double soft = d2 < this->Soft2[s];
        const double e2 = soft ? this->Soft2[s] : d2;
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
    const double e2 = std::max(d[0] * d[0] + d[1] * d[1] + d[2] * d[2], this->Soft2[s]);
    w += this->Areas[s] * kInverseFourPi * (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / (e2 * std::sqrt(e2));
  }
  return w;
}

} // namespace meshfree
