#!/usr/bin/env python3
"""Quantiles of the cloud base shape (the Perlin-Worley billows of shaders/cloud_noise.comp),
for the tables that make it uniform on [0, 1]. A port of shaders/include/cloud_noise_lib.glsl
evaluated at random points of the unit cube. Usage: measure_cloud_noise.py [POINTS] [SEED...]
(default 15000 points, noise seeds 1 2 3 4); prints the quantiles at 0.002, 1/16 .. 15/16 and
0.998 of the full billows and of their lowest octave, per seed and averaged."""
import math
import random
import sys

MASK = 0xFFFFFFFF


def hash32(x, y, z, w):
    h = (x * 747796405 + y * 2891336453 + z * 3545902487 + w * 2246822519) & MASK
    h ^= h >> 16
    h = (h * 0x7FEB352D) & MASK
    h ^= h >> 15
    h = (h * 0x846CA68B) & MASK
    h ^= h >> 16
    return h


def hash3(cell, salt, seed):
    k = (seed * 7919 + salt) & MASK
    x, y, z = (v & MASK for v in cell)
    return (hash32(x, y, z, k) / 4294967295.0, hash32(x, y, z, (k + 101) & MASK) / 4294967295.0,
            hash32(x, y, z, (k + 211) & MASK) / 4294967295.0)


def worley(x, period, salt, seed):
    p = [v * period for v in x]
    cell = [math.floor(v) for v in p]
    best = 1e9
    for k in (-1, 0, 1):
        for j in (-1, 0, 1):
            for i in (-1, 0, 1):
                c = (cell[0] + i, cell[1] + j, cell[2] + k)
                f = hash3(tuple(((v % period) + period) % period for v in c), salt, seed)
                d = [c[a] + f[a] - p[a] for a in range(3)]
                best = min(best, d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    return 1.0 - min(max(math.sqrt(best), 0.0), 1.0)


def gradient(x, period, salt, seed):
    p = [v * period for v in x]
    cell = [math.floor(v) for v in p]
    f = [p[a] - cell[a] for a in range(3)]
    u = [t * t * t * (t * (t * 6 - 15) + 10) for t in f]
    corners = []
    for n in range(8):
        o = (n & 1, (n >> 1) & 1, (n >> 2) & 1)
        c = tuple((((cell[a] + o[a]) % period) + period) % period for a in range(3))
        g = [v * 2 - 1 + 1e-4 for v in hash3(c, salt, seed)]
        length = math.sqrt(sum(v * v for v in g))
        corners.append(sum(g[a] / length * (f[a] - o[a]) for a in range(3)))

    def mix(a, b, t):
        return a + (b - a) * t
    x00, x10 = mix(corners[0], corners[1], u[0]), mix(corners[2], corners[3], u[0])
    x01, x11 = mix(corners[4], corners[5], u[0]), mix(corners[6], corners[7], u[0])
    return mix(mix(x00, x10, u[1]), mix(x01, x11, u[1]), u[2]) * 1.7


def perlin01(x, octaves, seed):
    total, amp = 0.0, 0.5
    for o in range(octaves):
        total += amp * gradient(x, 4 << o, 9 + o, seed)
        amp *= 0.5
    return min(max(total / 0.875 * 0.5 + 0.5, 0.0), 1.0)


def billows(perlin, worley_fbm):
    return min(max((perlin - (worley_fbm - 1.0)) / (2.0 - worley_fbm), 0.0), 1.0)


PROBABILITIES = [0.002] + [i / 16 for i in range(1, 16)] + [0.998]


def quantiles(values):
    values = sorted(values)
    return [values[int(q * len(values))] for q in PROBABILITIES]


def main():
    points = int(sys.argv[1]) if len(sys.argv) > 1 else 15000
    seeds = [int(s) for s in sys.argv[2:]] or [1, 2, 3, 4]
    sums = {"full": [0.0] * len(PROBABILITIES), "low": [0.0] * len(PROBABILITIES)}
    for seed in seeds:
        rng = random.Random(seed)
        full, low = [], []
        for _ in range(points):
            x = (rng.random(), rng.random(), rng.random())
            w1, w2, w3 = worley(x, 4, 1, seed), worley(x, 8, 2, seed), worley(x, 16, 3, seed)
            full.append(billows(perlin01(x, 3, seed), w1 * 0.625 + w2 * 0.25 + w3 * 0.125))
            low.append(billows(perlin01(x, 1, seed), w1))
        for name, v in (("full", full), ("low", low)):
            q = quantiles(v)
            sums[name] = [a + b for a, b in zip(sums[name], q)]
            print(f"seed {seed} {name}: " + ", ".join(f"{v:.4f}" for v in q))
    for name, total in sums.items():
        print(f"mean {name}: " + ", ".join(f"{v / len(seeds):.4f}" for v in total))


if __name__ == "__main__":
    main()
