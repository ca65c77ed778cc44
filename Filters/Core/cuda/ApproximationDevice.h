// MLS approximation on the CUDA device: the fast path of the moving fits (Common/MLSFastPath.h, the code the CPU
// runs), one thread per evaluation point, with a k-nearest search in the host grid's cell-sorted layout that finds
// the same neighbours, in the same order (distance, then position), as NeighborGrid::FindKNearest. Points the fast
// path cannot finish (a fit needing the eigen-decomposition or a fallback, a far query, non-finite results) are
// flagged NeedsCPU; the Approximator finishes them with its robust chain. Declared without any CUDA type; without
// CUDA or without a device every call returns false with the reason.
#ifndef MeshFree_cuda_ApproximationDevice_h
#define MeshFree_cuda_ApproximationDevice_h

#include "Common/ImageProbes.h"
#include "Common/KernelShapes.h"

#include <cstdint>
#include <memory>
#include <string>

namespace meshfree
{
namespace cuda
{

/// The largest k (neighbours per fit) the device search keeps.
constexpr int kMLSDeviceMaxNeighbors = 64;
/// Components done per kernel pass (more are done in several passes over the same neighbours).
constexpr int kMLSDeviceComponentGroup = 4;

/// The cloud as the host NeighborGrid lays it out (host pointers; copied by Upload).
struct MLSDeviceCloud
{
  std::int64_t Points = 0;                   // valid points
  const double* SortedPoints = nullptr;      // 3 * Points, cell-sorted
  const std::int64_t* SortedOrder = nullptr; // original index of each sorted position
  const double* SortedValues = nullptr;      // Points * Components, in the sorted order
  int Components = 0;
  const std::int64_t* CellRanges = nullptr; // 2 per cell (begin, end), cell i + nx (j + ny k)
  std::int64_t Dimensions[3] = { 1, 1, 1 }; // cells per axis
  double Origin[3] = { 0.0, 0.0, 0.0 };     // minimum corner of the cells
  double CellSize = 1.0;
};

/// The fit (see Approximator::MLSShape): k nearest, h = SupportFactor x d_k, weights W(d / h) of a plain weight
/// (Common/KernelShapes.h) with prefactor WeightNormalization, basis of Degree in the Dimension intrinsic axes.
struct MLSDeviceOptions
{
  int Dimension = 3;
  int Degree = 2;
  int Neighbors = 20;
  double SupportFactor = 1.1;
  int WeightKind = 1;
  double WeightNormalization = 1.0;
  double Axes[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  bool Gradients = false;
};

/// Host outputs for m points (null: not wanted). Points with NeedsCPU[i] = 1 are left untouched elsewhere.
struct MLSDeviceOutput
{
  double* Values = nullptr;          // m * C
  double* Gradients = nullptr;       // m * C * 3
  double* NeighborCounts = nullptr;  // m
  double* Conditions = nullptr;      // m: the Cholesky pivot ratio (a lower bound of kappa), not the exact kappa
  unsigned char* NeedsCPU = nullptr; // m, always written
};

/// Whether the device path handles these options (dimension 2 or 3; degree 1 or 2, or 3 in 2D; a plain weight;
/// k <= kMLSDeviceMaxNeighbors); otherwise false with the reason. Pure host logic, the same in every build.
inline bool MLSDeviceSupports(const MLSDeviceOptions& options, std::string* reason)
{
  const char* why = nullptr;
  if (options.Dimension != 2 && options.Dimension != 3)
  {
    why = "the device MLS handles clouds of intrinsic dimension 2 and 3";
  }
  else if (options.Degree < 1 || options.Degree > (options.Dimension == 2 ? 3 : 2))
  {
    why = "the device MLS handles degrees 1-2 (and 3 in 2D)";
  }
  else if (!IsPlainWeight(options.WeightKind))
  {
    why = "the device MLS handles the plain-arithmetic weights (Wendland, Poly6, W3-W5, Lucy, Spiky, CubicSpline)";
  }
  else if (options.Neighbors < 1 || options.Neighbors > kMLSDeviceMaxNeighbors)
  {
    why = "the device MLS keeps at most 64 neighbours per fit";
  }
  if (why && reason)
  {
    *reason = why;
  }
  return why == nullptr;
}

/// The device copy of one cloud and its options, evaluated at explicit or image probes in chunks.
class MLSDevice
{
public:
  MLSDevice();
  ~MLSDevice();
  MLSDevice(const MLSDevice&) = delete;
  MLSDevice& operator=(const MLSDevice&) = delete;

  /// Uploads the cloud (once) and the options. False with the reason when no device is usable or an
  /// allocation or copy fails.
  bool Upload(const MLSDeviceCloud& cloud, const MLSDeviceOptions& options, std::string* error);
  /// Evaluates at m points (interleaved x, y, z; uploaded chunk by chunk). `progress(fraction)` returning false
  /// stops between chunks (false returned, error "aborted").
  bool Evaluate(const double* xyz, std::int64_t m, const MLSDeviceOutput& out, std::string* error,
    bool (*progress)(void* data, double fraction) = nullptr, void* progressData = nullptr);
  /// Evaluates at the points of an image, generated on the device (ImagePoint), chunk by chunk.
  bool EvaluateImage(const ImageGeometry& image, const MLSDeviceOutput& out, std::string* error,
    bool (*progress)(void* data, double fraction) = nullptr, void* progressData = nullptr);
  /// Kernel time of the last Evaluate/EvaluateImage in seconds (CUDA events; transfers excluded).
  double LastKernelSeconds() const;

private:
  struct State;
  std::unique_ptr<State> S;
};

} // namespace cuda
} // namespace meshfree

#endif
