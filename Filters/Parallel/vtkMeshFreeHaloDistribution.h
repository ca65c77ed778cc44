// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file    vtkMeshFreeHaloDistribution.h
 * @brief   The core's Distribution (Filters/Core/Common/Distribution.h) over a vtkMultiProcessController and a
 *          vtkMeshFreeHalo exchange (private to MeshFree::Filters, not wrapped).
 *
 * The local cloud is the halo's output: the rank's own points first, then the halo. Owned(i): i is one of the
 * first GetNumberOfOwnedPoints(); Key(i): the global point id; UpdateHalo: vtkMeshFreeHalo::UpdateHalo; sums,
 * maxima and gathers: the controller's AllReduce and AllGatherV; Complete(x): the halo's radius plus x's depth
 * inside the region the halo was grown from (less its distance outside). Every method but Owned, Key and Complete is collective.
 */
#ifndef vtkMeshFreeHaloDistribution_h
#define vtkMeshFreeHaloDistribution_h

#include "Common/Distribution.h"

#include "vtkType.h"

#include <cstddef>
#include <vector>

class vtkMeshFreeHalo;
class vtkMultiProcessController;

class vtkMeshFreeHaloDistribution : public meshfree::Distribution
{
public:
  /// The halo must have exchanged (Exchange, with `region` and `radius`) before; it must outlive this object, and its
  /// output's GlobalIds (the keys, read in place) must stay while this object is used.
  vtkMeshFreeHaloDistribution(
    vtkMultiProcessController* controller, vtkMeshFreeHalo* halo, const double region[6], double radius);
  /// Without a halo: n points, all this rank's own (keys: their indices); for reductions and selections only.
  vtkMeshFreeHaloDistribution(vtkMultiProcessController* controller, vtkIdType n);

  int Rank() const override;
  int Size() const override;
  bool Owned(meshfree::Index i) const override { return i < this->NumberOfOwned; }
  std::int64_t Key(meshfree::Index i) const override { return this->Ids ? static_cast<std::int64_t>(this->Ids[i]) : i; }
  void Sum(double* values, meshfree::Index count) const override;
  void Sum(std::int64_t* values, meshfree::Index count) const override;
  void Max(double* values, meshfree::Index count) const override;
  void Gather(const std::vector<double>& mine, std::vector<double>& all) const override;
  void UpdateHalo(double* values, int components) const override;
  /// The radius plus x's depth inside the region (minus its distance to the region outside it).
  double Complete(const double x[3]) const override;

  /// Space partitioned in slabs along `axis` (vtkMeshFreeSlabs): this rank owns the positions with lower <=
  /// x[axis] < upper. Without it, this rank owns every position (OwnsPosition, OwnsBall).
  void SetSlab(int axis, double lower, double upper);
  bool OwnsPosition(const double x[3]) const override;
  bool OwnsBall(const double x[3], double radius) const override;

private:
  vtkMultiProcessController* Controller;
  vtkMeshFreeHalo* Halo;
  meshfree::Index NumberOfOwned = 0;
  double Region[6];
  double Radius;
  vtkIdType Count = 0;             // points held
  const vtkIdType* Ids = nullptr; // the halo's global ids (its output's GlobalIds), null: the keys are the indices
  int SlabAxis = -1;
  double SlabLower = 0.0;
  double SlabUpper = 0.0;
};

#endif
