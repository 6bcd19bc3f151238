"""Which TCP addresses do this process and its descendants listen on? (Linux ``/proc``; no psutil)."""

from __future__ import annotations

import ipaddress
import os
from pathlib import Path


def _descendants(root: int) -> set[int]:
    children: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))  # ppid -> pid
    out, todo = set(), [root]
    while todo:
        pid = todo.pop()
        out.add(pid)
        todo.extend(children.get(pid, []))
    return out


def _socket_inodes(pids: set[int]) -> set[str]:
    inodes = set()
    for pid in pids:
        try:
            for fd in os.scandir(f"/proc/{pid}/fd"):
                target = os.readlink(fd.path)
                if target.startswith("socket:["):
                    inodes.add(target[8:-1])
        except OSError:
            continue
    return inodes


def _addr(hex_addr: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address:
    raw = bytes.fromhex(hex_addr)
    if len(raw) == 4:
        return ipaddress.IPv4Address(raw[::-1])  # little-endian u32
    words = b"".join(raw[i : i + 4][::-1] for i in range(0, 16, 4))  # four little-endian u32
    v6 = ipaddress.IPv6Address(words)
    return v6.ipv4_mapped or v6


def listening_addresses(root: int | None = None) -> set[str]:
    """Local addresses of LISTEN sockets owned by ``root`` (default: this process) or its descendants."""
    inodes = _socket_inodes(_descendants(root or os.getpid()))
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = Path(table).read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            cols = line.split()
            local, state, inode = cols[1], cols[3], cols[9]
            if state == "0A" and inode in inodes:  # 0A = LISTEN
                found.add(str(_addr(local.split(":")[0])))
    return found


def non_loopback(addresses: set[str]) -> set[str]:
    return {a for a in addresses if not ipaddress.ip_address(a).is_loopback}
