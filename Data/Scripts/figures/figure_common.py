"""Shared pieces of the thesis-figure scripts (pvpython): plugin loading, Data/ paths, one render view,
the PNG. Each fig_*.py beside this file rebuilds one figure of the thesis from Data/ with the plugin:
  pvpython --no-mpi fig_3_3.py --out DIR     (under xvfb-run when there is no display)
The plugin comes from $MESHFREE_PLUGIN (build/lib/paraview-5.11/plugins/MeshFree/MeshFree.so)."""
import argparse
import os
import sys

from paraview import simple

DATA = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def start(description):
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", default=".", help="folder for the PNG")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    plugin = os.environ.get("MESHFREE_PLUGIN")
    if not plugin or not os.path.exists(plugin):
        sys.exit("set MESHFREE_PLUGIN to build/lib/paraview-5.11/plugins/MeshFree/MeshFree.so")
    simple.LoadPlugin(plugin, remote=False, ns=sys.modules["__main__"].__dict__)
    return args.out


def data(name):
    return os.path.join(DATA, name)


def view(size=(800, 600)):
    v = simple.CreateRenderView()
    v.ViewSize = list(size)
    v.OrientationAxesVisibility = 1
    return v


def points(source, v, color=(0.1, 0.1, 0.1), size=8):
    d = simple.Show(source, v)
    d.SetRepresentationType("Points")
    d.RenderPointsAsSpheres = 1
    d.PointSize = size
    d.ColorArrayName = ["POINTS", ""]
    d.AmbientColor = d.DiffuseColor = list(color)
    return d


def colored(source, v, array, association="POINTS"):
    d = simple.Show(source, v)
    simple.ColorBy(d, (association, array))
    d.RescaleTransferFunctionToDataRange(True, False)
    d.SetScalarBarVisibility(v, True)
    return d


def save(v, out, name, camera=None):
    if camera:
        v.CameraPosition, v.CameraFocalPoint, v.CameraViewUp = camera
        v.ResetCamera(False)
    else:
        simple.ResetCamera(v)
    simple.Render(v)
    path = os.path.join(out, name)
    simple.SaveScreenshot(path, v, ImageResolution=list(v.ViewSize))
    print("wrote", path)
    return path
