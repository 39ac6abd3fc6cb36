#!/usr/bin/env python3
"""Dense corresponding landmark sets from a family with dense ground truth (issue 19).

The landmarks are farthest-point samples of member 0 (geodesic along mesh edges, starting at
vertex 0, among the vertices the ground truth covers), carried to every other member through
the ground truth. Two ground-truth layouts are read (../shared/meshes/README.md):
  .corr.txt  line k of every member is the same surface point (common sample k): vertex v of
             member 0 is carried to corr_m[k] for the first k with corr_0[k] == v;
  .gt.txt    one template id per vertex: v is carried to the vertex of member m with the same id.
A sample whose partner is already a landmark of some member is skipped (landmarks are distinct).

  dense_landmarks.py gen   -k K -o DIR MESH0 MESH1 ...   writes DIR/<stem>.lm.txt per member
  dense_landmarks.py bench -k K[,K...] -o DIR [--spherekit PROG] [--threads N] MESH0 MESH1 ...
      for each K: generate, run `spherekit consistent --report`, print the wall time per step,
      whether a step fell back, flipped faces and feature error per member (from collection.json).
K = 0 uses the family's own .lm.txt files. Pure Python (no numpy), so it runs anywhere.
"""
import argparse
import heapq
import json
import os
import subprocess
import sys
import time


def read_obj(path):
    V, F = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                V.append(tuple(float(x) for x in line.split()[1:4]))
            elif line.startswith("f "):
                F.append(tuple(int(x.split("/")[0]) - 1 for x in line.split()[1:4]))
    return V, F


def read_ints(path):
    with open(path) as f:
        return [int(x) for x in f.read().split()]


def stem_of(path):
    return os.path.splitext(os.path.basename(path))[0]


def ground_truth(mesh):
    """('corr', list) or ('gt', list) for a member, from its sidecar file."""
    base = os.path.splitext(mesh)[0]
    for kind in ("corr", "gt"):
        if os.path.exists(base + "." + kind + ".txt"):
            return kind, read_ints(base + "." + kind + ".txt")
    sys.exit("dense_landmarks.py: %s has no .corr.txt or .gt.txt ground truth" % mesh)


def carry_maps(meshes):
    """Per member m > 0: dict vertex of member 0 -> vertex of member m."""
    kind0, g0 = ground_truth(meshes[0])
    maps = []
    for m in meshes[1:]:
        kind, g = ground_truth(m)
        if kind != kind0:
            sys.exit("dense_landmarks.py: %s and %s have different ground-truth layouts" % (meshes[0], m))
        carry = {}
        if kind == "corr":
            if len(g) != len(g0):
                sys.exit("dense_landmarks.py: %s: %d samples, %s has %d" % (m, len(g), meshes[0], len(g0)))
            for k, v in enumerate(g0):
                carry.setdefault(v, g[k])
        else:
            by_id = {}
            for w, t in enumerate(g):
                if t >= 0:
                    by_id.setdefault(t, w)
            for v, t in enumerate(g0):
                if t >= 0 and t in by_id:
                    carry[v] = by_id[t]
        maps.append(carry)
    return maps


def dense_landmarks(meshes, k):
    V, F = read_obj(meshes[0])
    adj = [set() for _ in V]
    for a, b, c in F:
        adj[a].update((b, c))
        adj[b].update((a, c))
        adj[c].update((a, b))
    maps = carry_maps(meshes)

    def length(a, b):
        return sum((V[a][i] - V[b][i]) ** 2 for i in range(3)) ** 0.5

    dist = [float("inf")] * len(V)
    chosen = [[] for _ in meshes]
    used = [set() for _ in meshes]
    nxt = 0
    while len(chosen[0]) < k:
        partners = [cm.get(nxt) for cm in maps]
        if all(p is not None for p in partners) and not any(
                p in used[i + 1] for i, p in enumerate(partners)):
            for i, v in enumerate([nxt] + partners):
                chosen[i].append(v)
                used[i].add(v)
        # Dijkstra from the new sample, only where it lowers the distance to the sample set.
        dist[nxt] = 0.0
        heap = [(0.0, nxt)]
        while heap:
            d, v = heapq.heappop(heap)
            if d > dist[v]:
                continue
            for w in adj[v]:
                nd = d + length(v, w)
                if nd < dist[w]:
                    dist[w] = nd
                    heapq.heappush(heap, (nd, w))
        dist[nxt] = -1.0  # tried: never again, whether it was taken or not
        covered = maps[0] if maps else {v: v for v in range(len(V))}
        best, nxt = -1.0, -1
        for v, d in enumerate(dist):
            if d > best and v in covered:
                best, nxt = d, v
        if nxt < 0:
            sys.exit("dense_landmarks.py: only %d landmarks could be placed" % len(chosen[0]))
    return chosen


def write_sets(meshes, k, out):
    os.makedirs(out, exist_ok=True)
    files = []
    if k == 0:
        return [os.path.splitext(m)[0] + ".lm.txt" for m in meshes]
    for m, verts in zip(meshes, dense_landmarks(meshes, k)):
        path = os.path.join(out, stem_of(m) + ".lm.txt")
        with open(path, "w") as f:
            for i, v in enumerate(verts):
                f.write("p%d %d\n" % (i, v))
        files.append(path)
    return files


def bench(args):
    steps = ["step1_reference", "step2_initial_maps", "step3_remesh", "step4_concatenate", "step5_joint_map",
             "step6_final_maps", "total"]
    print("k  wall  " + "  ".join(s.split("_")[0] for s in steps) + "  fallback  flips  max_feature_angle  steiner_vertices")
    for k in [int(x) for x in args.k.split(",")]:
        out = os.path.join(args.output, "k%d" % k)
        files = write_sets(args.meshes, k, out)
        col = os.path.join(out, "col")
        cmd = [args.spherekit, "consistent", "-q", "--threads", str(args.threads), "-o", col, "--report",
               os.path.join(out, "report.json")] + args.meshes + ["--features"] + files + args.extra
        t0 = time.time()
        rc = subprocess.call(cmd, stderr=open(os.path.join(out, "stderr.txt"), "w"))
        wall = time.time() - t0
        if rc != 0:
            print("%d  %.1f  failed (exit %d, see %s/stderr.txt)" % (k, wall, rc, out))
            continue
        rep = json.load(open(os.path.join(out, "report.json")))
        man = json.load(open(os.path.join(col, "collection.json")))
        times = rep.get("times", {})
        res = [m.get("result", {}) for m in man.get("meshes", [])]
        flips = [r.get("flipped_faces") for r in res]
        angle = [r.get("max_feature_angle") for r in res]
        steiner = [r.get("network", {}).get("steiner_vertices") for r in res]
        print("%d  %.1f  %s  %s  %s  %s  %s" % (k, wall, "  ".join("%.1f" % times.get(s, -1) for s in steps),
                                               man.get("refinement_failure", "none"), flips, angle, steiner))
        sys.stdout.flush()


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("mode", choices=["gen", "bench"])
    p.add_argument("-k", required=True, help="landmarks per member (bench: a comma-separated list; 0 = given)")
    p.add_argument("-o", "--output", required=True)
    p.add_argument("--spherekit", default="spherekit")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("meshes", nargs="+")
    p.add_argument("--extra", nargs=argparse.REMAINDER, default=[], help="more flags for spherekit consistent")
    args = p.parse_args()
    if args.mode == "gen":
        for f in write_sets(args.meshes, int(args.k), args.output):
            print(f)
    else:
        bench(args)


if __name__ == "__main__":
    main()
