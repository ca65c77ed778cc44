// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class meshfree::FilledField
 * @brief A point-set surface (MLS or WLS) continued across the regions without samples by the cloud's
 *        generalized winding number (WindingNumber.h): exact where the samples are, a smooth, tight film where
 *        they are not (research/surface.md §1; issue 23 "closing what the data leave open").
 *
 * With q(x) = min_i |x - p_i| / h (h the median fit support of the samples) and the blend weight
 * t = smoothstep((q - Inner) / (1 - Inner)) (0 within Inner supports of a sample, 1 beyond one support):
 *
 *   f(x) = (1 - t) f_fit(x) + t f_w(x),        f_w(x) = (1/2 - w(x)) / max(|grad w(x)|, GradientFloor),
 *
 * f_w the first-order signed distance to the winding number's 1/2 level (in length units like f_fit). Chosen
 * by measurement on virtual scans of a sphere and a torus with unseen undersides (issue 23): Inner = 0.5
 * leaves the surface on the data as it was (vertex rms 3.79e-4 on the sphere scan, unchanged; Inner = 0.25
 * gave 5.28e-4); the gradient normalisation beat a constant scale s (1/2 - w), s = 2 h (6.35e-4 on the data,
 * rougher film); the median support beat each sample's own (folds, see HoleFilling.cxx). Where the fit is
 * undefined (too few weighted neighbours) t = 1.
 * The field is defined everywhere, so the contouring's continuation walks from the data across every hole.
 * The winding number is evaluated only where t > 0: the cost follows the filled area, not the data.
 */
#ifndef meshfree_HoleFilling_h
#define meshfree_HoleFilling_h

#include "Common/Distribution.h"
#include "Common/NeighborGrid.h"
#include "Surface/ImplicitField.h"
#include "Surface/WindingNumber.h"

#include <atomic>
#include <mutex>
#include <vector>

namespace meshfree
{

class FilledField : public ImplicitField
{
public:
  /// `fit`, `grid` (the cloud's) and the arrays must outlive this field; `supports` are the fit supports h_i in
  /// the caller's point order (h, the blend's length, is their median over h_i > 0); points,
  /// unit normals and areas (3, 3, 1 per point, same order) define the winding number, whose tree is built on
  /// the first evaluation that needs it (a well-sampled closed cloud may never need it).
  void Set(const ImplicitField& fit, const NeighborGrid& grid, const double* supports, const double* points,
    const double* normals, const double* areas, Index count, const Distribution* d = nullptr);

  /// The winding number (built on first use; thread-safe).
  const WindingNumber& Winding() const;
  bool WindingBuilt() const { return this->Built.load(); }
  /// Distributed (Set with d): how far the halo fell short of what the winding number needed (<= 0: complete;
  /// -infinity serially). Read after the evaluations.
  double Shortfall() const;

  bool Evaluate(const double x[3], double& value, double gradient[3], FieldScratch& scratch) const override;

  /// The blend weight t at x (0: the fit alone, 1: the winding number alone).
  double BlendWeight(const double x[3], FieldScratch& scratch) const;

  static constexpr double Inner = 0.5;

private:
  /// t and its gradient.
  double Blend(const double x[3], double gradient[3], FieldScratch& scratch, bool fitQueried) const;
  bool FitQueriesSamples = false;
  const ImplicitField* Fit = nullptr;
  mutable WindingNumber Tree;
  mutable std::once_flag Once;
  mutable std::atomic<bool> Built{ false };
  const double* Points = nullptr;
  const double* Normals = nullptr;
  const double* Areas = nullptr;
  Index Count = 0;
  const NeighborGrid* Grid = nullptr;
  double InverseScale = 0.0; // 1 / the median support
  WindingCubes Cubes;
  double GradientFloor = 0.0;
};

/// Areas a_i = pi r_i^2 / k of the samples for the winding number: r_i the distance to the k-th nearest
/// neighbour, so the k neighbours' disc is shared evenly (0 where r_i is 0).
std::vector<double> SampleAreas(const std::vector<double>& neighborDistance, int k);

} // namespace meshfree

#endif
