#!/usr/bin/env python3
"""An Ethernet link with loss and delay, for the network-fault test (tests/deploy/netfaults.sh).

Why not `tc netem`: the kernels of our CI machines are built without sch_netem
(CONFIG_NET_SCH_NETEM is not set; `tc qdisc add ... netem` says "Specified qdisc kind is
unknown"), and no other qdisc here delays packets by a fixed time. This program is the link
instead: two TAP devices, one becomes a host's eth0, the other a port of the switch's bridge,
and every Ethernet frame between them passes through here, where it is dropped with
probability LOSS or held for DELAY ms, per direction, independently of the other frames.

  impaired_link.py HOST_IF SWITCH_IF CONTROL_FILE STATS_FILE

creates the two TAP devices (in the caller's network namespace; the caller moves them into
the host's and the switch's) and forwards until SIGTERM/SIGINT. CONTROL_FILE holds
"loss=<0..1> delay_ms=<ms>" and is read again whenever it changes (a missing file means a
clean link). STATS_FILE is rewritten every 0.5 s and at exit: per direction, frames in,
dropped, forwarded, and the control in force. The random generator is seeded (--seed) so a
run drops the same pattern of frames.
"""
import argparse
import collections
import fcntl
import os
import random
import select
import signal
import struct
import sys
import time

TUNSETIFF = 0x400454CA
IFF_TAP = 0x0002
IFF_NO_PI = 0x1000
MAX_FRAME = 65536


def open_tap(name):
    fd = os.open("/dev/net/tun", os.O_RDWR | os.O_NONBLOCK)
    fcntl.ioctl(fd, TUNSETIFF, struct.pack("16sH", name.encode(), IFF_TAP | IFF_NO_PI))
    return fd


def read_control(path, current):
    """(loss, delay_s) from PATH; the current values if the file is malformed (with a note)."""
    try:
        with open(path) as f:
            text = f.read()
    except FileNotFoundError:
        return 0.0, 0.0
    values = dict(word.split("=", 1) for word in text.split() if "=" in word)
    try:
        loss = float(values.get("loss", 0))
        delay_s = float(values.get("delay_ms", 0)) / 1000.0
    except ValueError:
        print(f"impaired_link: {path}: expected 'loss=<0..1> delay_ms=<ms>', got {text!r}",
              file=sys.stderr)
        return current
    if not (0.0 <= loss <= 1.0) or not (0.0 <= delay_s <= 10.0):
        print(f"impaired_link: {path}: loss must be in [0, 1] and delay_ms in [0, 10000]",
              file=sys.stderr)
        return current
    return loss, delay_s


class Direction:
    def __init__(self, name, src, dst):
        self.name, self.src, self.dst = name, src, dst
        self.queue = collections.deque()  # (due time, frame): one delay for all, so FIFO
        self.frames_in = self.dropped = self.forwarded = self.write_errors = 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("host_if")
    ap.add_argument("switch_if")
    ap.add_argument("control_file")
    ap.add_argument("stats_file")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()

    rng = random.Random(args.seed)
    host_fd, switch_fd = open_tap(args.host_if), open_tap(args.switch_if)
    directions = {host_fd: Direction("host_to_switch", host_fd, switch_fd),
                  switch_fd: Direction("switch_to_host", switch_fd, host_fd)}
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))

    loss, delay_s = 0.0, 0.0
    control_mtime = None
    next_stats = 0.0

    def write_stats():
        tmp = args.stats_file + ".tmp"
        with open(tmp, "w") as f:
            f.write(f"loss {loss}\ndelay_ms {delay_s * 1000:g}\n")
            for d in directions.values():
                f.write(f"{d.name} in {d.frames_in} dropped {d.dropped} forwarded {d.forwarded}"
                        f" write_errors {d.write_errors}\n")
        os.replace(tmp, args.stats_file)

    print(f"impaired_link: {args.host_if} <-> {args.switch_if}, control {args.control_file}",
          file=sys.stderr, flush=True)
    while not stop:
        now = time.monotonic()
        try:
            mtime = os.stat(args.control_file).st_mtime_ns
        except FileNotFoundError:
            mtime = None
        if mtime != control_mtime:
            control_mtime = mtime
            loss, delay_s = read_control(args.control_file, (loss, delay_s))
            print(f"impaired_link: loss {loss:g}, delay {delay_s * 1000:g} ms",
                  file=sys.stderr, flush=True)
        # Send what is due; the earliest pending frame bounds the wait.
        timeout = 0.05
        for d in directions.values():
            while d.queue and d.queue[0][0] <= now:
                try:
                    os.write(d.dst, d.queue.popleft()[1])
                    d.forwarded += 1
                except OSError:  # the other side down (ip link set down): the frame is lost
                    d.write_errors += 1
            if d.queue:
                timeout = min(timeout, max(0.0, d.queue[0][0] - now))
        if now >= next_stats:
            write_stats()
            next_stats = now + 0.5
        try:
            readable, _, _ = select.select(list(directions), [], [], timeout)
        except InterruptedError:
            continue
        for fd in readable:
            d = directions[fd]
            while True:
                try:
                    frame = os.read(fd, MAX_FRAME)
                except (BlockingIOError, OSError):
                    break
                d.frames_in += 1
                if loss > 0 and rng.random() < loss:
                    d.dropped += 1
                else:
                    d.queue.append((time.monotonic() + delay_s, frame))
    write_stats()
    return 0


if __name__ == "__main__":
    sys.exit(main())
