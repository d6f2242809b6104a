#!/usr/bin/env python3
"""Peak memory of one vertexflow command, whole and by phase (issue 29, docs/benchmarks.md).

Runs COMMAND under `/usr/bin/time -v`, samples the command's resident set (VmRSS in
/proc/PID/status) every --interval seconds, and timestamps each line it prints on stderr
("vertexflow: reading ...", "flowing ...", "writing ...", "report written ..."). Prints one JSON
object: the peak RSS and wall of /usr/bin/time, the stderr lines with their times, the peak RSS
between each line and the next (the phases the CLI names), and with --trace the whole sampled
series. Each phase also gets the command's system CPU time in it and the transparent huge pages
the kernel faulted in meanwhile (the machine's thp_fault_alloc, 2 MiB each): on this VM zeroing
fresh pages is a large part of a 10M run (docs/benchmarks.md).

    bench/memory_profile.py [--interval 0.02] [--trace FILE.tsv] -- \
        build/bin/vertexflow enhance /tmp/vf29/arm1m.ply /tmp/vf29/out.ply --report /tmp/vf29/r.json

With --report, "by_phase" adds the table of docs/benchmarks.md ("Memory by phase"): seconds and
peak RSS of the read, the flow's phases (placed on the sampled clock from the report's
"seconds"), the write, the report's metrics and the parts no report field times.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import threading
import time


def rss_kib(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except (FileNotFoundError, ProcessLookupError):
        return None
    return 0


def system_seconds(pid):
    """The process's system CPU time (stime, field 15 of /proc/PID/stat)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return int(fields[12]) / os.sysconf("SC_CLK_TCK")
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return None


def huge_page_faults():
    """Transparent huge pages faulted in since boot, machine-wide (/proc/vmstat)."""
    with open("/proc/vmstat") as f:
        for line in f:
            if line.startswith("thp_fault_alloc "):
                return int(line.split()[1])
    return 0


def busy_cpu_seconds():
    """CPU time all processes have used (user, nice, system, irq, softirq, steal) per /proc/stat."""
    with open("/proc/stat") as f:
        fields = [int(x) for x in f.readline().split()[1:]]
    return (fields[0] + fields[1] + fields[2] + fields[5] + fields[6] + fields[7]) / os.sysconf("SC_CLK_TCK")


def child_of(pid):
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as f:
            kids = f.read().split()
        return int(kids[0]) if kids else None
    except FileNotFoundError:
        return None


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--interval", type=float, default=0.02)
    parser.add_argument("--trace", help="write 'seconds<TAB>RSS MiB' samples here")
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    command = args.command[1:] if args.command and args.command[0] == "--" else args.command
    if not command:
        parser.error("no command")

    busy0 = busy_cpu_seconds()
    t0 = time.monotonic()
    proc = subprocess.Popen(["/usr/bin/time", "-v"] + command, stderr=subprocess.PIPE, text=True)
    lines = []  # (seconds, text)

    def read_stderr():
        for line in proc.stderr:
            lines.append((time.monotonic() - t0, line.rstrip("\n")))

    reader = threading.Thread(target=read_stderr)
    reader.start()
    samples = []  # (seconds, KiB)
    counters = []  # (seconds, system CPU seconds of the command, huge pages faulted machine-wide)
    target = None
    while proc.poll() is None:
        if target is None:
            target = child_of(proc.pid)
        if target is not None:
            kib = rss_kib(target)
            if kib is not None:
                now = time.monotonic() - t0
                samples.append((now, kib))
                sys_s = system_seconds(target)
                if sys_s is not None:
                    counters.append((now, sys_s, huge_page_faults()))
        time.sleep(args.interval)
    reader.join()
    busy = busy_cpu_seconds() - busy0

    text = "\n".join(t for _, t in lines)
    peak = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", text)
    wall_s = None
    if wall:
        wall_s = 0.0
        for part in wall.group(1).split(":"):
            wall_s = wall_s * 60 + float(part)
    user = re.search(r"User time \(seconds\): ([\d.]+)", text)
    system = re.search(r"System time \(seconds\): ([\d.]+)", text)
    events = [(s, t) for s, t in lines if t.startswith("vertexflow:")]
    phases = []
    bounds = [(0.0, "start")] + events + [(samples[-1][0] if samples else 0.0, "end")]
    for (a, what), (b, _) in zip(bounds, bounds[1:]):
        inside = [k for s, k in samples if a <= s <= b]
        phases.append({"after": what, "from_s": round(a, 3), "to_s": round(b, 3),
                       "peak_rss_MiB": round(max(inside) / 1024, 1) if inside else None})
    result = {
        "command": command,
        "exit": proc.returncode,
        "peak_rss_MiB": round(int(peak.group(1)) / 1024, 1) if peak else None,
        "wall_s": wall_s,
        "user_s": float(user.group(1)) if user else None,
        "system_s": float(system.group(1)) if system else None,
        # CPU the rest of the machine used meanwhile (a shared machine; docs/benchmarks.md)
        "other_cpu_s": round(busy - float(user.group(1)) - float(system.group(1)), 1) if user and system else None,
        "sampled_peak_MiB": round(max(k for _, k in samples) / 1024, 1) if samples else None,
        "phases": phases,
    }
    # The phases on the sampled clock (docs/benchmarks.md, "Memory by phase"), when the command
    # wrote a report: its "seconds" place the flow's inner phases after the "flowing" line, in
    # the order the code runs them. What no report field times: the part between the read and the
    # "flowing" line, the flow's topology and set-up (the flow's wall time less its timed phases,
    # placed first: they run before the curvature), the report's metrics (between the "writing"
    # and "report written" lines, less the write) and process start and exit. An automatic solve
    # that switches to the multilevel preconditioner interleaves factorization and solve, so
    # those two windows are approximate there (their common peak is exact).
    if "--report" in command:
        report_path = command[command.index("--report") + 1]
        at = {}
        for s_, t_ in events:
            for key, prefix in [("reading", "vertexflow: reading"), ("flowing", "vertexflow: flowing"),
                                ("timed", "vertexflow: curvature "), ("writing", "vertexflow: writing"),
                                ("written", "vertexflow: report written")]:
                if t_.startswith(prefix) and key not in at:
                    at[key] = s_
        if len(at) == 5 and os.path.exists(report_path):
            with open(report_path) as f:
                seconds = json.load(f)["seconds"]

            def peak(a, b):
                inside = [k for s_, k in samples if a <= s_ <= b]
                return round(max(inside) / 1024, 1) if inside else None

            def grown(a, b):  # (system seconds, huge-page MiB) from the last sample before a to the last before b
                before = [c for c in counters if c[0] <= a]
                until = [c for c in counters if c[0] <= b]
                if not until:
                    return None, None
                first = before[-1] if before else (0.0, 0.0, counters[0][2])
                last = until[-1]
                return round(last[1] - first[1], 2), 2 * (last[2] - first[2])

            order = ["curvature", "assembly", "factorization", "solve", "projection", "guard"]
            read_end = at["reading"] + seconds["read"]
            untimed = (at["timed"] - at["flowing"]) - sum(seconds[k] for k in order)
            rows = [("read", seconds["read"], at["reading"]),
                    ("untimed: before the flow", at["flowing"] - read_end, read_end),
                    ("untimed: topology and set-up in the flow", untimed, at["flowing"])]
            t = at["flowing"] + untimed
            for k in order:
                rows.append((k, seconds[k], t))
                t += seconds[k]
            rows.append(("write", seconds["write"], at["writing"]))
            metrics_start = at["writing"] + seconds["write"]
            rows.append(("untimed: report metrics", at["written"] - metrics_start, metrics_start))
            result["by_phase"] = []
            for name, length, begin in rows:
                system_s, faulted = grown(begin, begin + length)
                result["by_phase"].append({"phase": name, "seconds": round(length, 3),
                                           "peak_rss_MiB": peak(begin, begin + length),
                                           "system_s": system_s, "huge_page_faults_MiB": faulted})
            if wall_s is not None:
                result["by_phase"].append({"phase": "untimed: start and exit",
                                           "seconds": round(wall_s - (at["written"] - at["reading"]), 3),
                                           "peak_rss_MiB": None})
            result["report_seconds"] = seconds
    if args.trace:
        with open(args.trace, "w") as f:
            for s, k in samples:
                f.write(f"{s:.3f}\t{k / 1024:.1f}\n")
    json.dump(result, sys.stdout, indent=1)
    sys.stdout.write("\n")
    return proc.returncode


if __name__ == "__main__":
    sys.exit(main())
