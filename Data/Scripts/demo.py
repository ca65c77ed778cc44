"""MeshFree demo: renders what the plugin computes into PNG pictures.

Run by `./run.sh demo` (pvpython under Xvfb, plugin from $MESHFREE_PLUGIN):
  pvpython --no-mpi demo.py --out DIR
Pictures:
  kernels.png           profiles W(r) of every weight function of the core, normalised in 1D/2D/3D
  kernel_wendland.png   the 2D Wendland kernel as a surface, coloured by its Laplacian
  neighbors.png         a clustered point cloud coloured by MeanNeighborDistance (the shared neighbour grid)
"""
import argparse
import os
import sys

import numpy as np
from paraview import simple
from paraview import servermanager as sm
from vtkmodules.numpy_interface import dataset_adapter as dsa

KERNELS = ["Gaussian", "Wendland", "InverseDistance", "Poly6", "W2", "W3", "W4", "W5", "Lucy", "Spiky",
           "Viscosity", "CubicSpline"]


def load_plugin():
    path = os.environ.get("MESHFREE_PLUGIN")
    if not path or not os.path.exists(path):
        sys.exit("set MESHFREE_PLUGIN to build/lib/paraview-5.11/plugins/MeshFree/MeshFree.so")
    simple.LoadPlugin(path, remote=False, ns=globals())


def kernel_profiles(out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 4, figsize=(13, 8.5), sharex=True)
    n = 121
    for ax, name in zip(axes.flat, KERNELS):
        for dim, style in ((1, ":"), (2, "--"), (3, "-")):
            src = MeshFreeKernel(Kernel=name, Dimension=dim, SupportRadius=1.0, Resolution=n)
            src.UpdatePipeline()
            data = dsa.WrapDataObject(sm.Fetch(src))
            value = np.asarray(data.PointData["Value"]).reshape(n, n)[n // 2, :]
            origin, spacing = data.VTKObject.GetOrigin(), data.VTKObject.GetSpacing()
            x = origin[0] + spacing[0] * np.arange(n)
            keep = x >= 0
            ax.plot(x[keep], value[keep], style, label="%dD" % dim)
            simple.Delete(src)
        if name == "Viscosity":
            ax.set_ylim(0, 8)  # the kernel is singular at r = 0 (capped): show its body
        ax.set_title(name)
        ax.axvline(1.0, color="0.7", lw=0.8)
        ax.grid(alpha=0.3)
    axes[0, 0].legend()
    for ax in axes[-1]:
        ax.set_xlabel("r / h")
    fig.suptitle("MeshFree weight functions W(r), support radius h = 1, normalised per dimension")
    fig.tight_layout()
    path = os.path.join(out, "kernels.png")
    fig.savefig(path, dpi=80)
    return path


def kernel_surface(out):
    src = MeshFreeKernel(Kernel="Wendland", Dimension=2, SupportRadius=1.0, Resolution=121)
    surface = simple.ExtractSurface(Input=src)
    warp = simple.WarpByScalar(Input=surface, Scalars=["POINTS", "Value"], ScaleFactor=0.4)
    view = simple.CreateRenderView()
    view.ViewSize = [800, 600]
    view.OrientationAxesVisibility = 0
    display = simple.Show(warp, view)
    simple.ColorBy(display, ("POINTS", "Laplacian"))
    display.RescaleTransferFunctionToDataRange(True, False)
    display.SetScalarBarVisibility(view, True)
    view.CameraPosition = [2.6, -3.2, 2.2]
    view.CameraFocalPoint = [0, 0, 0.2]
    view.CameraViewUp = [0, 0, 1]
    simple.Render(view)
    path = os.path.join(out, "kernel_wendland.png")
    simple.SaveScreenshot(path, view, ImageResolution=[800, 600])
    simple.Delete(view)
    return path


def neighbor_cloud(out):
    # A cloud of three blobs of very different densities: the mean distance to the 10 nearest points,
    # from the core's Morton-sorted grid, shows the local sampling density.
    blobs = [simple.PointSource(NumberOfPoints=n, Radius=r, Center=c)
             for n, r, c in ((20000, 1.0, [0, 0, 0]), (4000, 0.6, [1.8, 0, 0]), (800, 0.8, [0.6, 1.6, 0]))]
    cloud = simple.AppendDatasets(Input=blobs)
    neighbors = PointNeighbors(Input=cloud, NeighborCount=10)
    view = simple.CreateRenderView()
    view.ViewSize = [800, 600]
    view.OrientationAxesVisibility = 0
    display = simple.Show(neighbors, view)
    display.SetRepresentationType("Points")
    display.PointSize = 3
    simple.ColorBy(display, ("POINTS", "MeanNeighborDistance"))
    display.RescaleTransferFunctionToDataRange(True, False)
    display.SetScalarBarVisibility(view, True)
    simple.ResetCamera(view)
    simple.Render(view)
    path = os.path.join(out, "neighbors.png")
    simple.SaveScreenshot(path, view, ImageResolution=[800, 600])
    simple.Delete(view)
    return path


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="demo", help="folder for the PNG pictures")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    load_plugin()
    for step in (kernel_profiles, kernel_surface, neighbor_cloud):
        print("wrote", step(args.out))


if __name__ == "__main__":
    main()
