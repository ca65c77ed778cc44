// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class meshfree::ImplicitField
 * @brief A scalar function of space whose zero set is a surface: negative inside, positive outside.
 *
 * The point-set surfaces (MLS: algebraic spheres, WLS: blended local fits) return approximately a signed
 * distance; the SPH fluid surface returns level - c(x), c the colour field. Evaluate() may be undefined
 * where the data give no support (too few points carry weight): it returns false there and the contouring
 * leaves such places open rather than inventing a value (research/surface.md §4, "never 0").
 *
 * Evaluate() is const and thread-safe; every thread passes its own FieldScratch, whose buffers grow once
 * and are reused, so evaluation allocates nothing in the hot loop.
 */
#ifndef meshfree_ImplicitField_h
#define meshfree_ImplicitField_h

#include "Common/NeighborGrid.h"

#include <vector>

namespace meshfree
{

/// Per-thread buffers of the field evaluations.
struct FieldScratch
{
  std::vector<Index> Positions; // neighbours, as sorted positions of the field's grid
  std::vector<double> Dist2;
  std::vector<double> Work;
  std::vector<Index> MorePositions; // a second query's neighbours (PointSetSurface's wide-support samples)
  std::vector<double> MoreDist2;
};

class ImplicitField
{
public:
  virtual ~ImplicitField() = default;

  /// f(x) and, when gradient is not null, grad f(x). False where f is undefined (then value and gradient
  /// are left unspecified).
  virtual bool Evaluate(const double x[3], double& value, double gradient[3], FieldScratch& scratch) const = 0;

  /// Moves x onto the zero set (at most maxStep away) and gives the unit outward normal there: Newton's step
  /// along the gradient, x - f grad f / |grad f|^2, repeated `iterations` (>= 1) times; the normal is the
  /// last gradient evaluated. Returns false (x and normal untouched) where the field is undefined or flat or
  /// the point would move farther than maxStep.
  virtual bool Project(double x[3], double normal[3], double maxStep, int iterations, FieldScratch& scratch) const;
};

} // namespace meshfree

#endif
