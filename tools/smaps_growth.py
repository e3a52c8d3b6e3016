#!/usr/bin/env python3
"""Which mappings of a running process grow: samples /proc/PID/smaps and prints, per process,
the mappings whose resident size changed most between the first and the last sample.

Used beside `avs bench soak` to find where resident memory grows (docs/reliability.md, "Soak"):

    python3 tools/smaps_growth.py --interval 15 --samples 20 $(pgrep -d' ' -f 'avs container')

With --strings, the readable text of each process's fastest-growing anonymous mapping is
printed too (reading /proc/PID/mem needs the right to trace the process, e.g. root); that is how
the growing 1 MiB blocks were recognised as Cyclone DDS receive buffers holding RTPS datagrams.
"""
import argparse
import re
import sys
import time

MAPPING = re.compile(r"^([0-9a-f]+)-([0-9a-f]+) \S+ \S+ \S+ \S+\s*(.*)$")


def sample(pid):
    """{(start, end, name): rss_kib} of one process; None when it is gone."""
    maps, key = {}, None
    try:
        with open(f"/proc/{pid}/smaps") as f:
            for line in f:
                m = MAPPING.match(line)
                if m:
                    key = (int(m.group(1), 16), int(m.group(2), 16), m.group(3) or "[anon]")
                elif line.startswith("Rss:") and key is not None:
                    maps[key] = int(line.split()[1])
    except (FileNotFoundError, ProcessLookupError):
        return None
    return maps


def printable_runs(data, min_len=6):
    return re.findall(rb"[\x20-\x7e]{%d,}" % min_len, data)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("pids", nargs="+", type=int, help="processes to sample")
    ap.add_argument("--interval", type=float, default=15.0, help="seconds between samples (15)")
    ap.add_argument("--samples", type=int, default=20, help="number of samples (20), at least 2")
    ap.add_argument("--top", type=int, default=5, help="mappings listed per process (5)")
    ap.add_argument("--strings", action="store_true",
                    help="print text found in each process's fastest-growing anonymous mapping")
    a = ap.parse_args()
    if a.samples < 2 or not a.interval > 0:
        ap.error("--samples must be at least 2 and --interval positive")

    first, last = {}, {}
    for k in range(a.samples):
        for pid in a.pids:
            m = sample(pid)
            if m is None:
                continue
            first.setdefault(pid, m)
            last[pid] = m
        print(f"smaps_growth: sample {k + 1} of {a.samples}", file=sys.stderr)
        if k + 1 < a.samples:
            time.sleep(a.interval)
    minutes = (a.samples - 1) * a.interval / 60.0

    for pid in a.pids:
        if pid not in first:
            print(f"{pid}: gone before the first sample")
            continue
        before, after = first[pid], last[pid]
        total = sum(after.values()) - sum(before.values())
        print(f"{pid}: resident {sum(after.values())} KiB, {total:+d} KiB over {minutes:.1f} min")
        changes = sorted(((after.get(key, 0) - before.get(key, 0), key)
                          for key in set(before) | set(after)), reverse=True)
        for delta, (lo, hi, name) in [c for c in changes if c[0] != 0][: a.top]:
            print(f"  {delta:+7d} KiB  {lo:x}-{hi:x} ({(hi - lo) // 1024} KiB) {name}")
        growing = [c for c in changes if c[0] > 0 and c[1][2] == "[anon]"]
        if a.strings and growing:
            lo, hi, _ = growing[0][1]
            try:
                with open(f"/proc/{pid}/mem", "rb") as mem:
                    mem.seek(lo)
                    runs = printable_runs(mem.read(hi - lo))
                print(f"  text in {lo:x}-{hi:x}: " +
                      ", ".join(sorted({r.decode() for r in runs})[:12]))
            except OSError as e:
                print(f"  text in {lo:x}-{hi:x} not read: {e}")


if __name__ == "__main__":
    main()
