#!/usr/bin/python3
"""Makes a synthetic family with ground truth from one mesh (landmark and correspondence tests
on shapes the shared families do not cover).

usage: warp_family.py MESH.obj OUTDIR MEMBERS [SEED]

Member k is the mesh under a smooth non-rigid warp (Gaussian radial displacements of up to
~12 % of the bounding box, anisotropic scaling 0.8..1.25, a random rotation), with its
vertices and faces renumbered by random permutations. OUTDIR/NAME_k.obj and NAME_k.corr.txt
(line i: the vertex of member k at the original vertex i, the format eval_landmarks.py --corr
reads). Member 0 is only renumbered.
"""
import os
import sys
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from eval_landmarks import read_obj  # noqa: E402  (the same OBJ reading as the evaluator)


def main(argv):
    src, out, members = argv[0], argv[1], int(argv[2])
    seed = int(argv[3]) if len(argv) > 3 else 1
    rng = np.random.default_rng(seed)
    V, F = read_obj(src)
    name = os.path.splitext(os.path.basename(src))[0]
    os.makedirs(out, exist_ok=True)
    lo, hi = V.min(0), V.max(0)
    diag = np.linalg.norm(hi - lo)
    for k in range(members):
        W = V.copy()
        if k > 0:
            for _ in range(6):
                c = lo + rng.random(3) * (hi - lo)
                d = rng.normal(size=3)
                d *= 0.12 * diag / np.linalg.norm(d)
                w = np.exp(-np.sum((W - c) ** 2, 1) / (2 * (0.25 * diag) ** 2))
                W += w[:, None] * d
            Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
            W = (W @ Q) * rng.uniform(0.8, 1.25, 3) @ Q.T
            R, _ = np.linalg.qr(rng.normal(size=(3, 3)))
            if np.linalg.det(R) < 0:
                R[:, 0] *= -1
            W = W @ R.T
        perm = rng.permutation(len(V))  # perm[i]: new index of vertex i
        NV = np.empty_like(W)
        NV[perm] = W
        NF = perm[F][rng.permutation(len(F))]
        with open(os.path.join(out, f'{name}_{k}.obj'), 'w') as f:
            for p in NV:
                f.write('v %.9g %.9g %.9g\n' % tuple(p))
            for t in NF:
                f.write('f %d %d %d\n' % tuple(t + 1))
        np.savetxt(os.path.join(out, f'{name}_{k}.corr.txt'), perm, fmt='%d')


if __name__ == '__main__':
    main(sys.argv[1:])
