#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# Writes the tiny .tgt files of this folder from docs/trace-format.md, independently of the
# C++ writer (tests compare the two). Run from anywhere: python3 make_traces.py [out_dir]
import os
import struct
import sys
import zlib

NONE = 0xFFFFFFFF
R, W, RW, CW = 0, 1, 2, 3


def u8(v):
    return struct.pack("<B", v)


def u32(v):
    return struct.pack("<I", v)


def u64(v):
    return struct.pack("<Q", v)


def string(s):
    b = s.encode()
    return u32(len(b)) + b


def frame(ftype, payload):
    head = u32(ftype) + u32(len(payload))
    crc = zlib.crc32(head + payload) & 0xFFFFFFFF  # CRC-32 of type, length and payload
    return head + u32(crc) + payload


VERSION = 2  # what the C++ writer writes; version 1 lacks the host time of each step


def file_header(magic=b"TGTR", version=VERSION):
    return magic + u32(version)


def header_frame(scene, engine, machine, version):
    return frame(1, string(scene) + string(engine) + string(machine) + string(version))


def structure(kinds, objects, data, accesses, tasks, loops):
    out = u32(len(kinds)) + b"".join(string(k) for k in kinds)
    out += u32(len(objects)) + b"".join(string(o) for o in objects)
    out += u32(len(data)) + b"".join(string(n) + u32(o) + u64(b) for n, o, b in data)
    out += u32(len(accesses)) + b"".join(u32(d) + u8(m) for d, m in accesses)
    out += u32(len(tasks)) + b"".join(u32(k) + u32(o) + u32(c) + u32(l) + u64(key)
                                      for k, o, c, l, key in tasks)
    out += u32(len(loops)) + b"".join(u32(c) + u32(f) + u32(l) + u32(m) for c, f, l, m in loops)
    return out


def values(costs, iterations, contacts, groups, host_ns, version=VERSION):
    out = u32(len(costs)) + b"".join(u64(c) for c in costs)
    out += u32(len(iterations)) + b"".join(u32(i) for i in iterations)
    out += u32(len(contacts)) + b"".join(u32(a) + u32(b) for a, b in contacts)
    out += u32(len(groups)) + b"".join(u32(g) for g in groups)
    if version >= 2:
        out += u64(host_ns)
    return out


# Step 0: two objects, a one-task loop whose break task reads the condition "done".
S0 = dict(kinds=["integrate", "loop.break"], objects=["a", "b"],
          data=[("x", 0, 8), ("done", NONE, 1)],
          accesses=[(0, RW), (0, R), (1, W), (1, R)],
          tasks=[(0, 0, 1, NONE, 11), (1, 1, 3, 0, 12)],
          loops=[(1, 1, 2, 9)])
# Step 1: another structure, no loop.
S1 = dict(kinds=["integrate"], objects=["a", "b", "c"],
          data=[("x", 0, 8), ("y", 1, 8), ("z", 2, 16)],
          accesses=[(0, RW), (1, RW), (2, RW), (0, R), (1, W)],
          tasks=[(0, 0, 1, NONE, 1), (0, 1, 1, NONE, 2), (0, 2, 1, NONE, 3), (0, NONE, 2, NONE, 4)],
          loops=[])


def full(s, v):
    return frame(2, structure(**s) + v)


def small_parts(magic=b"TGTR", version=VERSION, s0=S0, ref=0):
    return [file_header(magic, version),
            header_frame("hand-made", "make_traces.py", "none", "0.1.0"),
            full(s0, values([40, 50], [3], [(0, 1)], [0, 0], 700, version)),
            full(S1, values([1, 2, 3, 4], [], [], [], 0, version)),
            frame(3, u32(ref) + values([41, 51], [5], [(0, 1)], [1, 1], 900, version)),
            frame(4, u32(3))]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    files = {}
    small = b"".join(small_parts())
    files["small.tgt"] = small
    files["empty.tgt"] = b"".join(small_parts()[:2]) + frame(4, u32(0))
    files["interrupted.tgt"] = b"".join(small_parts()[:4])
    files["truncated.tgt"] = b"".join(small_parts()[:4]) + small_parts()[4][:20]
    files["bad_magic.tgt"] = b"".join(small_parts(magic=b"TGTX"))
    files["small-v1.tgt"] = b"".join(small_parts(version=1))  # older files stay readable
    files["bad_version.tgt"] = b"".join(small_parts(version=3))
    broken = bytearray(small)
    step1 = len(b"".join(small_parts()[:3]))
    broken[step1 + 12 + 6] ^= 0x20  # a byte of step 1's payload; the CRC no longer matches
    files["bad_checksum.tgt"] = bytes(broken)
    parts = small_parts()
    files["unknown_frame.tgt"] = b"".join(parts[:2] + [frame(7, b"future")] + parts[2:])
    absurd = bytearray(parts[2][12:])
    absurd[0:4] = u32(0xFFFFFFFF)  # the kind count of step 0
    files["absurd_count.tgt"] = b"".join(parts[:2] + [frame(2, bytes(absurd))] + parts[3:])
    files["bad_kind.tgt"] = b"".join(small_parts(s0=dict(S0, tasks=[(5, 0, 1, NONE, 11), (1, 1, 3, 0, 12)])))
    files["bad_datum.tgt"] = b"".join(small_parts(s0=dict(S0, accesses=[(9, RW), (0, R), (1, W), (1, R)])))
    files["bad_loop.tgt"] = b"".join(small_parts(s0=dict(S0, loops=[(1, 1, 9, 9)])))
    files["bad_reference.tgt"] = b"".join(small_parts(ref=7))
    for name, data in files.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)
        print(f"{name}: {len(data)} bytes")


if __name__ == "__main__":
    main()
