#!/usr/bin/env python3
"""Counts UDP datagrams on an interface for some seconds and how many contain a marker.
Usage: sniff.py IFACE SECONDS MARKER  ->  prints "udp=N marker=M". Needs root (AF_PACKET)."""
import socket
import struct
import sys
import time

iface, seconds, marker = sys.argv[1], float(sys.argv[2]), sys.argv[3].encode()
s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.ntohs(0x0003))
s.bind((iface, 0))
s.settimeout(0.2)
udp = hits = 0
end = time.monotonic() + seconds
while time.monotonic() < end:
    try:
        frame, addr = s.recvfrom(65535)
    except socket.timeout:
        continue
    if addr[2] == socket.PACKET_OUTGOING:  # on lo every packet is seen twice
        continue
    # Ethernet header (14 B; lo has a zero one), then IPv4.
    if len(frame) < 34 or struct.unpack("!H", frame[12:14])[0] != 0x0800:
        continue
    ip = frame[14:]
    if ip[9] != 17:  # UDP
        continue
    udp += 1
    if marker in ip[(ip[0] & 0x0F) * 4 + 8:]:
        hits += 1
print(f"udp={udp} marker={hits}")
