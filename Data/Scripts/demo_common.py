"""What the demo scripts share (demo_scan.py, demo_dambreak.py, demo_spheric2.py): the plugin, a white render view,
a box from bounds, scalar bars that read on it, colouring by speed, and frames saved over time."""
import os
import sys

from paraview import simple


def load_plugin(namespace):
    """Loads MeshFree from $MESHFREE_PLUGIN into `namespace` (the caller's globals())."""
    path = os.environ.get("MESHFREE_PLUGIN")
    if not path or not os.path.exists(path):
        sys.exit("set MESHFREE_PLUGIN to build/lib/paraview-5.11/plugins/MeshFree/MeshFree.so")
    simple.LoadPlugin(path, remote=False, ns=namespace)


def new_view(size):
    """A render view of `size` pixels: white background, no orientation axes."""
    view = simple.CreateRenderView()
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    view.Background = [1, 1, 1]
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    return view


def bounds_box(bounds):
    """A Box source filling bounds [x0, x1, y0, y1, z0, z1]."""
    return simple.Box(XLength=bounds[1] - bounds[0], YLength=bounds[3] - bounds[2], ZLength=bounds[5] - bounds[4],
                      Center=[0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
                              0.5 * (bounds[4] + bounds[5])])


def black_scalar_bar(lut, view, title, component=""):
    """The scalar bar of `lut` in `view` with black title and labels (the default white is invisible on white)."""
    bar = simple.GetScalarBar(lut, view)
    bar.Title = title
    bar.ComponentTitle = component
    bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
    return bar


def speed_colours(display, view, maximum):
    """Colours `display` by the magnitude of Velocity (Jet, 0 to `maximum` m/s) with its bar; returns the bar."""
    simple.ColorBy(display, ("POINTS", "Velocity", "Magnitude"))
    lut = simple.GetColorTransferFunction("Velocity")
    lut.ApplyPreset("Jet", True)
    lut.RescaleTransferFunction(0.0, maximum)
    display.SetScalarBarVisibility(view, True)
    bar = black_scalar_bar(lut, view, "speed", "(m/s)")
    bar.TitleFontSize = 18
    bar.LabelFontSize = 16
    bar.RangeLabelFormat = "%-#.1f"
    return bar


def save_frames(view, times, out, pattern, size):
    """Renders `view` at each of `times` into out/(pattern % k); returns the paths."""
    paths = []
    for k, t in enumerate(times):
        view.ViewTime = t
        simple.Render(view)
        path = os.path.join(out, pattern % k)
        simple.SaveScreenshot(path, view, ImageResolution=list(size))
        paths.append(path)
    return paths
