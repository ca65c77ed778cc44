"""Pictures of reconstructed meshes for bench_surface.py: one small PNG per mesh, coloured by the signed distance
to the analytic surface (blue inside, red outside, symmetric range = the 99th percentile of |distance|), saved
with a 128-colour palette to keep the committed pictures small.

    xvfb-run -a pvpython --no-mpi surface_render.py SPEC.json
SPEC.json: a list of {"mesh": .vtp, "png": path, "title": text, "cloud": the cloud's .json}. Prints one line per
picture. Needs a display (xvfb-run when there is none).
"""
import json
import os
import sys

import numpy as np
from paraview import simple
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from surface_score import Reference  # noqa: E402

SIZE = [400, 300]


def shrink(png):
    """A 128-colour palette: the noisy error maps compress to about 40 % of their size (when PIL is there)."""
    try:
        from PIL import Image
    except ImportError:
        return
    image = Image.open(png).convert("RGB")
    image.quantize(colors=128, dither=Image.Dither.NONE).save(png, optimize=True)


def render(view, item):
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(item["mesh"])
    reader.Update()
    mesh = reader.GetOutput()
    with open(item["cloud"]) as f:
        ref = Reference.from_cloud(json.load(f))
    points = vtk_to_numpy(mesh.GetPoints().GetData()).astype(float)
    error = np.nan_to_num(ref.signed_distance(points))
    arr = numpy_to_vtk(error, deep=True)
    arr.SetName("SignedDistance")
    mesh.GetPointData().AddArray(arr)
    used = np.unique(vtk_to_numpy(mesh.GetPolys().GetConnectivityArray())) if mesh.GetNumberOfPolys() else []
    span = float(np.percentile(np.abs(error[used] if len(used) else error), 99)) or 1e-9

    source = simple.PVTrivialProducer()
    source.GetClientSideObject().SetOutput(mesh)
    display = simple.Show(source, view)
    simple.ColorBy(display, ("POINTS", "SignedDistance"))
    lut = simple.GetColorTransferFunction("SignedDistance")
    lut.ApplyPreset("Cool to Warm", True)
    lut.AutomaticRescaleRangeMode = "Never"  # each picture its own range
    lut.RescaleTransferFunction(-span, span)
    bar = simple.GetScalarBar(lut, view)
    bar.Title = "signed distance"
    bar.ComponentTitle = ""
    bar.RangeLabelFormat = "%-#.1e"
    bar.ScalarBarLength = 0.6
    bar.TitleColor = bar.LabelColor = [0.1, 0.1, 0.1]
    bar.TitleFontSize = bar.LabelFontSize = 10
    display.SetScalarBarVisibility(view, True)
    text = simple.Text(Text=item["title"])
    text_display = simple.Show(text, view)
    text_display.FontSize = 11
    text_display.Color = [0.1, 0.1, 0.1]
    text_display.WindowLocation = "Upper Left Corner"
    view.CameraPosition = [2.2, -3.2, 2.4]
    view.CameraFocalPoint = [0.0, 0.0, 0.0]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    view.GetActiveCamera().Dolly(1.3)
    simple.SaveScreenshot(item["png"], view, ImageResolution=SIZE, CompressionLevel="9")
    shrink(item["png"])
    simple.Hide(source, view)
    simple.Hide(text, view)
    display.SetScalarBarVisibility(view, False)
    simple.Delete(text)
    simple.Delete(source)
    print("wrote %s" % item["png"], flush=True)


def main():
    with open(sys.argv[1]) as f:
        items = json.load(f)
    view = simple.CreateView("RenderView")
    view.ViewSize = SIZE
    view.OrientationAxesVisibility = 0
    view.Background = [1.0, 1.0, 1.0]
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    for item in items:
        render(view, item)
    return 0


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    os._exit(code)  # skips the interpreter's teardown, which can crash pvpython once Xvfb is going away
