"""MeshFree demo: the surface of a scanned object from its point cloud (Meshless Normals, Meshless Surface).

Called by ./run.sh demo, or on its own:
  pvpython --no-mpi demo_scan.py --out DIR     (plugin from $MESHFREE_PLUGIN; renders, so run under Xvfb)
Data/scan_torus.pcd is a torus seen by four scanners (3,000 points, noise along the rays, an intensity per point;
the scanners never saw a band at the bottom of the inner side). Pictures:
  scan_points.png    the cloud with its estimated, outward normals as glyphs, coloured by intensity
  scan_holes.png     seen from below, the default MLS surface with HoleFilling 'Auto' (left: closed, one piece)
                     beside HoleFilling 'Off' (right: open where the scanners saw nothing), both coloured by
                     DistanceToData (0 on the data, growing across the filled band: a Threshold on it cuts the
                     filled part away).
  scan_surface.png   the surface (normals estimated from the points alone), coloured by the scan's intensity
                     approximated onto its vertices. The band the scanners never saw is wider than the default
                     support (2 x the distance to the 20th neighbour); HoleFilling (Auto, the default: the cloud
                     encloses a volume) closes it from the points' winding number, so every method gives one closed
                     piece (DistanceToData on the vertices tells the filled part). The demo uses WLS with a wider
                     support (NeighborCount 30, SupportScale 3), which bridges the band smoothly from the data.
"""
import argparse
import os

from paraview import simple

from demo_common import black_scalar_bar, load_plugin, new_view

HERE = os.path.dirname(os.path.abspath(__file__))


def frame(view):
    """Looks at the torus from the front and above, filling the picture."""
    view.CameraPosition = [0.0, -3.2, 2.4]
    view.CameraFocalPoint = [0.0, 0.0, 0.0]
    view.CameraViewUp = [0, 0, 1]
    simple.ResetCamera(view)
    view.CameraParallelProjection = 0
    camera = simple.GetActiveCamera()
    camera.Dolly(1.25)


def intensity_colours(display, view, title):
    simple.ColorBy(display, ("POINTS", "intensity"))
    lut = simple.GetColorTransferFunction("intensity")
    lut.ApplyPreset("Viridis (matplotlib)", True)
    lut.RescaleTransferFunction(0.0, 1.0)
    display.SetScalarBarVisibility(view, True)
    black_scalar_bar(lut, view, title)


def holes(cloud, out, size):
    """out/scan_holes.png: the default MLS surface filled and not, side by side, seen from below."""
    filled = MeshlessSurface(Input=cloud, HoleFilling="Auto")  # noqa: F821
    open_ = MeshlessSurface(Input=cloud, HoleFilling="Off")  # noqa: F821
    beside = simple.Transform(Input=open_)
    beside.Transform.Translate = [2.9, 0.0, 0.0]
    view = new_view(size)
    lut = simple.GetColorTransferFunction("DistanceToData")
    lut.ApplyPreset("Inferno (matplotlib)", True)
    for source in (filled, beside):
        display = simple.Show(source, view)
        simple.ColorBy(display, ("POINTS", "DistanceToData"))
        display.Specular = 0.2
    lut.AutomaticRescaleRangeMode = "Never"
    lut.RescaleTransferFunction(0.0, 0.15)
    display.SetScalarBarVisibility(view, True)
    black_scalar_bar(lut, view, "DistanceToData").WindowLocation = "Upper Left Corner"
    view.CameraPosition = [1.45, -2.5, -3.0]
    view.CameraFocalPoint = [1.45, 0.0, 0.0]
    view.CameraViewUp = [0, 0, 1]
    simple.SetActiveView(view)
    simple.ResetCamera(view)
    simple.GetActiveCamera().Dolly(1.5)
    simple.Render(view)
    path = os.path.join(out, "scan_holes.png")
    simple.SaveScreenshot(path, view, ImageResolution=list(size))
    simple.Delete(view)
    return path


def scan_surface(out, size=(900, 600)):
    """Writes out/scan_points.png, out/scan_holes.png and out/scan_surface.png; returns their paths."""
    if "MeshlessSurface" not in globals():
        load_plugin(globals())
    cloud = simple.OpenDataFile(os.path.join(HERE, "..", "scan_torus.pcd"))
    normals = MeshlessNormals(Input=cloud)  # noqa: F821
    # CellSize 0.03: a finer mesh than the automatic one (a quarter of the wide support, 0.1) for the picture.
    surface = MeshlessSurface(Input=cloud, Method="WLS", NeighborCount=30, SupportScale=3.0,  # noqa: F821
                              CellSize=0.03)
    paths = []

    view = new_view(size)
    points = simple.Show(normals, view)
    points.SetRepresentationType("Points")
    points.PointSize = 3
    intensity_colours(points, view, "intensity")
    glyphs = simple.Glyph(Input=normals, GlyphType="Arrow")
    glyphs.OrientationArray = ["POINTS", "Normals"]
    glyphs.ScaleArray = ["POINTS", "No scale array"]
    glyphs.ScaleFactor = 0.08
    glyphs.GlyphMode = "Every Nth Point"
    glyphs.Stride = 6
    arrows = simple.Show(glyphs, view)
    simple.ColorBy(arrows, None)
    arrows.AmbientColor = arrows.DiffuseColor = [0.3, 0.3, 0.3]
    simple.SetActiveView(view)
    frame(view)
    simple.Render(view)
    paths.append(os.path.join(out, "scan_points.png"))
    simple.SaveScreenshot(paths[-1], view, ImageResolution=list(size))
    simple.Delete(view)

    paths.append(holes(cloud, out, (1200, 540)))

    view = new_view(size)
    mesh = simple.Show(surface, view)
    intensity_colours(mesh, view, "intensity")
    mesh.Specular = 0.3
    simple.SetActiveView(view)
    frame(view)
    simple.Render(view)
    paths.append(os.path.join(out, "scan_surface.png"))
    simple.SaveScreenshot(paths[-1], view, ImageResolution=list(size))
    simple.Delete(view)
    return paths


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="demo", help="folder for the PNG pictures")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    for path in scan_surface(args.out):
        print("wrote", path)


if __name__ == "__main__":
    main()
