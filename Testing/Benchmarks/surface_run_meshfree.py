"""MeshFree's surface filters through their pvpython proxies, for bench_surface.py (issue 13).

    pvpython --no-mpi surface_run_meshfree.py probe
        prints {"MeshlessSurface": true|false, "MeshlessNormals": true|false, ...}; exit 0 when both exist
    pvpython --no-mpi surface_run_meshfree.py surface IN.vtp OUT.vtp [Name=value ...]
        MeshlessSurface(Input=IN) with the given properties (e.g. Method=MLS NeighborCount=20 SupportRadius=0
        CellSize=0); IN's point array Normals is used by the filter when present
    pvpython --no-mpi surface_run_meshfree.py normals IN.vtp OUT.vtp [ProjectPoints=0|1 ...]
        MeshlessNormals(Input=IN)
    pvpython --no-mpi surface_run_meshfree.py jobs JOBS.json
        several of the above in one process: a JSON list of {"mode", "input", "output", "properties"}

The plugin is $MESHFREE_PLUGIN, else <source>/build/lib/paraview-5.11/plugins/MeshFree/MeshFree.so.
For each job one JSON line: update_s = the filter's own Update() (the vtkAlgorithm behind the proxy; the input
already read), read_s and write_s, the output's size; or {"error": ...}. Exit 3 when the proxies are missing,
2 when a job failed.
"""
import json
import os
import sys
import time

from surface_memory import AlgorithmMemory

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
PLUGIN_REL = os.path.join("lib", "paraview-5.11", "plugins", "MeshFree", "MeshFree.so")
PROXIES = {"surface": "MeshlessSurface", "normals": "MeshlessNormals"}


def plugin_path():
    return os.environ.get("MESHFREE_PLUGIN") or os.path.join(SOURCE, "build", PLUGIN_REL)


def load():
    """paraview.simple with the plugin loaded, and which proxies it has (None, reason when it cannot load)."""
    path = plugin_path()
    if not os.path.exists(path):
        return None, "plugin not found at %s (set MESHFREE_PLUGIN)" % path
    from paraview import simple
    try:
        simple.LoadPlugin(path, remote=False)
    except Exception as e:  # an unloadable plugin is reported, not raised
        return None, "LoadPlugin(%s) failed: %s" % (path, e)
    return simple, None


def parse_value(text):
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    return text


def run_job(simple, job):
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
    proxy_name = PROXIES[job["mode"]]
    if not hasattr(simple, proxy_name):
        return {"error": "%s not available in this build" % proxy_name}
    t0 = time.perf_counter()
    reader = simple.XMLPolyDataReader(FileName=[job["input"]])
    reader.UpdatePipeline()
    read_s = time.perf_counter() - t0
    filt = getattr(simple, proxy_name)(Input=reader)
    for name, value in job.get("properties", {}).items():
        if filt.GetProperty(name) is None:
            return {"error": "%s has no property %s (it has: %s)" % (
                proxy_name, name, ", ".join(str(p) for p in filt.ListProperties()))}
        setattr(filt, name, value)
    filt.UpdateVTKObjects()
    algorithm = filt.GetClientSideObject()
    memory = AlgorithmMemory()
    memory.start()
    t0 = time.perf_counter()
    algorithm.Update()
    update_s = time.perf_counter() - t0
    algo_mb = memory.stop()
    out = algorithm.GetOutputDataObject(0)
    if out is None or out.GetNumberOfPoints() == 0:
        return {"error": "%s produced no points" % proxy_name, "update_s": update_s}
    if not out.IsA("vtkPolyData"):  # a point set: keep the points and their arrays
        pd = vtkPolyData()
        pd.SetPoints(out.GetPoints())
        pd.GetPointData().ShallowCopy(out.GetPointData())
        out = pd
    t0 = time.perf_counter()
    w = vtkXMLPolyDataWriter()
    w.SetFileName(job["output"])
    w.SetInputData(out)
    w.SetDataModeToAppended()
    w.EncodeAppendedDataOff()
    w.SetCompressorTypeToNone()
    ok = w.Write()
    write_s = time.perf_counter() - t0
    arrays = out.GetPointData()
    result = dict(update_s=update_s, algo_mb=algo_mb, read_s=read_s, write_s=write_s, points_out=out.GetNumberOfPoints(),
                  polys_out=out.GetNumberOfPolys(),
                  arrays_out=[arrays.GetArrayName(i) for i in range(arrays.GetNumberOfArrays())])
    if not ok:
        result["error"] = "could not write " + job["output"]
    simple.Delete(filt)
    simple.Delete(reader)
    return result


def main(argv):
    if len(argv) < 1 or argv[0] not in ("probe", "surface", "normals", "jobs"):
        print(__doc__)
        return 1
    simple, why = load()
    available = {name: bool(simple is not None and hasattr(simple, name)) for name in PROXIES.values()}
    if argv[0] == "probe":
        print(json.dumps(dict(available, plugin=plugin_path(), reason=why)), flush=True)
        return 0 if all(available.values()) else 3
    if argv[0] == "jobs":
        with open(argv[1]) as f:
            jobs = json.load(f)
    else:
        props = dict(a.split("=", 1) for a in argv[3:])
        jobs = [dict(mode=argv[0], input=argv[1], output=argv[2],
                     properties={k: parse_value(v) for k, v in props.items()})]
    status = 0
    for i, job in enumerate(jobs):
        if simple is None:
            result = {"error": why}
        else:
            try:
                result = run_job(simple, job)
            except Exception as e:  # one failing job does not stop the others
                result = {"error": "%s: %s" % (type(e).__name__, e)}
        result["job"] = i
        print(json.dumps(result), flush=True)
        if "error" in result:
            status = 3 if not available.get(PROXIES[job["mode"]]) else 2
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
