#!/usr/bin/env python3
"""Writes a targets file for `spherekit param --targets` from a mesh's own sphere map.

Each feature's target is its image on the given (unconstrained) sphere map, moved along the
sphere by a pseudo-random rotation: a random axis perpendicular to the image, an angle
uniform in [--min-deg, --max-deg].  Used to exercise the constrained parameterization on a
single mesh (no other family member to take targets from): the constrained map must put the
features exactly on the moved points, bijectively, at an efficiency close to the
unconstrained one.

Deterministic: the random numbers come from SplitMix64 seeded with --seed and do not depend
on the Python version or any library.  No dependencies.

Usage:
    perturb_targets.py SPHERE.obj FEATURES.lm.txt OUT.txt [--seed N] [--min-deg A] [--max-deg B]

SPHERE.obj has one `v x y z` line per input vertex (the map written by `spherekit param`);
FEATURES.lm.txt is `name vertex_index` per line (0-based, `#` comments); OUT.txt gets
`name x y z` per line.
"""
import argparse
import math
import sys

MASK = (1 << 64) - 1


class SplitMix64:
    def __init__(self, seed):
        self.state = seed & MASK

    def next(self):
        self.state = (self.state + 0x9E3779B97F4A7C15) & MASK
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
        return z ^ (z >> 31)

    def uniform(self):  # [0, 1)
        return (self.next() >> 11) * (1.0 / (1 << 53))


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def read_sphere(path):
    S = []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                S.append(normalize([float(x) for x in line.split()[1:4]]))
    return S


def read_features(path):
    out = []
    with open(path) as f:
        for line in f:
            t = line.split("#")[0].split()
            if len(t) >= 2:
                out.append((t[0], int(t[1])))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("sphere")
    ap.add_argument("features")
    ap.add_argument("out")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--min-deg", type=float, default=5.0)
    ap.add_argument("--max-deg", type=float, default=8.0)
    a = ap.parse_args()
    if not (0 <= a.min_deg <= a.max_deg < 90):
        sys.exit("need 0 <= min-deg <= max-deg < 90")
    S = read_sphere(a.sphere)
    feats = read_features(a.features)
    rng = SplitMix64(a.seed)
    with open(a.out, "w") as out:
        for name, v in feats:
            if not 0 <= v < len(S):
                sys.exit("feature %s: vertex %d out of range (%d vertices)" % (name, v, len(S)))
            p = S[v]
            # Tangent basis at p, then a random direction in it.
            ref = [1.0, 0.0, 0.0] if abs(p[0]) < 0.6 else [0.0, 1.0, 0.0]
            e1 = normalize(cross(p, ref))
            e2 = cross(p, e1)
            phi = 2 * math.pi * rng.uniform()
            ang = math.radians(a.min_deg + (a.max_deg - a.min_deg) * rng.uniform())
            d = [math.cos(phi) * e1[i] + math.sin(phi) * e2[i] for i in range(3)]
            q = normalize([math.cos(ang) * p[i] + math.sin(ang) * d[i] for i in range(3)])
            out.write("%s %.17g %.17g %.17g\n" % (name, q[0], q[1], q[2]))


if __name__ == "__main__":
    main()
