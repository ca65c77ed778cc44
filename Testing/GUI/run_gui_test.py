"""Replays one recorded ParaView GUI session (a QtTesting .xml) with the MeshFree plugin loaded and checks it.

  python3 run_gui_test.py --paraview paraview --plugin-dir DIR --data-dir DIR --out DIR --xml TEST.xml
                          [--baseline B.png --threshold T] [--expect REGEX ...] [--timeout S]

ParaView itself plays the events (`paraview --test-script`): a menu entry, property widget or button that is
missing ends the replay with "Couldn't find object" and a non-zero exit; `<pqcheck>` lines compare widget
properties; `--test-baseline` compares the active view with the baseline PNG at the end. This script adds
what the player cannot: every --expect regular expression must appear in ParaView's output (the replays print
their own checks there through the Python shell), and nothing may print a VTK error or a traceback unless
--allow-errors is given. The exit code is 0 only when all of it holds.

Re-recording a baseline: run the test with MESHFREE_GUI_REBASELINE=1 in the environment; the image
ParaView rendered is copied over the baseline (review it before committing).
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import time

FAILURES = [
    (r"Couldn't find object", "a widget, menu or button of the recording is missing"),
    (r"couldn't find action", "a menu entry of the recording is missing"),
    (r"Test .* is finished\. Success =  false", "the replay failed"),
    (r"Failed Image Test", "the view differs from the baseline"),
    (r"Unhandled (event|error)", "the player could not replay an event"),
    (r"property value is: .* Expecting: ", "a <pqcheck> did not hold"),
]
ERRORS = [r"Traceback \(most recent call last\)", r"(\n|^)ERROR: ", r"ERR\|"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--paraview", required=True)
    parser.add_argument("--plugin-dir", required=True)
    parser.add_argument("--data-dir", required=True, help="$PARAVIEW_DATA_ROOT of the recordings' file dialogs")
    parser.add_argument("--out", required=True, help="test directory: rendered and difference images")
    parser.add_argument("--xml", required=True)
    parser.add_argument("--baseline")
    parser.add_argument("--threshold", type=float, default=10.0)
    parser.add_argument("--expect", action="append", default=[], help="regex that must appear in the output")
    parser.add_argument("--allow-errors", action="store_true", help="VTK errors are part of the test")
    parser.add_argument("--timeout", type=float, default=280.0)
    args = parser.parse_args()

    name = os.path.splitext(os.path.basename(args.xml))[0]
    out = os.path.join(args.out, name)
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    command = [args.paraview, "--dr", "--plugin-search-paths=" + args.plugin_dir, "--plugins=MeshFree",
               "--data-directory=" + args.data_dir, "--test-directory=" + out, "--test-script=" + args.xml]
    if args.baseline:
        command += ["--test-baseline=" + args.baseline, "--test-threshold=%g" % args.threshold]
    command.append("--exit")
    print(" ".join(command), flush=True)

    start = time.monotonic()
    try:
        run = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=args.timeout)
        text, code = run.stdout.decode("utf-8", "replace"), run.returncode
    except subprocess.TimeoutExpired as e:
        text, code = (e.stdout or b"").decode("utf-8", "replace"), "timeout"
    elapsed = time.monotonic() - start
    # Re-printed so that ctest --output-on-failure shows the whole session; the checks below read the copy.
    sys.stdout.write(text)

    problems = []
    if code != 0:
        problems.append("paraview exited with %s" % code)
    for pattern, meaning in FAILURES:
        if re.search(pattern, text):
            problems.append(meaning + " (" + pattern + ")")
    if not args.allow_errors:
        for pattern in ERRORS:
            if re.search(pattern, text):
                problems.append("an error was printed (" + pattern + ")")
    for pattern in args.expect:
        if not re.search(pattern, text):
            problems.append("expected in the output, not found: " + pattern)

    if args.baseline and os.environ.get("MESHFREE_GUI_REBASELINE"):
        rendered = [f for f in os.listdir(out) if f.endswith(".png") and ".diff." not in f and "valid" not in f]
        if rendered:
            shutil.copyfile(os.path.join(out, sorted(rendered)[0]), args.baseline)
            print("MESHFREE_GUI_REBASELINE: copied %s over %s" % (sorted(rendered)[0], args.baseline))

    print("gui test %s: %.1f s, %s" % (name, elapsed, "passed" if not problems else "FAILED"))
    for p in problems:
        print("  - " + p)
    return 0 if not problems else 1


if __name__ == "__main__":
    sys.exit(main())
