"""The thesis' deformable scenes (figs 4.6-4.8) with the MLS Deformable Solid source, rendered to PNG.

Call deformable_scenes(out) from the demo (the MeshFree plugin loaded), or run it alone:
  MESHFREE_PLUGIN=.../MeshFree.so xvfb-run -a pvpython --no-mpi demo_solid.py --out DIR
Pictures (each a strip of four moments of the drop):
  solid_octahedron.png   octahedron of ~299 phyxels dropped into a box (fig 4.6; phyxels coloured by von Mises stress)
  solid_ellipsoid568.png ellipsoid of 568 phyxels dropped into a cylinder (fig 4.7)
  solid_ellipsoid715.png ellipsoid of ~715 phyxels with its 990-vertex, 1976-triangle surface in a box (fig 4.8)
Geometry is scaled to bodies 0.4 m long; material from the thesis' table 4.3 (the ellipsoids 20x stiffer).
"""
import argparse
import os
import sys

from paraview import simple

from demo_common import new_view

CONTAINER = [-0.3, 0.3, -0.3, 0.3, 0.0, 1.0]
SCENES = [
    dict(name="solid_octahedron", title="Octahedron, %d phyxels, box (thesis fig 4.6)", Shape="Octahedron",
         ShapeBounds=[-0.2, 0.2, -0.2, 0.2, 0.3, 0.5], PhyxelSpacing=0.0268, Container="Box",
         YoungModulus=1e4, PoissonRatio=0.1, Density=10.0, VolumeStiffness=100.0, surface=False),
    dict(name="solid_ellipsoid568", title="Ellipsoid, %d phyxels, cylinder (thesis fig 4.7)", Shape="Ellipsoid",
         ShapeBounds=[-0.2, 0.2, -0.1, 0.1, 0.3, 0.5], PhyxelSpacing=0.0247, Container="Cylinder",
         YoungModulus=2000.0, PoissonRatio=0.2, Density=5.0, VolumeStiffness=100.0, surface=True),
    dict(name="solid_ellipsoid715", title="Ellipsoid, %d phyxels, 990-vertex surface, box (thesis fig 4.8)",
         Shape="Ellipsoid", ShapeBounds=[-0.2, 0.2, -0.08, 0.08, 0.3, 0.46], PhyxelSpacing=0.0196,
         Container="Box", YoungModulus=2000.0, PoissonRatio=0.2, Density=5.0, VolumeStiffness=100.0,
         surface=True),
]
TIMES = [0.0, 0.3, 0.45, 2.0]


def _container(kind, view):
    if kind == "Box":
        shape = simple.Box(XLength=0.6, YLength=0.6, ZLength=1.0, Center=[0, 0, 0.5])
    else:
        cylinder = simple.Cylinder(Radius=0.3, Height=1.0, Resolution=64, Center=[0, 0, 0])
        shape = simple.Transform(Input=cylinder)
        shape.Transform.Rotate = [90, 0, 0]
        shape.Transform.Translate = [0, 0, 0.5]
    display = simple.Show(shape, view)
    display.SetRepresentationType("Wireframe" if kind == "Cylinder" else "Outline")
    display.AmbientColor = display.DiffuseColor = [0.45, 0.45, 0.5]
    display.Opacity = 0.35


def _render_scene(scene, out):
    properties = {k: v for k, v in scene.items() if k not in ("name", "title", "surface")}
    solid = MLSDeformableSolid(ContainerBounds=CONTAINER, InitialVelocity=[0.6, 0.3, 0.0], Damping=1.0,
                               EndTime=2.0, OutputInterval=0.05, **properties)
    phyxels = simple.ExtractBlock(Input=solid, Selectors=["/Root/Phyxels"])
    view = new_view([480, 560])
    _container(scene["Container"], view)
    pd = simple.Show(phyxels, view)
    pd.SetRepresentationType("Point Gaussian")
    pd.GaussianRadius = 0.4 * scene["PhyxelSpacing"]
    simple.ColorBy(pd, ("POINTS", "VonMises"))
    lut = simple.GetColorTransferFunction("VonMises")
    lut.ApplyPreset("Viridis (matplotlib)", True)
    lut.RescaleTransferFunction(0.0, 2.0 * scene["YoungModulus"] * 0.02)
    if scene["surface"]:
        surface = simple.ExtractBlock(Input=solid, Selectors=["/Root/Surface"])
        sd = simple.Show(surface, view)
        sd.AmbientColor = sd.DiffuseColor = [0.85, 0.55, 0.35]
        sd.Opacity = 0.45
        sd.ColorArrayName = ["POINTS", ""]
    view.CameraPosition = [1.15, -1.6, 0.85]
    view.CameraFocalPoint = [0, 0, 0.28]
    view.CameraViewUp = [0, 0, 1]
    frames = []
    for t in TIMES:
        view.ViewTime = t
        simple.Render(view)
        frame = os.path.join(out, "%s_t%.2f.png" % (scene["name"], t))
        simple.SaveScreenshot(frame, view, ImageResolution=[480, 560])
        frames.append(frame)
    solid.UpdatePipelineInformation()
    count = solid.GetPropertyValue("NumberOfPhyxels")
    simple.Delete(view)
    return frames, scene["title"] % count


def _load_plugin():
    if "MLSDeformableSolid" not in globals():
        plugin = os.environ.get("MESHFREE_PLUGIN")
        if not plugin or not os.path.exists(plugin):
            sys.exit("set MESHFREE_PLUGIN to build/lib/paraview-5.11/plugins/MeshFree/MeshFree.so")
        simple.LoadPlugin(plugin, remote=False, ns=globals())


def deformable_scenes(out):
    """Render the three scenes; returns the paths of the three PNG strips."""
    _load_plugin()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt

    paths = []
    for scene in SCENES:
        frames, title = _render_scene(scene, out)
        fig, axes = plt.subplots(1, len(frames), figsize=(3.2 * len(frames), 4.0))
        for ax, frame, t in zip(axes, frames, TIMES):
            ax.imshow(mpimg.imread(frame))
            ax.set_title("t = %.2f s" % t)
            ax.axis("off")
            os.remove(frame)
        fig.suptitle(title)
        fig.tight_layout()
        path = os.path.join(out, scene["name"] + ".png")
        fig.savefig(path, dpi=80)
        plt.close(fig)
        paths.append(path)
    return paths


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=".")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    for p in deformable_scenes(args.out):
        print(p)
