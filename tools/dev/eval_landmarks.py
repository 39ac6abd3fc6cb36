#!/usr/bin/python3
"""Measures proposed landmarks against a family's ground truth (issue 25's check).

usage: eval_landmarks.py --corr|--gt A.obj A.lm.txt A.truth B.obj B.lm.txt B.truth [C.obj ...]

For every pair of members (A, B) and landmark name: the ground-truth partner on B of A's
landmark vertex a is found through the truth files (--corr: line k of all files is the same
point; --gt: template id per vertex), from the truth point of A nearest to a; the error is the
edge-graph geodesic distance on B from B's landmark to that partner, / sqrt(area B).
Prints one JSON line: pairs, mean, max, fraction under 0.05.
"""
import json
import sys
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree


def read_obj(path):
    V, F = [], []
    for line in open(path):
        t = line.split()
        if not t:
            continue
        if t[0] == 'v':
            V.append([float(x) for x in t[1:4]])
        elif t[0] == 'f':
            F.append([int(x.split('/')[0]) - 1 for x in t[1:4]])
    return np.array(V), np.array(F)


def read_lm(path):
    out = {}
    for line in open(path):
        line = line.split('#')[0].split()
        if len(line) == 2:
            out[line[0]] = int(line[1])
    return out


def main(argv):
    mode = argv[0]
    rest = argv[1:]
    members = [rest[i:i + 3] for i in range(0, len(rest), 3)]
    data = []
    for obj, lm, truth in members:
        V, F = read_obj(obj)
        t = np.loadtxt(truth, dtype=np.int64)
        e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
        w = np.linalg.norm(V[e[:, 0]] - V[e[:, 1]], axis=1)
        G = coo_matrix((w, (e[:, 0], e[:, 1])), shape=(len(V), len(V))).tocsr()
        G = G.maximum(G.T)
        area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1).sum()
        data.append(dict(V=V, G=G, lm=read_lm(lm), t=t, sa=np.sqrt(area)))
    errs = []
    by_name = {}
    for i, A in enumerate(data):
        for j, B in enumerate(data):
            if i == j:
                continue
            if mode == '--corr':
                pa, pb = A['t'], B['t']
            else:  # template ids: pairs where both have the id
                ids_b = {int(x): v for v, x in enumerate(B['t']) if x >= 0}
                pa = np.array([v for v, x in enumerate(A['t']) if int(x) in ids_b])
                pb = np.array([ids_b[int(A['t'][v])] for v in pa])
            tree = cKDTree(A['V'][pa])
            for name, a in A['lm'].items():
                if name not in B['lm']:
                    continue
                _, k = tree.query(A['V'][a])
                d = dijkstra(B['G'], indices=B['lm'][name])
                errs.append(d[pb[k]] / B['sa'])
                by_name.setdefault(name, []).append(errs[-1])
    errs = np.array(errs)
    print(json.dumps(dict(pairs=len(errs), mean=float(errs.mean()), max=float(errs.max()),
                          under_005=float((errs < 0.05).mean()),
                          by_name={n: round(float(np.mean(e)), 4) for n, e in by_name.items()})))


if __name__ == '__main__':
    main(sys.argv[1:])
