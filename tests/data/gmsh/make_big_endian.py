#!/usr/bin/env python3
"""Writes sq22b_be.msh: sq22b.msh (MSH 2.2 binary, little-endian) with every binary
value byte-swapped, as a big-endian machine would write it. Fixture for the reader's
endianness check; the file layout follows the MSH 2.2 binary format."""
import struct

src = open("sq22b.msh", "rb").read()
out = bytearray()
pos = 0


def line():
    global pos
    end = src.index(b"\n", pos) + 1
    chunk = src[pos:end]
    out.extend(chunk)
    pos = end
    return chunk.strip()


def swap(fmt):
    global pos
    size = struct.calcsize("<" + fmt)
    values = struct.unpack_from("<" + fmt, src, pos)
    out.extend(struct.pack(">" + fmt, *values))
    pos += size
    return values


NODES = {1: 2, 2: 3, 15: 1}
while pos < len(src):
    header = line()
    if header == b"2.2 1 8":
        swap("i")
        line()
    elif header == b"$Nodes":
        n = int(line())
        for _ in range(n):
            swap("i3d")
        line()
    elif header == b"$Elements":
        n = int(line())
        done = 0
        while done < n:
            etype, follow, ntags = swap("3i")
            for _ in range(follow):
                swap("%di" % (1 + ntags + NODES[etype]))
            done += follow
        line()
open("sq22b_be.msh", "wb").write(out)
