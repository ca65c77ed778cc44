"""The machine a benchmark ran on, as the benchmarks' reports state it (run_benchmarks.py, bench_surface.py)."""
import os
import platform


def describe():
    """'CPU model, N cores, M GB memory, platform' from /proc where it can be read."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    memory = ""
    try:
        with open("/proc/meminfo") as f:
            memory = ", %.0f GB memory" % (int(f.readline().split()[1]) / 1024.0 ** 2)
    except (OSError, ValueError, IndexError):
        pass
    return "%s, %d cores%s, %s" % (cpu, os.cpu_count(), memory, platform.platform())
