"""Sources never take an input nobody gave them (issue 16): SPHFluid and MLSDeformableSolid are pure sources,
whatever is active; their variants SPHFluidWithObstacles and MLSDeformableSolidFromSurface take the obstacle
surface and the body's surface as their required input and give what the plain proxies gave with that input
before; an old script's Obstacles=/Input= on the plain proxies gets a message naming the variant; the solid has no
container unless asked for one."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402
from paraview import servermanager as sm  # noqa: E402
from paraview import simple  # noqa: E402
from vtkmodules.numpy_interface import dataset_adapter as dsa  # noqa: E402
from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow, vtkStringOutputWindow  # noqa: E402

meshfree_test.load(globals())


def points(proxy, t=0.0):
    """Positions of the particles (fluid) or phyxels (solid, block 0) at time t."""
    proxy.UpdatePipeline(t)
    data = sm.Fetch(proxy)
    if data.IsA("vtkMultiBlockDataSet"):
        data = data.GetBlock(0)
    return np.array(dsa.WrapDataObject(data).Points)


def input_name(proxy):
    """The input property paraview.simple and the GUI fill with the active/selected source ('' for none)."""
    return sm.vtkSMCoreUtilities.GetInputPropertyName(proxy.SMProxy, 0) or ""


def messages(create):
    """VTK's output (errors and warnings) while `create()` runs, captured instead of printed."""
    window = vtkStringOutputWindow()
    previous = vtkOutputWindow.GetInstance()
    previous.Register(None)
    vtkOutputWindow.SetInstance(window)
    verbosity = vtkLogger.GetCurrentVerbosityCutoff()
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
    try:
        create()
    finally:
        vtkOutputWindow.SetInstance(previous)
        previous.UnRegister(None)
        vtkLogger.SetStderrVerbosity(verbosity)
    return window.GetOutput()


# The plain proxies are pure sources: no input property, in the Sources menu.
simple.SetActiveSource(None)
fluid_alone = SPHFluid()
solid_alone = MLSDeformableSolid(PhyxelSpacing=0.05)
n_fluid = len(points(fluid_alone))
n_solid = len(points(solid_alone))
assert n_fluid == 2000, n_fluid  # the default dam break: 10 x 10 x 20 particles
assert input_name(fluid_alone) == "" and input_name(solid_alone) == "", (input_name(fluid_alone), input_name(solid_alone))
pxm = sm.ProxyManager()
assert pxm.GetPrototypeProxy("sources", "SPHFluid") and pxm.GetPrototypeProxy("sources", "MLSDeformableSolid")

# Created right after another source, they ignore it (on main: SPHFluid used the sphere as Obstacles, which
# left no particle, and
# MLSDeformableSolid filled it with 6,980 phyxels at its default spacing).
sphere = simple.Sphere()
assert simple.GetActiveSource() == sphere
fluid = SPHFluid()
assert input_name(fluid) == "" and len(points(fluid)) == n_fluid
simple.SetActiveSource(sphere)
solid = MLSDeformableSolid(PhyxelSpacing=0.05)
assert input_name(solid) == "" and len(points(solid)) == n_solid
assert np.array_equal(points(solid), points(solid_alone))

# The variants: in the filters group, with a required input of the documented name.
for name, port in (("SPHFluidWithObstacles", "Obstacles"), ("MLSDeformableSolidFromSurface", "Input")):
    prototype = pxm.GetPrototypeProxy("filters", name)
    assert prototype is not None, name
    assert sm.vtkSMCoreUtilities.GetInputPropertyName(prototype, 0) == port, name
    assert prototype.GetProperty(port).GetHints() is None or \
        prototype.GetProperty(port).GetHints().FindNestedElementByName("Optional") is None, name
# The GUI's Sources and Filters menus read each proxy's own hints: both plain sources and both variants are in
# the MeshFree category.
definitions = pxm.SMProxyManager.GetProxyDefinitionManager()
for group, name in (("sources", "SPHFluid"), ("sources", "MLSDeformableSolid"), ("filters", "SPHFluidWithObstacles"),
                    ("filters", "MLSDeformableSolidFromSurface")):
    hints = definitions.GetProxyDefinition(group, name).FindNestedElementByName("Hints")
    menu = hints.FindNestedElementByName("ShowInMenu") if hints else None
    assert menu is not None and menu.GetAttribute("category") == "MeshFree", (group, name)

# SPH Fluid With Obstacles gives what SPHFluid(Obstacles=...) gave before (measured on main at b6e802a; 1e-6 m
# leaves room for another summation order of the parallel loops): a 2D column released against a box obstacle.
geometry = dict(Dimension=2, ParticleSpacing=0.01, FluidBounds=[0, 0.1, 0, 0, 0, 0.2],
                DomainBounds=[0, 0.6, 0, 0, 0, 0.3], EndTime=0.2, OutputInterval=0.1)
obstacle = simple.Box(XLength=0.1, YLength=0.4, ZLength=0.1, Center=[0.4, 0.1, 0.05])
around = SPHFluidWithObstacles(Obstacles=obstacle, **geometry)
x = points(around, 0.2)
SPH_OBST_MEAN = [0.1272352890408463, 0.0, 0.03693899339800522]
assert len(x) == 200, len(x)
assert np.allclose(x.mean(axis=0), SPH_OBST_MEAN, rtol=0, atol=1e-6), x.mean(axis=0).tolist()
free = SPHFluid(**geometry)
assert not np.allclose(points(free, 0.2).mean(axis=0), SPH_OBST_MEAN, rtol=0, atol=1e-6), "the obstacle had no effect"
# Created with the obstacle active, the variant takes it (that is what it is for).
simple.SetActiveSource(obstacle)
active = SPHFluidWithObstacles(**geometry)
assert active.Obstacles == obstacle and np.array_equal(points(active, 0.2), x)

# MLS Deformable Solid From Surface gives what MLSDeformableSolid(Input=...) gave before (main at b6e802a). The
# container is asked for explicitly: it was the default box then.
body = simple.Sphere(Radius=0.2, Center=[0, 0, 0.5], ThetaResolution=24, PhiResolution=24)
filled = MLSDeformableSolidFromSurface(Input=body, EndTime=0.2, OutputInterval=0.1, PhyxelSpacing=0.05,
                                       Container="Box", ContainerBounds=[-0.5, 0.5, -0.5, 0.5, 0.0, 1.0])
x = points(filled, 0.2)
assert len(x) == 280, len(x)
assert np.allclose(x.mean(axis=0), [0, 0, 0.30292410714285717], rtol=0, atol=1e-6), x.mean(axis=0).tolist()
simple.SetActiveSource(body)
active = MLSDeformableSolidFromSurface(PhyxelSpacing=0.05)
assert active.Input == body and len(points(active)) == 280

# Old scripts: Obstacles=/Input= on the plain proxies are ignored with an error naming the variant.
text = messages(lambda: SPHFluid(Obstacles=obstacle))
assert "SPHFluidWithObstacles" in text and "pure source" in text, text
text = messages(lambda: MLSDeformableSolid(Input=body))
assert "MLSDeformableSolidFromSurface" in text and "pure source" in text, text
assert messages(lambda: MLSDeformableSolid(PhyxelSpacing=0.05)) == ""

# The solid's default container is none: nothing stops a body moving in +x (the old default box had a wall at
# x = 0.5) or one lying below the old default box's floor at z = 0 (it was pushed up through the floor).
simple.SetActiveSource(None)
moving = MLSDeformableSolid(InitialVelocity=[2, 0, 0], Gravity=[0, 0, 0], EndTime=0.5, OutputInterval=0.25,
                            PhyxelSpacing=0.05)
assert moving.Container == "None", moving.Container
x0, x = points(moving, 0.0), points(moving, 0.5)
assert np.allclose(x - x0, [1.0, 0, 0], atol=1e-6), np.abs(x - x0 - [1.0, 0, 0]).max()
below = MLSDeformableSolid(ShapeBounds=[-0.2, 0.2, -0.15, 0.15, -0.6, -0.3], Gravity=[0, 0, 0], EndTime=0.2,
                           OutputInterval=0.1, PhyxelSpacing=0.05)
x0, x = points(below, 0.0), points(below, 0.2)
assert np.abs(x - x0).max() < 1e-9, np.abs(x - x0).max()
print("Sources take no input nobody gave them; the variants take theirs")
