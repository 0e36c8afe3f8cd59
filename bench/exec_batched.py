#!/usr/bin/python3
"""The default `handcentric audit --exec` of the Python example, one scene per request, batched
with the numbers as JSON text (`repr.py --batched --text`: up to 256 scenes of any shapes per
request) and batched with base64 arrays (`repr.py --batched`, the default), in the same run
(docs/BENCHMARKS.md, "Python"). Prints each run's wall and CPU time (both processes), and
checks that the three audits printed the same report (the plug-in's command aside).

Run from the repository after building the CLI:
    /usr/bin/python3 bench/exec_batched.py build/apps/handcentric [runs]
"""
import os
import resource
import subprocess
import sys
import time

CLI = sys.argv[1] if len(sys.argv) > 1 else "build/apps/handcentric"
RUNS = int(sys.argv[2]) if len(sys.argv) > 2 else 3
ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), ".."))
EXAMPLE = "/usr/bin/python3 " + os.path.join(ROOT, "examples", "python_representation", "repr.py")


def children_cpu():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def audit(command):
    """(wall seconds, CPU seconds of the audit and its plug-in, report)."""
    cpu, start = children_cpu(), time.perf_counter()
    out = subprocess.run([CLI, "audit", "--exec", command], check=True, capture_output=True,
                         text=True).stdout
    return time.perf_counter() - start, children_cpu() - cpu, out


def main():
    modes = [("per scene", EXAMPLE), ("batched text", EXAMPLE + " --batched --text"),
             ("batched base64", EXAMPLE + " --batched")]
    times = {name: [] for name, _ in modes}
    reports = {}
    for _ in range(RUNS):  # alternating, so that a change in the machine's load hits both
        for name, command in modes:
            wall, cpu, out = audit(command)
            times[name].append((wall, cpu))
            reports[name] = out.replace(command, EXAMPLE)
    print("handcentric audit --exec '%s [--batched [--text]]' (defaults), %d runs each, load "
          "average %.2f at the end" % (EXAMPLE, RUNS, os.getloadavg()[0]))
    for name, _ in modes:
        runs = ", ".join("%.2f s (%.2f s CPU)" % r for r in times[name])
        print("  %-14s best %.2f s wall: %s" % (name, min(w for w, _ in times[name]), runs))
    same = all(report == reports["per scene"] for report in reports.values())
    print("  reports identical (command aside): %s" % ("yes" if same else "NO"))
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
