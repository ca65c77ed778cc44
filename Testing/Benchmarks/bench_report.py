"""CSV schema, validation, Pareto fronts and plots of the MeshFree benchmarks (issue #7).

Pure numpy + matplotlib (Agg): runs under pvpython or /usr/bin/python3 (Debian's, which has matplotlib).
Used by run_benchmarks.py; also a checker of its output on its own:

    /usr/bin/python3 Testing/Benchmarks/bench_report.py --check DIR     # well-formed CSVs with finite values
    /usr/bin/python3 Testing/Benchmarks/bench_report.py --plot DIR      # (re)draw the PNGs and pareto.md from the CSVs
"""
import csv
import math
import os
import sys

# Exact column sets of the three files (the approximation columns are fixed by the issue).
APPROXIMATION_COLUMNS = ["method", "peer", "n", "degree", "rms_error", "max_error", "seconds", "evals_per_second"]
SPH_COLUMNS = ["case", "dimension", "resolution", "particles", "steps", "seconds", "rms_error", "max_error",
               "particle_steps_per_second"]
SOLID_COLUMNS = ["case", "integrator", "resolution", "phyxels", "steps", "seconds", "rms_error", "max_error",
                 "phyxel_steps_per_second"]
SCHEMAS = {"approximation.csv": APPROXIMATION_COLUMNS, "sph.csv": SPH_COLUMNS, "solid.csv": SOLID_COLUMNS}
# Columns that may be empty: the error of a throughput row (no reference), nothing else.
OPTIONAL = {"rms_error", "max_error"}
TEXT = {"method", "case", "integrator"}


def write_csv(path, columns, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for r in rows:
            w.writerow([_fmt(r[c]) for c in columns])


def _fmt(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return "%.6g" % v
    return str(v)


def read_csv(path):
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        rows = []
        for r in reader:
            out = {}
            for k, v in r.items():
                if k in TEXT:
                    out[k] = v
                elif v == "":
                    out[k] = None
                else:
                    out[k] = float(v)
            rows.append(out)
        return reader.fieldnames, rows


def check_dir(directory, require=("approximation.csv", "sph.csv", "solid.csv")):
    """Return a list of problems (empty when every CSV is well formed: exact header, at least one row, every
    numeric cell finite, errors >= 0, seconds > 0, and the throughput consistent with it)."""
    problems = []
    for name in require:
        path = os.path.join(directory, name)
        if not os.path.exists(path):
            problems.append("%s: missing" % name)
            continue
        try:
            header, rows = read_csv(path)
        except ValueError as e:
            problems.append("%s: unparsable (%s)" % (name, e))
            continue
        if header != SCHEMAS[name]:
            problems.append("%s: header %s, expected %s" % (name, header, SCHEMAS[name]))
            continue
        if not rows:
            problems.append("%s: no rows" % name)
        for i, r in enumerate(rows):
            where = "%s row %d (%s)" % (name, i + 2, r.get("method") or r.get("case"))
            for k, v in r.items():
                if k in TEXT:
                    if not v:
                        problems.append("%s: empty %s" % (where, k))
                    continue
                if v is None:
                    throughput = r.get("case") == "throughput"
                    if not (k in OPTIONAL and throughput):
                        problems.append("%s: empty %s" % (where, k))
                    continue
                if not math.isfinite(v):
                    problems.append("%s: %s = %r is not finite" % (where, k, v))
                elif v < 0:
                    problems.append("%s: %s = %r < 0" % (where, k, v))
            if r.get("seconds") is not None and not r["seconds"] > 0:
                problems.append("%s: seconds must be > 0" % where)
            rate = [k for k in r if k.endswith("_per_second")][0]
            if r.get(rate) is not None and not r[rate] > 0:
                problems.append("%s: %s must be > 0" % (where, rate))
            if name != "approximation.csv" and None not in (r.get("steps"), r.get("seconds"), r.get(rate)):
                work = r.get("particles", r.get("phyxels")) * r["steps"]
                expected = work / r["seconds"]
                if abs(r[rate] - expected) > 1e-4 * expected:
                    problems.append("%s: %s = %g but size x steps / seconds = %g" % (where, rate, r[rate], expected))
    return problems


# ---------------------------------------------------------------------------------------------- Pareto
def split_method(method):
    """'F1/mls_wendland_k20' -> ('F1', 'mls_wendland_k20')."""
    field, _, name = method.partition("/")
    return field, name


def label(row):
    field, name = split_method(row["method"])
    if row["peer"] == 0 and not name.startswith("sph"):
        return "%s d%d" % (name, row["degree"])
    return name


def family(row):
    """Series name for the convergence/scaling plots: the method without its tuned setting (the setting may
    change with N): 'vtk_gaussian_r2h_s2' -> 'vtk_gaussian'; ours keep the degree."""
    import re
    name = split_method(row["method"])[1]
    if row["peer"] == 0:
        return label(row)
    tokens = name.split("_")
    while len(tokens) > 2 and re.fullmatch(r"(r|s|p|n|k|step)[0-9.]+h?", tokens[-1]):
        tokens.pop()
    return "_".join(tokens)


def groups(rows):
    """{(field, n): [rows]} keeping the file's order."""
    out = {}
    for r in rows:
        field, _ = split_method(r["method"])
        out.setdefault((field, int(r["n"])), []).append(r)
    return out


def dominators(row, rows):
    """Rows strictly faster AND strictly more accurate (rms) than row."""
    return [q for q in rows if q is not row and q["seconds"] < row["seconds"] and q["rms_error"] < row["rms_error"]]


def pareto(rows):
    return [r for r in rows if not dominators(r, rows)]


def pareto_markdown(rows, field="F1", sizes=None):
    """Markdown: per N, every row sorted by time, with the front marked and, for dominated rows, the fastest
    of the rows that dominate it; then the MLS verdict for every field and N."""
    g = groups(rows)
    lines = []
    ns = sorted(n for (f, n) in g if f == field)
    if sizes:
        ns = [n for n in ns if n in sizes]
    for n in ns:
        rs = sorted(g[(field, n)], key=lambda r: r["seconds"])
        lines.append("\n%s, N = %d (%d evaluation points inside the data's hull)\n" % (field, n, _evals(rs[0])))
        lines.append("| method | peer | rms error | max error | seconds | on front | dominated by |")
        lines.append("|---|---|---|---|---|---|---|")
        for r in rs:
            d = dominators(r, rs)
            by = min(d, key=lambda q: q["seconds"]) if d else None
            lines.append("| %s | %s | %.3g | %.3g | %.4g | %s | %s |" % (
                label(r), "yes" if r["peer"] else "", r["rms_error"], r["max_error"], r["seconds"],
                "" if d else "**front**", "%s (+%d more)" % (label(by), len(d) - 1) if by else ""))
    lines.append("\nIs our MLS dominated by a peer (a peer both faster and with lower rms)? Every field and N:\n")
    lines.append("| field | N | MLS settings not dominated by any peer | peers dominating MLS degree 2 (the default) |")
    lines.append("|---|---|---|---|")
    for (f, n), rs in sorted(g.items(), key=lambda kv: (kv[0][0], kv[0][1])):
        peers = [q for q in rs if q["peer"] == 1]
        mls = [r for r in rs if r["peer"] == 0 and split_method(r["method"])[1].startswith("mls")]
        free = [label(r).replace("mls_wendland_", "") for r in mls if not dominators(r, peers)]
        d2 = [r for r in mls if int(r["degree"]) == 2]
        dom2 = dominators(d2[0], peers) if d2 else []
        lines.append("| %s | %d | %s | %s |" % (f, n, ", ".join(free) or "**none**",
                                               ", ".join(label(q) for q in dom2) or "none"))
    return "\n".join(lines) + "\n"


def _evals(r):
    return int(round(r["evals_per_second"] * r["seconds"]))


# ---------------------------------------------------------------------------------------------- plots
def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _style(row):
    name = split_method(row["method"])[1]
    if row["peer"] == 0:
        color = {"ls": "#9e9e9e", "wls": "#6d4c41", "mls": "#d62728", "pu-wls": "#ff7f0e", "sph": "#e377c2"}
        family = name.split("_")[0]
        marker = "osD^"[int(row["degree"])] if family != "sph" else "v"
        return color.get(family, "k"), marker, True
    family = name.split("_")[0]
    color = {"vtk": "#1f77b4", "scipy": "#2ca02c"}.get(family, "#17becf")
    marker = {"vtk": "x", "scipy": "+"}.get(family, "*")
    return color, marker, False


def plot_pareto(rows, path, field="F1", title=""):
    plt = _plt()
    g = groups(rows)
    ns = sorted(n for (f, n) in g if f == field)
    if not ns:
        return
    fig, axes = plt.subplots(1, len(ns), figsize=(max(5.0 * len(ns), 8.0), 5.0), squeeze=False)
    for ax, n in zip(axes[0], ns):
        rs = g[(field, n)]
        for r in rs:
            c, m, ours = _style(r)
            ax.scatter(r["seconds"], max(r["rms_error"], 1e-16), c=c, marker=m, s=30 if ours else 40,
                       linewidths=1.2, zorder=3)
        front = sorted(pareto(rs), key=lambda r: r["seconds"])
        ax.step([r["seconds"] for r in front], [max(r["rms_error"], 1e-16) for r in front], where="post",
                color="k", lw=0.8, zorder=2, label="Pareto front")
        for r in front:
            ax.annotate(label(r), (r["seconds"], max(r["rms_error"], 1e-16)), fontsize=6, xytext=(3, 3),
                        textcoords="offset points")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("run time (s), median")
        ax.set_title("%s, N = %d" % (field, n), fontsize=10)
        ax.grid(True, which="major", lw=0.3)
    axes[0][0].set_ylabel("rms error")
    # Legend: one entry per family.
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=c, marker=m, ls="", label=l) for l, c, m in (
        ("MeshFree MLS (o d0, s d1, D d2, ^ d3)", "#d62728", "D"), ("MeshFree WLS", "#6d4c41", "D"),
        ("MeshFree PU-WLS", "#ff7f0e", "D"), ("MeshFree LS", "#9e9e9e", "D"), ("MeshFree SPH", "#e377c2", "v"),
        ("VTK point interpolators", "#1f77b4", "x"), ("SciPy", "#2ca02c", "+"))]
    handles.append(Line2D([], [], color="k", lw=0.8, label="Pareto front"))
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=7, frameon=False)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.1, 1.0, 0.95))
    fig.savefig(path, dpi=80)
    plt.close(fig)


PEER_COLORS = ["#1f77b4", "#17becf", "#9467bd", "#8c564b", "#bcbd22", "#2ca02c", "#7f7f7f", "#e377c2", "#393b79",
               "#637939", "#8c6d31", "#843c39", "#7b4173", "#3182bd"]


def _series_style(key, row, index):
    """Colour/marker/line of one line-plot series: ours in their family colour (solid, marker by degree),
    peers each in its own colour (dashed)."""
    c, m, ours = _style(row)
    if not ours:
        c = PEER_COLORS[index % len(PEER_COLORS)]
    return c, m, ours


def plot_convergence(rows, path, fields=("F1", "F1_3d"), sph=None, solid=None):
    """rms error against N for the local methods (ours: MLS degrees 1-3, PU-WLS 2-3, SPH; every peer family),
    plus the SPH and solid accuracy against resolution."""
    plt = _plt()
    panels = [f for f in fields if any(split_method(r["method"])[0] == f for r in rows)]
    count = len(panels) + int(bool(sph)) + int(bool(solid))
    cols = 2 if count > 1 else 1
    nrows = (count + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(6.0 * cols, 4.4 * nrows), squeeze=False)
    axes = [a for row in axes for a in row]
    for ax in axes[count:]:
        ax.axis("off")
    for ax, field in zip(axes, panels):
        series = {}
        for r in rows:
            f, name = split_method(r["method"])
            if f != field:
                continue
            if r["peer"] == 0:
                fam = name.split("_")[0]
                d = int(r["degree"])
                if not ((fam == "mls" and d >= 1) or (fam == "pu-wls" and d >= 2) or fam == "sph"):
                    continue
            series.setdefault(family(r), []).append((r["n"], r["rms_error"], r))
        peers = 0
        for key, pts in sorted(series.items()):
            pts.sort(key=lambda p: p[0])
            c, m, ours = _series_style(key, pts[0][2], peers)
            peers += 0 if ours else 1
            ax.plot([p[0] for p in pts], [max(p[1], 1e-16) for p in pts], color=c, marker=m, lw=1.6 if ours else 0.8,
                    ms=4, ls="-" if ours else "--", label=key)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("N (data points)")
        ax.set_ylabel("rms error")
        ax.set_title("approximation convergence, %s (local methods)" % field, fontsize=10)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=6, ncol=2, frameon=False)
    k = len(panels)
    if sph:
        ax = axes[k]
        k += 1
        for case, m in (("dam_break", "o"), ("hydrostatic", "s")):
            pts = sorted((r["resolution"], r["rms_error"]) for r in sph if r["case"] == case)
            if pts:
                ax.plot(*zip(*pts), marker=m, label={"dam_break": "dam-break front vs Martin & Moyce (rms rel.)",
                                                     "hydrostatic": "hydrostatic pressure (rel. L2)"}[case])
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("resolution (particles across the column width a / height H)")
        ax.set_ylabel("relative error")
        ax.set_title("SPH fluid, 2D", fontsize=10)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7, frameon=False)
    if solid:
        ax = axes[k]
        for integ, m, ms, lw in (("SymplecticEuler", "o", 9, 3.0), ("Implicit", "s", 4, 1.0)):
            pts = sorted((r["resolution"], r["rms_error"], r["max_error"]) for r in solid
                         if r["case"] == "cantilever" and r["integrator"] == integ)
            if pts:  # both integrators relax to the same static state: thick/large marks under thin/small ones
                ax.plot([p[0] for p in pts], [p[1] for p in pts], marker=m, ms=ms, lw=lw,
                        label=integ + " (rms over the beam)")
                ax.plot([p[0] for p in pts], [p[2] for p in pts], marker=m, ms=ms, lw=lw, ls=":",
                        label=integ + " (max)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("phyxels across the beam")
        ax.set_ylabel("deflection error / reference tip deflection")
        ax.set_title("MLS solid cantilever vs Euler-Bernoulli + shear", fontsize=10)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7, frameon=False)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def plot_scaling(approx, sph, solid, path):
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.0))
    ax = axes[0]
    for key, rs in (("SPH fluid 3D (particle-steps/s)", [r for r in sph if r["case"] == "throughput"]),
                    ("MLS solid, symplectic (phyxel-steps/s)",
                     [r for r in solid if r["case"] == "throughput" and r["integrator"] == "SymplecticEuler"]),
                    ("MLS solid, implicit (phyxel-steps/s)",
                     [r for r in solid if r["case"] == "throughput" and r["integrator"] == "Implicit"])):
        if rs:
            size = "particles" if "particles" in rs[0] else "phyxels"
            pts = sorted((r[size], r[[k for k in r if k.endswith("_per_second")][0]]) for r in rs)
            ax.plot(*zip(*pts), marker="o", label=key)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("particles / phyxels")
    ax.set_ylabel("steps x size per second")
    ax.set_title("simulation throughput", fontsize=10)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7, frameon=False)
    ax = axes[1]
    series = {}
    for r in approx:
        f, name = split_method(r["method"])
        if f != "F1":
            continue
        if r["peer"] == 0 and not (name.startswith("mls") and int(r["degree"]) in (1, 2, 3)):
            continue
        series.setdefault(family(r), []).append((r["n"], r["evals_per_second"], r))
    peers = 0
    for key, pts in sorted(series.items()):
        pts.sort(key=lambda p: p[0])
        c, m, ours = _series_style(key, pts[0][2], peers)
        peers += 0 if ours else 1
        ax.plot([p[0] for p in pts], [p[1] for p in pts], color=c, marker=m, ls="-" if ours else "--",
                lw=1.6 if ours else 0.8, ms=4, label=key)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("N (data points)")
    ax.set_ylabel("evaluations per second (incl. setup)")
    ax.set_title("approximation throughput, F1 2D", fontsize=10)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=5.5, ncol=2, frameon=False)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def report(directory, machine="", command=""):
    """Draw every PNG and write pareto.md from the CSVs in directory."""
    approx = read_csv(os.path.join(directory, "approximation.csv"))[1]
    sph_path, solid_path = os.path.join(directory, "sph.csv"), os.path.join(directory, "solid.csv")
    sph = read_csv(sph_path)[1] if os.path.exists(sph_path) else []
    solid = read_csv(solid_path)[1] if os.path.exists(solid_path) else []
    plot_pareto(approx, os.path.join(directory, "pareto_F1_2d.png"), "F1",
                "Franke F1, Halton points in [0,1]^2: rms error against run time (same evaluation set)")
    plot_pareto(approx, os.path.join(directory, "pareto_F1_3d.png"), "F1_3d",
                "3D Franke-type field, Halton points in [0,1]^3: rms error against run time")
    plot_convergence(approx, os.path.join(directory, "convergence.png"), sph=sph, solid=solid)
    plot_scaling(approx, sph, solid, os.path.join(directory, "scaling.png"))
    old = os.path.join(directory, "pareto.md")
    if not machine and os.path.exists(old):  # a redraw keeps the run's machine line
        with open(old) as f:
            machine = next((l[len("Machine: "):].strip() for l in f if l.startswith("Machine: ")), "")
        with open(old) as f:
            command = command or next((l[len("Command: "):].strip() for l in f if l.startswith("Command: ")), "")
    text = "# Pareto tables (generated by bench_report.py)\n"
    if machine:
        text += "\nMachine: %s\n" % machine
    if command:
        text += "\nCommand: %s\n" % command
    text += pareto_markdown(approx, "F1")
    with open(os.path.join(directory, "pareto.md"), "w") as f:
        f.write(text)
    return text


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--check":
        p = check_dir(sys.argv[2])
        print("\n".join(p) if p else "OK")
        sys.exit(1 if p else 0)
    if len(sys.argv) == 3 and sys.argv[1] == "--plot":
        print(report(sys.argv[2]))
        sys.exit(0)
    print(__doc__)
    sys.exit(2)
