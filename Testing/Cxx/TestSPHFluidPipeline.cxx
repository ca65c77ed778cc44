// SPH Fluid source in a VTK pipeline: reported times, snapping, the state cache (no re-simulation when going
// back or revisiting), determinism whatever the order of requests, invalidation by a property change, extra
// arrays on request, and hostile settings (clear error or warning, defined output).
#include "vtkMeshFreeSPHFluid.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <vector>

namespace
{
int failures = 0;
void Check(bool ok, const char* what)
{
  if (!ok)
  {
    std::cerr << "FAILED: " << what << "\n";
    ++failures;
  }
}

class Counter : public vtkCommand
{
public:
  static Counter* New() { return new Counter; }
  void Execute(vtkObject*, unsigned long event, void*) override
  {
    (event == vtkCommand::ErrorEvent ? this->Errors : this->Warnings)++;
  }
  int Errors = 0, Warnings = 0;
};

void Small(vtkMeshFreeSPHFluid* s)
{
  s->SetDimension(2);
  s->SetParticleSpacing(0.01);
  s->SetFluidBounds(0.0, 0.1, 0.0, 0.0, 0.0, 0.2);
  s->SetDomainBounds(0.0, 0.4, 0.0, 0.0, 0.0, 0.3);
  s->SetEndTime(0.2);
  s->SetOutputInterval(0.02);
}

vtkPolyData* At(vtkMeshFreeSPHFluid* s, double t)
{
  s->UpdateTimeStep(t);
  return s->GetOutput();
}

// Positions and velocities keyed by Id.
std::map<vtkIdType, std::vector<double>> Snapshot(vtkPolyData* out)
{
  std::map<vtkIdType, std::vector<double>> m;
  auto* ids = vtkIdTypeArray::SafeDownCast(out->GetPointData()->GetArray("Id"));
  vtkDataArray* v = out->GetPointData()->GetArray("Velocity");
  for (vtkIdType i = 0; ids && v && i < out->GetNumberOfPoints(); ++i)
  {
    double x[3], u[3];
    out->GetPoint(i, x);
    v->GetTuple(i, u);
    m[ids->GetValue(i)] = { x[0], x[1], x[2], u[0], u[1], u[2] };
  }
  return m;
}
}

int TestSPHFluidPipeline(int, char*[])
{
  vtkNew<vtkMeshFreeSPHFluid> fluid;
  Small(fluid);
  fluid->UpdateInformation();
  vtkInformation* info = fluid->GetOutputInformation(0);
  const int nt = info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  const double* times = info->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  Check(nt == 11 && times[0] == 0.0 && std::fabs(times[1] - 0.02) < 1e-15 && times[10] == 0.2, "time steps");

  vtkPolyData* out = At(fluid, 0.1);
  Check(out->GetNumberOfPoints() == 10 * 20 && out->GetNumberOfVerts() == 200, "one vertex per particle");
  for (const char* name : { "Velocity", "Density", "Pressure", "Id" })
  {
    Check(out->GetPointData()->GetArray(name) != nullptr, name);
  }
  Check(out->GetPointData()->GetArray("Acceleration") == nullptr, "no extra arrays by default");
  Check(out->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP()) == 0.1, "state at exactly t = 0.1");
  const auto at10 = Snapshot(out);
  const long stepsTo10 = fluid->GetStepsTaken();
  Check(stepsTo10 > 0, "simulated");

  // Back and forth: cached, no step taken.
  At(fluid, 0.06);
  At(fluid, 0.1);
  Check(fluid->GetStepsTaken() == stepsTo10, "revisiting / going back re-uses the cache");
  Check(Snapshot(fluid->GetOutput()) == at10, "revisited state identical");
  // A requested time between two output times: the state at exactly that time, simulated from the output time
  // before it (a few steps), the same whenever it is asked, and not disturbing the cached output states.
  const auto between = Snapshot(At(fluid, 0.1009));
  Check(fluid->GetOutput()->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP()) == 0.1009, "exactly 0.1009");
  const long partialSteps = fluid->GetStepsTaken() - stepsTo10;
  Check(partialSteps > 0 && partialSteps < stepsTo10 / 10, "simulated from t = 0.1 only");
  Check(between != at10 && between.size() == at10.size(), "a different state, same particles");
  Check(Snapshot(At(fluid, 0.1)) == at10, "the cached output state is unchanged");
  Check(Snapshot(At(fluid, 0.1009)) == between, "the same state when asked again");
  Check(fluid->GetStepsTaken() - stepsTo10 == 2 * partialSteps, "only the partial interval is simulated again");

  // Forward from the nearest cached state only.
  const long stepsBeforeForward = fluid->GetStepsTaken();
  At(fluid, 0.12);
  const long oneInterval = fluid->GetStepsTaken() - stepsBeforeForward;
  Check(oneInterval > 0 && oneInterval < stepsTo10 / 3, "forward from the nearest earlier state");
  // Past the end: the state at EndTime.
  At(fluid, 0.2 + 1e-3);
  Check(fluid->GetOutput()->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP()) == 0.2, "clamped to EndTime");

  // Determinism: a fresh source asked in another order gives the same bits.
  vtkNew<vtkMeshFreeSPHFluid> other;
  Small(other);
  At(other, 0.04);
  At(other, 0.18);
  At(other, 0.02);
  Check(Snapshot(At(other, 0.1)) == at10, "same state whatever the order of requests");

  // A property change invalidates the cache; changing it back reproduces the original.
  fluid->SetViscosity(0.5);
  const auto viscous = Snapshot(At(fluid, 0.1));
  Check(viscous != at10, "viscosity changes the result");
  fluid->SetViscosity(0.01);
  Check(Snapshot(At(fluid, 0.1)) == at10, "cache rebuilt after the change");

  // Extra arrays on request.
  fluid->ComputeAccelerationOn();
  fluid->ComputeNeighborCountOn();
  out = At(fluid, 0.1);
  Check(out->GetPointData()->GetArray("Acceleration") && out->GetPointData()->GetArray("NeighborCount"),
    "extra arrays");
  Check(Snapshot(out) == at10, "extra arrays do not change the state");

  // Hostile settings.
  {
    vtkNew<vtkMeshFreeSPHFluid> bad;
    vtkNew<Counter> counter;
    bad->AddObserver(vtkCommand::ErrorEvent, counter);
    bad->AddObserver(vtkCommand::WarningEvent, counter);
    Small(bad);
    bad->SetParticleSpacing(-0.01);
    Check(At(bad, 0.02)->GetNumberOfPoints() == 0 && counter->Errors > 0, "negative spacing: error, empty");
    bad->SetParticleSpacing(0.01);
    bad->SetFluidBounds(1.0, 1.2, 0.0, 0.0, 1.0, 1.2); // outside the domain
    const int warnings = counter->Warnings;
    Check(At(bad, 0.02)->GetNumberOfPoints() == 0 && counter->Warnings > warnings, "block outside: warning, empty");
    bad->SetFluidBounds(0.0, 0.1, 0.0, 0.0, 0.0, 0.1);
    bad->SetGasStiffness(1e8);
    bad->SetCFLNumber(0.0);
    bad->SetTimeStep(0.01);
    const int before = counter->Warnings;
    out = At(bad, 0.02);
    Check(out->GetNumberOfPoints() == 100 && counter->Warnings > before, "unstable fixed step: warning");
    double range[2];
    out->GetPointData()->GetArray("Velocity")->GetRange(range, -1);
    Check(std::isfinite(range[0]) && std::isfinite(range[1]), "no NaN");
  }
  // Progress is reported during long simulations, and abort stops them (empty output, a warning).
  {
    vtkNew<vtkMeshFreeSPHFluid> slow;
    Small(slow);
    vtkNew<Counter> counter;
    slow->AddObserver(vtkCommand::WarningEvent, counter);
    int progressEvents = 0;
    vtkNew<vtkCallbackCommand> abort;
    abort->SetClientData(&progressEvents);
    abort->SetCallback([](vtkObject* caller, unsigned long, void* clientData, void*) {
      auto* algorithm = static_cast<vtkMeshFreeSPHFluid*>(caller);
      if (algorithm->GetProgress() > 0.0 && algorithm->GetProgress() < 1.0)
      {
        ++*static_cast<int*>(clientData);
        algorithm->AbortExecuteOn();
      }
    });
    slow->AddObserver(vtkCommand::ProgressEvent, abort);
    vtkPolyData* aborted = At(slow, 0.2);
    Check(progressEvents > 0, "progress reported");
    Check(aborted->GetNumberOfPoints() == 0 && counter->Warnings > 0, "abort: warning, empty output");
    Check(slow->GetStepsTaken() < 100, "abort stops the simulation early");
  }
  if (failures == 0)
  {
    std::cout << "SPH Fluid pipeline: " << stepsTo10 << " steps to t = 0.1, one interval " << oneInterval << "\n";
  }
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
