// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the complete polynomial basis b(x) of total degree <= m in d variables (thesis 3.1, 3.8):
// k = (d+m)! / (m! d!) monomials, e.g. d = 2, m = 2: b = [1, x, y, x^2, xy, y^2].
//
// Order: by total degree, and within one degree by non-decreasing variable sequences (x before y before z),
// so the first entry is 1 and the next d entries are the linear terms. The fits evaluate the basis in
// shifted-and-scaled local coordinates xi = (x - x_c) / h (thesis 3.19-3.20), so that every entry is O(1).
//
// Each monomial i >= 1 is the product of an earlier monomial Parent(i) with one variable Variable(i); the
// tables are constexpr, so the templated evaluation below compiles to straight-line code.
#ifndef meshfree_PolynomialBasis_h
#define meshfree_PolynomialBasis_h

namespace meshfree
{

/// Number of monomials of total degree <= degree in `dimension` variables (1 for dimension 0).
constexpr int BasisSize(int dimension, int degree)
{
  // (d+m)! / (m! d!) computed incrementally to stay exact in int.
  int size = 1;
  for (int i = 1; i <= dimension; ++i)
  {
    size = size * (degree + i) / i;
  }
  return size;
}

/// Largest basis the fits use: cubic in 3D.
constexpr int kMaxBasisSize = BasisSize(3, 3);
constexpr int kMaxBasisDegree = 3;

/// Parent / variable / degree tables of the monomials (see the file comment).
struct BasisTable
{
  int Size = 1;
  int Parent[kMaxBasisSize] = {};
  int Variable[kMaxBasisSize] = {};
  int Degree[kMaxBasisSize] = {};
  int LastVariable[kMaxBasisSize] = {};
};

constexpr BasisTable MakeBasisTable(int dimension, int degree)
{
  BasisTable t{};
  t.Size = 1;
  t.Parent[0] = -1;
  t.Variable[0] = -1;
  t.Degree[0] = 0;
  t.LastVariable[0] = 0;
  int begin = 0;
  int end = 1;
  for (int k = 1; k <= degree; ++k)
  {
    for (int v = 0; v < dimension; ++v)
    {
      for (int i = begin; i < end; ++i)
      {
        if (t.LastVariable[i] <= v)
        {
          const int n = t.Size++;
          t.Parent[n] = i;
          t.Variable[n] = v;
          t.Degree[n] = k;
          t.LastVariable[n] = v;
        }
      }
    }
    begin = end;
    end = t.Size;
  }
  return t;
}

/**
 * Compile-time basis of D variables and total degree M. Evaluate() fills p[Size]; Derivatives() also fills
 * dp[a * Size + i] = d b_i / d xi_a.
 */
template <int D, int M>
struct PolynomialBasis
{
  static constexpr int Dimension = D;
  static constexpr int Degree = M;
  static constexpr int Size = BasisSize(D, M);
  static constexpr BasisTable Table = MakeBasisTable(D, M);

  static inline void Evaluate(const double* xi, double* p)
  {
    p[0] = 1.0;
    for (int i = 1; i < Size; ++i)
    {
      p[i] = p[Table.Parent[i]] * xi[Table.Variable[i]];
    }
  }

  static inline void Derivatives(const double* xi, double* p, double* dp)
  {
    p[0] = 1.0;
    for (int a = 0; a < D; ++a)
    {
      dp[a * Size] = 0.0;
    }
    for (int i = 1; i < Size; ++i)
    {
      const int parent = Table.Parent[i];
      const int v = Table.Variable[i];
      p[i] = p[parent] * xi[v];
      for (int a = 0; a < D; ++a)
      {
        dp[a * Size + i] = dp[a * Size + parent] * xi[v] + (a == v ? p[parent] : 0.0);
      }
    }
  }
};

template <int D, int M>
constexpr BasisTable PolynomialBasis<D, M>::Table;

/// Run-time version of PolynomialBasis for any dimension 0..3 and degree 0..3 (global fits, tests).
class RuntimeBasis
{
public:
  RuntimeBasis(int dimension, int degree)
    : Dim(dimension)
    , Table(MakeBasisTable(dimension, degree))
  {
  }
  int Size() const { return this->Table.Size; }
  int Dimension() const { return this->Dim; }
  void Evaluate(const double* xi, double* p) const
  {
    p[0] = 1.0;
    for (int i = 1; i < this->Table.Size; ++i)
    {
      p[i] = p[this->Table.Parent[i]] * xi[this->Table.Variable[i]];
    }
  }
  /// dp[a * Size() + i] = d b_i / d xi_a.
  void Derivatives(const double* xi, double* p, double* dp) const
  {
    const int n = this->Table.Size;
    p[0] = 1.0;
    for (int a = 0; a < this->Dim; ++a)
    {
      dp[a * n] = 0.0;
    }
    for (int i = 1; i < n; ++i)
    {
      const int parent = this->Table.Parent[i];
      const int v = this->Table.Variable[i];
      p[i] = p[parent] * xi[v];
      for (int a = 0; a < this->Dim; ++a)
      {
        dp[a * n + i] = dp[a * n + parent] * xi[v] + (a == v ? p[parent] : 0.0);
      }
    }
  }

private:
  int Dim;
  BasisTable Table;
};

} // namespace meshfree

#endif
