"""The memory an algorithm itself takes, for the surface benchmark's runners (bench_surface.py).

The process's peak resident memory (/usr/bin/time) includes the interpreter and, for pvpython, ParaView's
libraries (about 330 MB before any data) and the input read from disk. `algo_mb` is the peak resident memory
reached by the end of the algorithm less the resident memory just before it started (inputs read, outputs not
yet written): what the algorithm allocated on top of its input, comparable across tools whatever their
start-up. It is an upper bound when the process's earlier peak (e.g. reading) was higher.
"""
import resource


def resident_mb():
    """The process's resident memory now (MiB), from /proc/self/statm."""
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    return pages * resource.getpagesize() / 1048576.0


def peak_mb():
    """The process's peak resident memory so far (MiB; Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


class AlgorithmMemory:
    """start() before the algorithm, stop() after it: stop() returns the MiB it took (see the module's note)."""

    def __init__(self):
        self.before = None

    def start(self):
        self.before = resident_mb()

    def stop(self):
        return max(0.0, peak_mb() - self.before)
