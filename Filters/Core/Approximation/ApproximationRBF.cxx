// SPDX-License-Identifier: BSD-3-Clause
// RBF: the global polyharmonic spline or RBF-PU (see ApproximationRBF.h); Auto's choice is ApproximationAuto.cxx.
#include "Approximation/ApproximationRBF.h"
#include "Approximation/ApproximationPU.h"

#include "Common/Parallel.h"
#include "Common/PolynomialBasis.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <limits>
#include <numeric>

namespace meshfree
{

bool SolvePolyharmonic(int D, int beta, int degree, double lambda, const double* xi, Index n, const double* f, int C,
  double* w, double* tail, PolyharmonicFit& fit, double* leaveOneOut)
{
  if (leaveOneOut)
  {
    std::fill(leaveOneOut, leaveOneOut + static_cast<size_t>(std::max<Index>(n, 0)) * C,
      std::numeric_limits<double>::quiet_NaN());
  }
  using Matrix = Eigen::MatrixXd;
  fit.Condition = std::numeric_limits<double>::infinity();
  fit.Regularized = false;
  if (n <= 0)
  {
    return false;
  }
  // The tail: the highest degree <= `degree` whose basis has full column rank on the centres.
  int q = 0;
  Matrix P;
  int used = -1;
  for (int d = D > 0 ? std::min(degree, kMaxBasisDegree) : 0; d >= 0 && used < 0; --d)
  {
    const RuntimeBasis basis(D, d);
    q = basis.Size();
    if (n < q)
    {
      continue;
    }
    P.resize(n, q);
    double row[kMaxBasisSize];
    for (Index j = 0; j < n; ++j)
    {
      basis.Evaluate(xi + 3 * j, row);
      for (int k = 0; k < q; ++k)
      {
        P(j, k) = row[k];
      }
    }
    Eigen::ColPivHouseholderQR<Matrix> rank(P);
    rank.setThreshold(1e-10);
    if (rank.rank() == q)
    {
      used = d;
    }
  }
  if (used < 0)
  {
    return false;
  }
  fit.Degree = used;
  Eigen::HouseholderQR<Matrix> qr(P);
  Matrix B(n, n);
  for (Index i = 0; i < n; ++i)
  {
    const double* a = xi + 3 * i;
    B(i, i) = lambda + PolyharmonicValue(beta, 0.0); // phi(0): 0 for the polyharmonic kernels, 1 for Wendland's
    for (Index j = 0; j < i; ++j)
    {
      const double* b = xi + 3 * j;
      double r2 = 0.0;
      for (int k = 0; k < D; ++k)
      {
        r2 += (a[k] - b[k]) * (a[k] - b[k]);
      }
      B(i, j) = B(j, i) = PolyharmonicValue(beta, r2);
    }
  }
  Matrix F(n, C);
  for (Index j = 0; j < n; ++j)
  {
    for (int c = 0; c < C; ++c)
    {
      F(j, c) = f[j * C + c];
    }
  }
  // Q^T (K + lambda I) Q and Q^T f.
  B.applyOnTheLeft(qr.householderQ().transpose());
  B.applyOnTheRight(qr.householderQ());
  Matrix G = F;
  G.applyOnTheLeft(qr.householderQ().transpose());
  const Index m = n - q;
  Matrix Z(m, C);
  Eigen::VectorXd inverseDiagonal; // (A^-1)_jj for the leave-one-out residuals
  if (m > 0)
  {
    const auto B22 = B.bottomRightCorner(m, m);
    Eigen::LLT<Matrix> llt(B22);
    const double rcond = llt.info() == Eigen::Success ? llt.rcond() : 0.0;
    if (llt.info() == Eigen::Success && rcond > 1.0 / kRBFMaxCondition)
    {
      Z = llt.solve(G.bottomRows(m));
      fit.Condition = 1.0 / rcond;
      if (leaveOneOut && lambda == 0.0)
      {
        // diag(Q2 B22^-1 Q2^T) = the squared column norms of L^-1 Q2^T (B22 = L L^T).
        Matrix Q2t = Matrix::Identity(n, n);
        Q2t.applyOnTheLeft(qr.householderQ().transpose());
        Matrix Y = Q2t.bottomRows(m);
        llt.matrixL().solveInPlace(Y);
        inverseDiagonal = Y.colwise().squaredNorm().transpose();
      }
    }
    else
    {
      // Least squares: the eigen-decomposition, eigenvalues below 1e-13 of the largest dropped. An
      // indefinite but regular matrix (a tail below the kernel's order) is solved exactly.
      Eigen::SelfAdjointEigenSolver<Matrix> eig(B22);
      if (eig.info() != Eigen::Success)
      {
        return false;
      }
      const Eigen::VectorXd lambdas = eig.eigenvalues();
      const double largest = lambdas.cwiseAbs().maxCoeff();
      Eigen::VectorXd inverse(m);
      double smallest = std::numeric_limits<double>::infinity();
      for (Index k = 0; k < m; ++k)
      {
        const double l = std::fabs(lambdas(k));
        const bool keep = l > 1e-13 * largest && l > 0.0;
        inverse(k) = keep ? 1.0 / lambdas(k) : 0.0;
        fit.Regularized = fit.Regularized || !keep;
        smallest = std::min(smallest, l);
      }
      Z = eig.eigenvectors() * (inverse.asDiagonal() * (eig.eigenvectors().transpose() * G.bottomRows(m)));
      fit.Condition = smallest > 0.0 ? largest / smallest : std::numeric_limits<double>::infinity();
    }
  }
  else
  {
    fit.Condition = 1.0;
  }
  // R c = G1 - B12 z; w = Q [0; z].
  Matrix T = G.topRows(q);
  if (m > 0)
  {
    T.noalias() -= B.topRightCorner(q, m) * Z;
  }
  const Matrix c = qr.matrixQR().topLeftCorner(q, q).triangularView<Eigen::Upper>().solve(T);
  Matrix Wm = Matrix::Zero(n, C);
  if (m > 0)
  {
    Wm.bottomRows(m) = Z;
  }
  Wm.applyOnTheLeft(qr.householderQ());
  bool finite = c.allFinite() && Wm.allFinite();
  if (!finite)
  {
    return false;
  }
  for (Index j = 0; j < n; ++j)
  {
    for (int k = 0; k < C; ++k)
    {
      w[j * C + k] = Wm(j, k);
    }
  }
  if (leaveOneOut && inverseDiagonal.size() == n)
  {
    for (Index j = 0; j < n; ++j)
    {
      const double d = inverseDiagonal(j);
      for (int k = 0; k < C; ++k)
      {
        leaveOneOut[j * C + k] = d > 0.0 ? Wm(j, k) / d : std::numeric_limits<double>::quiet_NaN();
      }
    }
  }
  std::fill(tail, tail + static_cast<size_t>(kMaxBasisSize) * C, 0.0);
  for (int a = 0; a < q; ++a)
  {
    for (int k = 0; k < C; ++k)
    {
      tail[a * C + k] = c(a, k);
    }
  }
  return true;
}

void EvaluatePolyharmonic(int D, int beta, const PolyharmonicFit& fit, const double* centers, const double* weights,
  const double* tail, const double* xi, int C, double* out, double* gradient)
{
  EvaluateFit(D, fit.Degree, xi, tail, C, out, gradient);
  const double* X = centers + 3 * fit.Offset;
  const double* W = weights + static_cast<size_t>(fit.Offset) * C;
  const Index n = fit.Count;
  if (C == 1 && !gradient)
  {
    // The common case (one scalar field): a tight loop.
    double sum = 0.0;
    if (D == 2 && beta == 2)
    {
      for (Index j = 0; j < n; ++j)
      {
        const double dx = xi[0] - X[3 * j], dy = xi[1] - X[3 * j + 1];
        const double r2 = dx * dx + dy * dy;
        sum += 0.5 * r2 * KernelLog(r2 > 1e-300 ? r2 : 1.0) * W[j];
      }
    }
    else
    {
      for (Index j = 0; j < n; ++j)
      {
        double r2 = 0.0;
        for (int a = 0; a < D; ++a)
        {
          r2 += (xi[a] - X[3 * j + a]) * (xi[a] - X[3 * j + a]);
        }
        sum += PolyharmonicValue(beta, r2) * W[j];
      }
    }
    out[0] += sum;
    return;
  }
  for (Index j = 0; j < n; ++j)
  {
    double d[3] = { 0, 0, 0 };
    double r2 = 0.0;
    for (int a = 0; a < D; ++a)
    {
      d[a] = xi[a] - X[3 * j + a];
      r2 += d[a] * d[a];
    }
    const double phi = PolyharmonicValue(beta, r2);
    const double* wj = W + static_cast<size_t>(j) * C;
    for (int c = 0; c < C; ++c)
    {
      out[c] += phi * wj[c];
    }
    if (gradient)
    {
      const double slope = PolyharmonicSlope(beta, r2);
      for (int a = 0; a < D; ++a)
      {
        const double g = slope * d[a];
        for (int c = 0; c < C; ++c)
        {
          gradient[a * C + c] += g * wj[c];
        }
      }
    }
  }
}

bool Approximator::RBFIsGlobal() const
{
  return this->Frame.Dimension == 0 || this->GlobalValidPoints <= this->Opts.RBFGlobalLimit;
}

int Approximator::PatchSize() const
{
  if (this->Opts.Method != ApproximationMethod::RBF)
  {
    return this->Opts.NeighborCount;
  }
  return this->Opts.PatchPoints > 0 ? this->Opts.PatchPoints
                                    : kRBFPatchPoints[std::min(std::max(this->Frame.Dimension, 0), 3)];
}

namespace
{
/// The kernel's exponent beta in the cloud's intrinsic dimension: r^2 log r in 2D, r^3 otherwise (kWendlandBeta
/// for Wendland's C2 kernel).
int KernelBeta(int dimension, RBFKernelType kernel)
{
  return kernel == RBFKernelType::WendlandC2 ? kWendlandBeta : (dimension == 2 ? 2 : 3);
}
} // namespace

bool Approximator::PrepareRBF(const double* xyz, Index count)
{
  // The dense systems are allocated here (N^2 doubles for the global fit): running out of memory is an error
  // with a message, not a crash.
  try
  {
    return this->PrepareRBFFits(xyz, count);
  }
  catch (const std::bad_alloc&)
  {
    this->RBFFits.reset();
    this->Err = "not enough memory for the RBF systems (" + std::to_string(this->GlobalValidPoints) +
      " points; lower RBFGlobalLimit to use RBF-PU)";
  }
  catch (const std::exception& e)
  {
    this->RBFFits.reset();
    this->Err = std::string("the RBF fit failed: ") + e.what();
  }
  return false;
}

bool Approximator::PrepareRBFFits(const double* xyz, Index count)
{
  this->RBFFits.reset(new RBFData);
  RBFData& rbf = *this->RBFFits;
  const int D = this->Frame.Dimension;
  const int C = this->NumberOfComponents;
  const Index n = static_cast<Index>(this->Coordinates.size() / 3);
  const double* coords = this->Coordinates.data();
  rbf.Beta = KernelBeta(D, this->Opts.RBFKernel);
  const bool wendland = rbf.Beta == kWendlandBeta;
  rbf.Global = this->RBFIsGlobal();
  this->Rep.MergedPoints = 0;
  this->Rep.Regularized = 0;

  // Duplicates: each valid point (in id order) absorbs the not yet absorbed points within 1e-10 of the
  // diameter; the values of a kept point are the mean over the points it absorbed.
  const double diameter = std::sqrt(std::pow(this->Bounds[1] - this->Bounds[0], 2) +
    std::pow(this->Bounds[3] - this->Bounds[2], 2) + std::pow(this->Bounds[5] - this->Bounds[4], 2));
  const double tolerance = std::isfinite(diameter) ? 1e-10 * diameter : 0.0;
  rbf.Kept.assign(static_cast<size_t>(n), 0);
  rbf.Values = this->Values;
  std::vector<unsigned char> absorbed(static_cast<size_t>(n), 0);
  std::vector<Index> ids;
  std::vector<double> d2;
  for (Index i = 0; i < n; ++i)
  {
    const double* x = coords + 3 * i;
    if (absorbed[i] || !(std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2])))
    {
      continue;
    }
    rbf.Kept[i] = 1;
    absorbed[i] = 1;
    this->Points.FindWithinRadius(x, tolerance, ids, &d2);
    int merged = 1;
    for (Index j : ids)
    {
      if (absorbed[j])
      {
        continue;
      }
      absorbed[j] = 1;
      ++merged;
      for (int c = 0; c < C; ++c)
      {
        rbf.Values[static_cast<size_t>(i) * C + c] += this->Values[static_cast<size_t>(j) * C + c];
      }
    }
    if (merged > 1)
    {
      this->Rep.MergedPoints += merged - 1;
      for (int c = 0; c < C; ++c)
      {
        rbf.Values[static_cast<size_t>(i) * C + c] /= merged;
      }
    }
  }
  const size_t tailStride = static_cast<size_t>(kMaxBasisSize) * C;

  if (rbf.Global)
  {
    // One fit over every kept point, centred at their centroid and scaled by the largest distance from it.
    std::vector<Index> kept;
    double centre[3] = { 0, 0, 0 };
    for (Index i = 0; i < n; ++i)
    {
      if (rbf.Kept[i])
      {
        kept.push_back(i);
      }
    }
    const Index nk = static_cast<Index>(kept.size());
    if (nk == 0)
    {
      this->Err = "the cloud has no valid point";
      return false;
    }
    // The system's rows by position (then index), and the centroid summed in that order: the fit does not
    // depend on the order of the points in the input.
    std::sort(kept.begin(), kept.end(), [coords](Index a, Index b) {
      return NeighborGrid::NeighborBefore(0.0, coords + 3 * a, a, 0.0, coords + 3 * b, b);
    });
    for (Index i : kept)
    {
      for (int a = 0; a < 3; ++a)
      {
        centre[a] += coords[3 * i + a];
      }
    }
    for (double& v : centre)
    {
      v /= static_cast<double>(nk);
    }
    double largest2 = 0.0;
    for (Index i : kept)
    {
      double r2 = 0.0;
      for (int a = 0; a < 3; ++a)
      {
        r2 += (coords[3 * i + a] - centre[a]) * (coords[3 * i + a] - centre[a]);
      }
      largest2 = std::max(largest2, r2);
    }
    double scale = largest2 > 0.0 && std::isfinite(largest2) ? std::sqrt(largest2) : 1.0;
    if (wendland)
    {
      // Coordinates in units of the support radius rho: SupportRadius, else SupportFactor x the cover radius
      // of the RBF-PU lattice (a ball holding about PatchPoints points).
      double umin[3], spacing = 1.0, cover = 1.0;
      Index counts[3];
      this->PULattice(umin, spacing, cover, counts);
      const double rho = this->Opts.SupportRadius > 0.0 ? this->Opts.SupportRadius : this->Opts.SupportFactor * cover;
      scale = rho > 0.0 && std::isfinite(rho) ? rho : scale;
    }
    PolyharmonicFit fit;
    std::copy(centre, centre + 3, fit.Origin);
    fit.InvScale = 1.0 / scale;
    fit.Count = nk;
    rbf.X.assign(3 * static_cast<size_t>(nk), 0.0);
    std::vector<double> f(static_cast<size_t>(nk) * C);
    for (Index j = 0; j < nk; ++j)
    {
      const Index id = kept[j];
      const double dx[3] = { coords[3 * id] - centre[0], coords[3 * id + 1] - centre[1], coords[3 * id + 2] - centre[2] };
      this->Frame.Project<3>(dx, fit.InvScale, &rbf.X[3 * j]);
      for (int a = D; a < 3; ++a)
      {
        rbf.X[3 * j + a] = 0.0;
      }
      std::copy_n(&rbf.Values[static_cast<size_t>(id) * C], C, &f[static_cast<size_t>(j) * C]);
    }
    rbf.W.assign(static_cast<size_t>(nk) * C, 0.0);
    rbf.Tail.assign(tailStride, 0.0);
    const double lambda = this->Opts.Smoothing * std::pow(fit.InvScale, rbf.Beta);
    std::vector<double> loo(this->RBFLeaveOneOut ? static_cast<size_t>(nk) * C : 0);
    if (!SolvePolyharmonic(D, rbf.Beta, this->Opts.TailDegree, lambda, rbf.X.data(), nk, f.data(), C, rbf.W.data(),
          rbf.Tail.data(), fit, this->RBFLeaveOneOut ? loo.data() : nullptr))
    {
      this->Err = "the global RBF system has no finite solution";
      return false;
    }
    if (this->RBFLeaveOneOut)
    {
      rbf.LeaveOneOut.assign(static_cast<size_t>(n) * C, std::numeric_limits<double>::quiet_NaN());
      for (Index j = 0; j < nk; ++j)
      {
        std::copy_n(&loo[static_cast<size_t>(j) * C], C, &rbf.LeaveOneOut[static_cast<size_t>(kept[j]) * C]);
      }
    }
    this->Rep.Regularized = fit.Regularized ? 1 : 0;
    this->Rep.DegreeUsed = fit.Degree;
    this->Rep.Centers = 1;
    rbf.Fits.push_back(fit);
    return true;
  }

  // RBF-PU: the lattice of PU-WLS (spacing from the patch size), the nodes within R of the points to evaluate.
  const int k = this->PatchSize();
  std::vector<double> nodes;
  const double cover = this->PUCentresNear(xyz, count, nodes);
  rbf.CoverRadius = cover;
  const Index nodeCount = static_cast<Index>(nodes.size() / 3);
  struct Patch
  {
    PolyharmonicFit Fit;
    std::vector<double> X, W, Tail;
    bool Ok = false;
  };
  std::vector<Patch> patches(static_cast<size_t>(nodeCount));
  PerThread<FitScratch> scratch;
  const int cap = kRBFPatchCap * k;
  ParallelFor(nodeCount, 4, [&](Index begin, Index end) {
    FitScratch& s = scratch.Local();
    std::vector<std::pair<double, Index>> chosen;
    std::vector<double> f;
    for (Index node = begin; node < end; ++node)
    {
      const double* x = &nodes[3 * node];
      double h = this->Opts.SupportRadius;
      if (!(h > 0.0))
      {
        this->Neighbors(x, k, 0.0, s, h);
        h = std::max(h, this->Opts.SupportFactor * cover);
      }
      this->Points.FindWithinRadius(x, h, s.Ids, &s.Dist2);
      const bool covered =
        std::any_of(s.Dist2.begin(), s.Dist2.end(), [&](double v) { return v < cover * cover; });
      if (!covered)
      {
        continue; // blends nothing
      }
      chosen.clear();
      for (size_t j = 0; j < s.Ids.size(); ++j)
      {
        if (rbf.Kept[s.Ids[j]])
        {
          chosen.emplace_back(s.Dist2[j], s.Ids[j]);
        }
      }
      // The nearest `cap` by the grid's neighbour order (distance, then position), in that order: the fit
      // depends neither on how the points were found nor on their order in the input.
      if (static_cast<int>(chosen.size()) > cap)
      {
        std::nth_element(chosen.begin(), chosen.begin() + (cap - 1), chosen.end(), this->NeighborOrder());
        chosen.resize(cap);
      }
      std::sort(chosen.begin(), chosen.end(), this->NeighborOrder());
      Patch& p = patches[static_cast<size_t>(node)];
      const Index m = static_cast<Index>(chosen.size());
      std::copy(x, x + 3, p.Fit.Origin);
      p.Fit.InvScale = 1.0 / h;
      p.Fit.Count = m;
      p.X.assign(3 * static_cast<size_t>(m), 0.0);
      f.resize(static_cast<size_t>(m) * C);
      for (Index j = 0; j < m; ++j)
      {
        const Index id = chosen[j].second;
        const double dx[3] = { coords[3 * id] - x[0], coords[3 * id + 1] - x[1], coords[3 * id + 2] - x[2] };
        this->Frame.Project<3>(dx, p.Fit.InvScale, &p.X[3 * j]);
        for (int a = D; a < 3; ++a)
        {
          p.X[3 * j + a] = 0.0;
        }
        std::copy_n(&rbf.Values[static_cast<size_t>(id) * C], C, &f[static_cast<size_t>(j) * C]);
      }
      p.W.assign(static_cast<size_t>(m) * C, 0.0);
      p.Tail.assign(tailStride, 0.0);
      const double lambda = this->Opts.Smoothing * std::pow(p.Fit.InvScale, rbf.Beta);
      p.Ok = SolvePolyharmonic(
        D, rbf.Beta, this->Opts.TailDegree, lambda, p.X.data(), m, f.data(), C, p.W.data(), p.Tail.data(), p.Fit);
    }
  });
  Index kept = 0;
  for (Index node = 0; node < nodeCount; ++node)
  {
    Patch& p = patches[static_cast<size_t>(node)];
    if (!p.Ok)
    {
      continue;
    }
    p.Fit.Offset = static_cast<Index>(rbf.X.size() / 3);
    rbf.X.insert(rbf.X.end(), p.X.begin(), p.X.end());
    rbf.W.insert(rbf.W.end(), p.W.begin(), p.W.end());
    rbf.Tail.insert(rbf.Tail.end(), p.Tail.begin(), p.Tail.end());
    rbf.Centers.insert(rbf.Centers.end(), &nodes[3 * node], &nodes[3 * node] + 3);
    rbf.Fits.push_back(p.Fit);
    this->Rep.Regularized += p.Fit.Regularized ? 1 : 0;
    ++kept;
  }
  this->Rep.Centers = kept;
  if (kept == 0)
  {
    this->Err = "no RBF-PU patch has a finite fit";
    return false;
  }
  rbf.CenterGrid.Build(rbf.Centers.data(), kept);
  return true;
}

Approximator::PointResult Approximator::RBFPoint(
  const double x[3], FitScratch& s, const ApproximationOutput& out, Index i) const
{
  const RBFData& rbf = *this->RBFFits;
  const int D = this->Frame.Dimension;
  const int C = this->NumberOfComponents;
  const size_t tailStride = static_cast<size_t>(kMaxBasisSize) * C;
  if (rbf.Global)
  {
    PointResult result{ false, 0, 0.0, false, false };
    const bool gradient = out.Gradients != nullptr;
    // Work: the fit's values (C) and gradients (3C).
    if (s.Work.size() < 4 * static_cast<size_t>(C) + 4)
    {
      s.Work.resize(4 * static_cast<size_t>(C) + 4);
    }
    double* local = s.Work.data();
    double* localGrad = local + C;
    bool finite = true;
    const PolyharmonicFit& fit = rbf.Fits[0];
    const double dx[3] = { x[0] - fit.Origin[0], x[1] - fit.Origin[1], x[2] - fit.Origin[2] };
    double xi[3] = { 0, 0, 0 };
    this->Frame.Project<3>(dx, fit.InvScale, xi);
    for (int a = D; a < 3; ++a)
    {
      xi[a] = 0.0;
    }
    EvaluatePolyharmonic(D, rbf.Beta, fit, rbf.X.data(), rbf.W.data(), rbf.Tail.data(), xi, C, local,
      gradient ? localGrad : nullptr);
    for (int q = 0; q < C; ++q)
    {
      finite = finite && std::isfinite(local[q]);
      if (out.Values)
      {
        out.Values[i * C + q] = local[q];
      }
      if (gradient)
      {
        double l[3] = { 0, 0, 0 };
        for (int a = 0; a < D; ++a)
        {
          l[a] = localGrad[a * C + q] * fit.InvScale;
        }
        double* g = out.Gradients + 3 * (i * C + q);
        this->Frame.Unproject(l, g);
        finite = finite && std::isfinite(g[0]) && std::isfinite(g[1]) && std::isfinite(g[2]);
      }
    }
    result.Valid = finite;
    result.Neighbors = static_cast<int>(std::min<Index>(fit.Count, 2147483647));
    result.Condition = fit.Condition;
    result.Lowered = fit.Degree < this->Opts.TailDegree;
    return result;
  }

  // RBF-PU: the fits whose node lies within R, blended as PU-WLS blends its fits (3.16-3.21).
  auto fitAt = [&](Index c, const double dx[3], double* values, double* gradients) {
    const PolyharmonicFit& fit = rbf.Fits[c];
    double xi[3] = { 0, 0, 0 };
    this->Frame.Project<3>(dx, fit.InvScale, xi);
    for (int a = D; a < 3; ++a)
    {
      xi[a] = 0.0;
    }
    EvaluatePolyharmonic(
      D, rbf.Beta, fit, rbf.X.data(), rbf.W.data(), &rbf.Tail[tailStride * c], xi, C, values, gradients);
    for (int a = 0; gradients && a < D * C; ++a)
    {
      gradients[a] *= fit.InvScale; // per unit xi -> per unit length
    }
  };
  auto info = [&](Index c, PointResult& r) {
    const PolyharmonicFit& fit = rbf.Fits[c];
    r.Neighbors = static_cast<int>(fit.Count);
    r.Condition = fit.Condition;
    r.Lowered = fit.Degree < this->Opts.TailDegree;
  };
  return this->BlendCentres(x, rbf.CenterGrid, rbf.Centers.data(), rbf.CoverRadius, s, out, i, fitAt, info);
}

} // namespace meshfree
