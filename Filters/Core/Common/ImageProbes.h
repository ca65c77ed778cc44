// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the points of an axis-aligned image (origin, spacing, dimensions; x fastest), computed on the fly
// by one MESHFREE_HD function, so that the CPU loops and the CUDA kernels probe the very same positions without
// storing them (10^7 probes would be 240 MB to build and upload).
#ifndef meshfree_ImageProbes_h
#define meshfree_ImageProbes_h

#include "Common/HostDevice.h"

#include <cstdint>

namespace meshfree
{

/// An axis-aligned lattice of Dimensions[0] x [1] x [2] points: point i has indices (i % nx, (i / nx) % ny,
/// i / (nx ny)) and position Origin + index * Spacing per axis.
struct ImageGeometry
{
  double Origin[3] = { 0.0, 0.0, 0.0 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  std::int64_t Dimensions[3] = { 1, 1, 1 };

  std::int64_t NumberOfPoints() const { return this->Dimensions[0] * this->Dimensions[1] * this->Dimensions[2]; }
};

/// Position of point i of the image g.
MESHFREE_HD inline void ImagePoint(const ImageGeometry& g, std::int64_t i, double x[3])
{
  const std::int64_t nx = g.Dimensions[0], ny = g.Dimensions[1];
  const std::int64_t ix = i % nx;
  const std::int64_t rest = i / nx;
  const std::int64_t iy = rest % ny;
  const std::int64_t iz = rest / ny;
  x[0] = g.Origin[0] + static_cast<double>(ix) * g.Spacing[0];
  x[1] = g.Origin[1] + static_cast<double>(iy) * g.Spacing[1];
  x[2] = g.Origin[2] + static_cast<double>(iz) * g.Spacing[2];
}

} // namespace meshfree

#endif
