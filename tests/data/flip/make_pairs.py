#!/usr/bin/env python3
"""Writes the small FLIP reference image pairs of this folder (standard library only).

Usage: python3 make_pairs.py [OUTDIR]   (default: the folder of this script)

Every image is an 8-bit RGB PNG (colour type 2, no gamma chunk), deterministic: the noise comes
from an integer hash, not from a random module, so the bytes do not depend on the Python version.
"""
import os
import struct
import sys
import zlib


def write_png(path, width, height, pixel):
    """pixel(x, y) -> (r, g, b) bytes; rows top to bottom."""
    raw = bytearray()
    for y in range(height):
        row = bytearray()
        for x in range(width):
            row.extend(bytes(pixel(x, y)))
        raw.append(1)  # filter type Sub: each byte minus the byte 3 to its left (smaller files)
        raw.extend((row[i] - (row[i - 3] if i >= 3 else 0)) & 0xFF for i in range(len(row)))

    def chunk(tag, data):
        body = tag + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def hash32(x):
    x &= 0xFFFFFFFF
    x ^= x >> 16
    x = (x * 0x7FEB352D) & 0xFFFFFFFF
    x ^= x >> 15
    x = (x * 0x846CA68B) & 0xFFFFFFFF
    x ^= x >> 16
    return x


def clamp8(v):
    return max(0, min(255, int(v)))


# 1. gradient: a smooth two-axis colour gradient vs the same with +-10 code values of noise.
def gradient(x, y, w=64, h=64):
    return (clamp8(20 + 215 * x / (w - 1)), clamp8(30 + 190 * y / (h - 1)),
            clamp8(200 - 150 * (x + y) / (w + h - 2)))


def gradient_noisy(x, y):
    r, g, b = gradient(x, y)
    n = [(hash32(1000003 * (y * 64 + x) + c) % 21) - 10 for c in range(3)]
    return (clamp8(r + n[0]), clamp8(g + n[1]), clamp8(b + n[2]))


# 2. edge: a dark/light vertical edge with a soft diagonal band, shifted right by 2 pixels.
def edge(shift):
    def f(x, y):
        light = x >= 20 + shift
        band = abs((x - shift) - y) < 4
        v = 220 if light else 40
        return (v, clamp8(v - (60 if band else 0)), clamp8(v - 20))
    return f


# 3. colour: a disc on grey whose colour changes hue (orange -> teal), non-square image.
def disc(colour):
    def f(x, y):
        if (x - 24) ** 2 + (y - 15) ** 2 <= 11 ** 2:
            return colour
        return (128, 128, 128)
    return f


# 4. checker: a 2-pixel checkerboard vs flat mid grey of about the same mean (feature term).
def checker(x, y):
    v = 230 if ((x // 2) + (y // 2)) % 2 == 0 else 25
    return (v, v, v)


def flat(x, y):
    return (160, 160, 160)


# 5. identical: a busy pattern against itself (FLIP must be exactly 0).
def busy(x, y):
    return (hash32(7 * x + 131 * y) % 256, (x * 9 + y * 5) % 256, hash32(x * y + 17) % 256)


PAIRS = [
    ("gradient", 64, 64, gradient, gradient_noisy),
    ("edge", 48, 40, edge(0), edge(2)),
    ("colour", 48, 32, disc((230, 140, 30)), disc((30, 170, 160))),
    ("checker", 32, 32, checker, flat),
    ("identical", 40, 40, busy, busy),
]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    for name, w, h, ref, test in PAIRS:
        write_png(os.path.join(out, name + "_ref.png"), w, h, ref)
        write_png(os.path.join(out, name + "_test.png"), w, h, test)


if __name__ == "__main__":
    main()
