#!/usr/bin/env python3
"""Writes the landmark (feature) files in tests/data/features/ and documents how they were chosen.

The files index four developer meshes that are NOT in this repository (they live in the
shared mesh directory, by default ../shared/meshes next to the repository root):

    horse.obj (48485 v), armadillo.obj (12502 v), bunny.obj (34834 v), gargoyle.obj (10002 v)

Each file is `name vertex_index` per line (0-based index into the OBJ `v` lines, in order).
The indices below were picked by the geometric rules written next to them (extremal
vertices in a direction within a region, geodesic-farthest vertices, leg slices, ...),
then checked on rendered orthographic views.  bunny.lm.txt and gargoyle.lm.txt are one
corresponding set (same names, same order), as in the bunny+gargoyle example of the
Consistent Spherical Parameterization paper.

Usage:
    make_feature_files.py [--meshes DIR] [--check] [--out DIR]

Without --check it writes the files from the tables below (no dependencies).  With
--check (needs numpy + scipy and the shared meshes) it also re-runs every rule, reports
any index that no longer matches, and prints each feature's position and the smallest
distance between two features of a file.
"""
import argparse
import os
import sys

# name -> (vertex index, rule).  Axes are those of the shared OBJ files.
HORSE = {  # up +z, faces +y, its right side is +x (body mid-plane x ~ 0.014); head turned to -x
    "hoof_front_left": (40652, "leg of the quadrant (x<0.014, y>-0.025): sole vertex nearest the centroid of the sole (lowest 0.0008)"),
    "hoof_front_right": (3140, "same, quadrant x>0.014, y>-0.025"),
    "hoof_hind_left": (14704, "same, quadrant x<0.014, y<-0.025"),
    "hoof_hind_right": (14848, "same, quadrant x>0.014, y<-0.025"),
    "knee_front_left": (638, "leg axis tracked up from the sole in 0.002 slices; slice z=-0.035: front-most (max y) vertex"),
    "knee_front_right": (721, "same"),
    "hock_hind_left": (999, "leg axis slice z=-0.030: rear-most (min y) vertex (point of hock)"),
    "hock_hind_right": (30340, "same"),
    "shoulder_left": (18390, "|y - leg axis y at z=-0.021| < 0.006, |z| < 0.01: lateral-most vertex"),
    "shoulder_right": (18523, "same"),
    "hip_left": (6197, "y < -0.035, |z| < 0.01: lateral-most vertex"),
    "hip_right": (20989, "same"),
    "nose_tip": (37480, "head (y>0.06, z>0.03): geodesic-farthest vertex from the vertex nearest the centroid"),
    "ear_tip_left": (36202, "head: highest local z maximum of the ear with smaller y (head faces -x, so its left is -y)"),
    "ear_tip_right": (36443, "head: highest vertex"),
    "head_top": (36149, "midpoint of the shortest edge path between the ear tips (poll)"),
    "chin": (36492, "muzzle (x<-0.028, y>0.06, z>0.02): lowest vertex"),
    "withers": (42867, "slice |y-0.012|<0.001 (where the top line starts rising into the neck): highest vertex"),
    "back_middle": (42091, "slice |y+0.02|<0.001: highest vertex"),
    "belly_centre": (46815, "slice |y+0.02|<0.001: lowest vertex"),
    "chest_front": (20236, "slice |z-0.005|<0.0015: front-most (max y) vertex"),
    "tail_base": (11891, "back mid-line |x-0.019|<0.003, y<-0.05: extremal in direction (0,-1,1) (the mesh has no tail)"),
    "rump_rear": (23029, "back mid-line |x-0.019|<0.003, y<-0.05, z>0: rear-most vertex (point of buttock)"),
}

ARMADILLO = {  # up +y, faces +z, its left side is +x
    "hand_tip_left": (4, "x>0.3, y>0.3: geodesic-farthest vertex from the vertex nearest the centroid (a finger tip)"),
    "hand_tip_right": (358, "same, x<-0.3"),
    "elbow_left": (3112, "lateral-most vertex (max x)"),
    "elbow_right": (1066, "lateral-most vertex (min x)"),
    "shoulder_left": (7889, "|x-0.30|<0.02, 0.15<y<0.5, z>-0.1: highest vertex"),
    "shoulder_right": (1905, "same, |x+0.30|<0.02"),
    "toe_tip_left": (6039, "foot (x>0.1, y<-0.7): front-most (max z) vertex"),
    "toe_tip_right": (6856, "foot (x<-0.1, y<-0.7): front-most vertex"),
    "heel_left": (3371, "foot: rear-most (min z) vertex"),
    "heel_right": (4558, "same"),
    "knee_left": (7801, "leg (x>0.15), |y+0.43|<0.03: front-most vertex"),
    "knee_right": (8130, "same, x<-0.15"),
    "hip_left": (11005, "|y+0.15|<0.015: lateral-most vertex"),
    "hip_right": (3244, "same"),
    "tail_tip": (7496, "z<-0.45, y<-0.3: geodesic-farthest vertex from the vertex nearest the centroid"),
    "tail_base": (2762, "walking the shortest path tail tip -> back_centre: first vertex (>0.1 from the tip) whose geodesic ring is wider than 0.25"),
    "snout_tip": (124, "y>0.2, |x|<0.2: front-most vertex"),
    "ear_tip_left": (1780, "y>0.55, z>0.1, 0<x<0.3: geodesic-farthest vertex from the vertex nearest the centroid"),
    "ear_tip_right": (2181, "same, -0.3<x<0"),
    "head_top": (3163, "midpoint of the shortest edge path between the ear tips"),
    "chest_centre": (4593, "|x|<0.03, |y-0.10|<0.02: front-most vertex"),
    "belly_centre": (6861, "|x|<0.03, |y+0.10|<0.02: front-most vertex"),
    "back_centre": (9364, "|x|<0.03, |y-0.15|<0.02: rear-most vertex (middle of the shell)"),
}

# bunny <-> gargoyle: one corresponding set.  The gargoyle's wing tips correspond to the
# bunny's haunches ("wing_haunch"), its lower back above the pedestal to the bunny's tail,
# the bottom of its pedestal to the bunny's base plate.
BUNNY = {  # up +y, faces -x, its left side is +z (mid-plane z ~ 0.015); head turned to +z
    "ear_tip_left": (14117, "y>0.15: geodesic-farthest vertex from the vertex nearest the centroid, on the ear other than ear_tip_right"),
    "ear_tip_right": (28407, "y>0.15: geodesic-farthest vertex (the ear standing out to -z)"),
    "head_top": (23480, "midpoint of the shortest edge path between the ear tips"),
    "nose_tip": (18818, "y>0.09: extremal in the head direction (-1,0,0.35)"),
    "chin": (33412, "slice |y-0.110|<0.0015 (just above the head/chest crease at y~0.106), x<-0.03: extremal in the head direction"),
    "chest": (22593, "slice |y-0.090|<0.002, |z-0.015|<0.01: front-most (min x) vertex"),
    "back_top": (4615, "x>0.005, y<0.17 (behind the head, below the ears): highest vertex"),
    "wing_haunch_left": (3138, "0<x<0.04, 0.05<y<0.11: max z"),
    "wing_haunch_right": (29243, "same region: min z"),
    "front_foot_left": (16809, "slice |y-0.040|<0.002, |z-0.032|<0.002: front-most vertex"),
    "front_foot_right": (16876, "same, |z-0.006|<0.002"),
    "hind_foot_left": (16934, "same, |z-0.052|<0.002"),
    "hind_foot_right": (19364, "same, |z+0.024|<0.002"),
    "tail": (12217, "0.045<y<0.09, |z-0.015|<0.02: rear-most (max x) vertex"),
    "base_centre": (31039, "base plate (y<ymin+0.0015), >0.012 (edge path) from the holes: vertex nearest the plate centroid"),
}

GARGOYLE = {  # up +y, faces +z, its left side is +x (mid-plane x ~ 0.29); sits on a pedestal
    "ear_tip_left": (1148, "head (y>0.8, |x-0.29|<0.12, z>0.15), x>0.29: highest vertex"),
    "ear_tip_right": (2242, "same, x<0.29"),
    "head_top": (2179, "midpoint of the shortest edge path between the ear tips"),
    "nose_tip": (4108, "y>0.7, |x-0.29|<0.1: front-most (max z) vertex"),
    "chin": (1901, "y>0.65, |x-0.29|<0.06, z>0.3: extremal in direction (0,-1,1) (front of the lower jaw)"),
    "chest": (4341, "mid-line |x-0.29|<0.015, |y-0.64|<0.01: front-most vertex"),
    "back_top": (2104, "mid-line, |y-0.70|<0.01: rear-most vertex (upper back between the wings)"),
    "wing_haunch_left": (2895, "y>0.8: max x (left wing tip)"),
    "wing_haunch_right": (6083, "y>0.8: min x (right wing tip)"),
    "front_foot_left": (9454, "on the pedestal (0.475<y<0.54), x-0.29>0.03: front-most vertex (front paw toes)"),
    "front_foot_right": (3461, "same, 0.29-x>0.03"),
    "hind_foot_left": (1847, "same band, x-0.29>0.11: front-most vertex (hind paw toes, beside the front paw)"),
    "hind_foot_right": (4968, "same, 0.29-x>0.11"),
    "tail": (704, "mid-line, |y-0.50|<0.01: rear-most vertex (lower back just above the pedestal; the statue has no tail)"),
    "base_centre": (10000, "pedestal bottom (y<ymin+0.002): vertex nearest its centroid"),
}

FILES = [  # output name, mesh file, vertex count of that mesh, table
    ("horse.lm.txt", "horse.obj", 48485, HORSE),
    ("armadillo.lm.txt", "armadillo.obj", 12502, ARMADILLO),
    ("bunny.lm.txt", "bunny.obj", 34834, BUNNY),
    ("gargoyle.lm.txt", "gargoyle.obj", 10002, GARGOYLE),
]

HEADER = {
    "horse.lm.txt": "# horse.obj (shared meshes, 48485 vertices): up +z, faces +y, left/right are the horse's own.\n"
                    "# The mesh has no tail: tail_base marks the dock position, rump_rear the point of buttock.\n",
    "armadillo.lm.txt": "# armadillo.obj (shared meshes, 12502 vertices): up +y, faces +z, left/right are the armadillo's own.\n",
    "bunny.lm.txt": "# bunny.obj (shared meshes, 34834 vertices): corresponds name by name to gargoyle.lm.txt.\n"
                    "# wing_haunch_* are the haunches (matching the gargoyle's wing tips).\n",
    "gargoyle.lm.txt": "# gargoyle.obj (shared meshes, 10002 vertices): corresponds name by name to bunny.lm.txt.\n"
                       "# wing_haunch_* are the wing tips (matching the bunny's haunches); tail is the lower back\n"
                       "# above the pedestal; base_centre is the bottom of the pedestal.\n",
}


def file_text(name, table):
    lines = ["# landmarks: name vertex_index (0-based, OBJ `v` order); made by tools/dev/make_feature_files.py\n",
             HEADER[name]]
    lines += ["%s %d\n" % (n, v) for n, (v, _) in table.items()]
    return "".join(lines)


# ----------------------------------------------------------------------------------------
# Re-running the rules (only with --check; needs numpy + scipy and the shared meshes).


def _geometry_helpers():
    import numpy as np
    import scipy.sparse as sp
    from scipy.sparse.csgraph import dijkstra

    def load_obj(path):
        V, F = [], []
        with open(path) as fh:
            for line in fh:
                if line.startswith("v "):
                    V.append([float(t) for t in line.split()[1:4]])
                elif line.startswith("f "):
                    F.append([int(t.split("/")[0]) - 1 for t in line.split()[1:4]])
        return np.array(V), np.array(F)

    class Mesh:
        def __init__(self, path):
            self.V, self.F = load_obj(path)
            V, F = self.V, self.F
            E = np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
            Es, counts = np.unique(np.sort(E, 1), axis=0, return_counts=True)
            self.boundary = np.unique(Es[counts == 1])
            w = np.linalg.norm(V[Es[:, 0]] - V[Es[:, 1]], axis=1)
            n = len(V)
            self.G = sp.coo_matrix((np.r_[w, w], (np.r_[Es[:, 0], Es[:, 1]], np.r_[Es[:, 1], Es[:, 0]])),
                                   shape=(n, n)).tocsr()
            self.hops = sp.coo_matrix((np.ones(2 * len(Es)), (np.r_[Es[:, 0], Es[:, 1]], np.r_[Es[:, 1], Es[:, 0]])),
                                      shape=(n, n)).tocsr()
            self.x, self.y, self.z = V.T

        def best(self, mask, score):
            i = np.where(mask)[0]
            if len(i) == 0:
                raise RuntimeError("empty region")
            return int(i[np.argmax(score[i])])

        def dist(self, sources, limit=np.inf):
            return dijkstra(self.G, indices=sources, min_only=True, limit=limit)

        def from_centre(self):
            c = int(np.argmin(np.linalg.norm(self.V - self.V.mean(0), axis=1)))
            return self.dist(c)

        def path(self, a, b):
            d, pred = dijkstra(self.G, indices=a, return_predecessors=True)
            p = [b]
            while p[-1] != a:
                p.append(int(pred[p[-1]]))
            return p[::-1], d

        def path_midpoint(self, a, b):
            p, d = self.path(a, b)
            return int(min(p, key=lambda v: abs(d[v] - d[b] / 2)))

    return np, Mesh


def rules_horse(m, np):
    x, y, z = m.x, m.y, m.z
    XC = 0.014
    out = {}
    low = z < z.min() + 0.01
    quads = {"front_left": low & (x < XC) & (y > -0.025), "front_right": low & (x > XC) & (y > -0.025),
             "hind_left": low & (x < XC) & (y < -0.025), "hind_right": low & (x > XC) & (y < -0.025)}
    axis = {}
    for k, q in quads.items():
        sole = q & (z < z[q].min() + 0.0008)
        c = m.V[sole].mean(0)
        out["hoof_" + k] = m.best(sole, -np.linalg.norm(m.V - c, axis=1))
        cxy, track = c[:2], {}
        for h in np.arange(-0.074, -0.019, 0.002):
            s = (np.abs(z - h) < 0.0015) & (np.hypot(x - cxy[0], y - cxy[1]) < 0.012)
            cxy = m.V[s][:, :2].mean(0)
            track[round(h, 3)] = cxy
        axis[k] = track
    for k in quads:
        front = k.startswith("front")
        h = -0.035 if front else -0.030
        cxy = axis[k][min(axis[k], key=lambda t: abs(t - h))]
        s = (np.abs(z - h) < 0.001) & (np.hypot(x - cxy[0], y - cxy[1]) < 0.012)
        out[("knee_" if front else "hock_") + k] = m.best(s, y if front else -y)
    for k in quads:
        side = -1 if k.endswith("left") else 1
        if k.startswith("front"):
            yc = axis[k][min(axis[k], key=lambda t: abs(t + 0.021))][1]
            out["shoulder_" + k.split("_")[1]] = m.best((np.abs(y - yc) < 0.006) & (np.abs(z) < 0.01), side * (x - XC))
        else:
            out["hip_" + k.split("_")[1]] = m.best((y < -0.035) & (np.abs(z) < 0.01), side * (x - XC))
    head = (y > 0.06) & (z > 0.03)
    out["nose_tip"] = m.best(head, m.from_centre())
    e1 = m.best(head, z)
    e2 = None
    cand = np.where(head & (np.linalg.norm(m.V - m.V[e1], axis=1) > 0.01))[0]
    for v in cand[np.argsort(-z[cand])]:
        ball = np.isfinite(m.dist(int(v), limit=0.006))
        if z[ball].max() <= z[v]:
            e2 = int(v)
            break
    left, right = (e1, e2) if y[e1] < y[e2] else (e2, e1)
    out["ear_tip_left"], out["ear_tip_right"] = left, right
    out["head_top"] = m.path_midpoint(left, right)
    out["chin"] = m.best((x < -0.028) & (z > 0.02) & (y > 0.06), -z)
    out["withers"] = m.best(np.abs(y - 0.012) < 0.001, z)
    out["back_middle"] = m.best(np.abs(y + 0.02) < 0.001, z)
    out["belly_centre"] = m.best(np.abs(y + 0.02) < 0.001, -z)
    out["chest_front"] = m.best(np.abs(z - 0.005) < 0.0015, y)
    mid = np.abs(x - 0.019) < 0.003
    out["tail_base"] = m.best(mid & (y < -0.05), -y + z)
    out["rump_rear"] = m.best(mid & (z > 0) & (y < -0.05), -y)
    return out


def rules_armadillo(m, np):
    x, y, z = m.x, m.y, m.z
    out = {}
    d0 = m.from_centre()
    for s, sg in (("left", 1), ("right", -1)):
        out["hand_tip_" + s] = m.best((sg * x > 0.3) & (y > 0.3), d0)
        out["elbow_" + s] = m.best(sg * x > 0.3, sg * x)
        out["shoulder_" + s] = m.best((np.abs(sg * x - 0.30) < 0.02) & (y > 0.15) & (y < 0.5) & (z > -0.1), y)
        foot = (sg * x > 0.1) & (y < -0.7)
        out["toe_tip_" + s] = m.best(foot, z)
        out["heel_" + s] = m.best(foot, -z)
        out["knee_" + s] = m.best((sg * x > 0.15) & (np.abs(y + 0.43) < 0.03), z)
        out["hip_" + s] = m.best((sg * x > 0) & (np.abs(y + 0.15) < 0.015), sg * x)
        out["ear_tip_" + s] = m.best((y > 0.55) & (z > 0.1) & (sg * x > 0) & (sg * x < 0.3), d0)
    back = m.best((np.abs(x) < 0.03) & (np.abs(y - 0.15) < 0.02), -z)
    tail = m.best((z < -0.45) & (y < -0.3), d0)
    out["tail_tip"] = tail
    p, dt = m.path(tail, back)
    out["tail_base"] = next(v for v in p if dt[v] > 0.1 and np.ptp(m.V[np.abs(dt - dt[v]) < 0.01], axis=0).max() > 0.25)
    out["snout_tip"] = m.best((y > 0.2) & (np.abs(x) < 0.2), z)
    out["head_top"] = m.path_midpoint(out["ear_tip_left"], out["ear_tip_right"])
    out["chest_centre"] = m.best((np.abs(x) < 0.03) & (np.abs(y - 0.10) < 0.02), z)
    out["belly_centre"] = m.best((np.abs(x) < 0.03) & (np.abs(y + 0.10) < 0.02), z)
    out["back_centre"] = back
    return out


def rules_bunny(m, np):
    x, y, z = m.x, m.y, m.z
    ZC = 0.015
    out = {}
    d0 = m.from_centre()
    top = y > 0.15
    right = m.best(top, d0)
    left = m.best(top & (np.linalg.norm(m.V - m.V[right], axis=1) > 0.04), d0)
    out["ear_tip_left"], out["ear_tip_right"] = left, right
    out["head_top"] = m.path_midpoint(left, right)
    hd = np.array([-1.0, 0.0, 0.35]) / np.linalg.norm([-1.0, 0.0, 0.35])
    out["nose_tip"] = m.best(y > 0.09, m.V @ hd)
    out["chin"] = m.best((np.abs(y - 0.110) < 0.0015) & (x < -0.03), m.V @ hd)
    out["chest"] = m.best((np.abs(y - 0.090) < 0.002) & (np.abs(z - ZC) < 0.01), -x)
    out["back_top"] = m.best((x > 0.005) & (y < 0.17), y)
    haunch = (x > 0) & (x < 0.04) & (y > 0.05) & (y < 0.11)
    out["wing_haunch_left"] = m.best(haunch, z)
    out["wing_haunch_right"] = m.best(haunch, -z)
    for name, zc in (("front_foot_left", 0.032), ("front_foot_right", 0.006),
                     ("hind_foot_left", 0.052), ("hind_foot_right", -0.024)):
        out[name] = m.best((np.abs(y - 0.040) < 0.002) & (np.abs(z - zc) < 0.002), -x)
    out["tail"] = m.best((y > 0.045) & (y < 0.09) & (np.abs(z - ZC) < 0.02), x)
    plate = y < y.min() + 0.0015
    c = m.V[plate].mean(0)
    db = m.dist(m.boundary)
    out["base_centre"] = m.best(plate & (db > 0.012), -np.linalg.norm(m.V - c, axis=1))
    return out


def rules_gargoyle(m, np):
    x, y, z = m.x, m.y, m.z
    XC = 0.29
    out = {}
    head = (y > 0.8) & (np.abs(x - XC) < 0.12) & (z > 0.15)
    out["ear_tip_left"] = m.best(head & (x > XC), y)
    out["ear_tip_right"] = m.best(head & (x < XC), y)
    out["head_top"] = m.path_midpoint(out["ear_tip_left"], out["ear_tip_right"])
    out["nose_tip"] = m.best((y > 0.7) & (np.abs(x - XC) < 0.1), z)
    out["chin"] = m.best((y > 0.65) & (np.abs(x - XC) < 0.06) & (z > 0.3), z - y)
    mid = np.abs(x - XC) < 0.015
    out["chest"] = m.best(mid & (np.abs(y - 0.64) < 0.01), z)
    out["back_top"] = m.best(mid & (np.abs(y - 0.70) < 0.01), -z)
    out["wing_haunch_left"] = m.best(y > 0.8, x)
    out["wing_haunch_right"] = m.best(y > 0.8, -x)
    feet = (y > 0.475) & (y < 0.54)
    out["front_foot_left"] = m.best(feet & (x - XC > 0.03), z)
    out["front_foot_right"] = m.best(feet & (XC - x > 0.03), z)
    out["hind_foot_left"] = m.best(feet & (x - XC > 0.11), z)
    out["hind_foot_right"] = m.best(feet & (XC - x > 0.11), z)
    out["tail"] = m.best(mid & (np.abs(y - 0.50) < 0.01), -z)
    bottom = y < y.min() + 0.002
    out["base_centre"] = m.best(bottom, -np.linalg.norm(m.V - m.V[bottom].mean(0), axis=1))
    return out


RULES = {"horse.obj": rules_horse, "armadillo.obj": rules_armadillo, "bunny.obj": rules_bunny,
         "gargoyle.obj": rules_gargoyle}


def check(mesh_dir):
    np, Mesh = _geometry_helpers()
    from scipy.sparse.csgraph import shortest_path
    ok = True
    for out_name, mesh_name, nv, table in FILES:
        path = os.path.join(mesh_dir, mesh_name)
        if not os.path.exists(path):
            print("%s: %s not found, skipped" % (out_name, path))
            continue
        m = Mesh(path)
        print("== %s (%s, %d vertices, %d features)" % (out_name, mesh_name, len(m.V), len(table)))
        if len(m.V) != nv:
            print("  ERROR: expected %d vertices" % nv)
            ok = False
            continue
        idx = [v for v, _ in table.values()]
        if len(set(idx)) != len(idx) or min(idx) < 0 or max(idx) >= nv:
            print("  ERROR: indices out of range or not distinct")
            ok = False
        found = RULES[mesh_name](m, np)
        for n, (v, rule) in table.items():
            again = found.get(n)
            flag = "" if again == v else "   <-- rule now gives %s" % again
            ok &= again == v
            print("  %-18s %6d  (% .5f % .5f % .5f)%s" % (n, v, *m.V[v], flag))
        P = m.V[idx]
        D = np.linalg.norm(P[:, None] - P[None], axis=2) + np.eye(len(idx)) * 1e9
        hops = shortest_path(m.hops, unweighted=True, indices=idx)[:, idx] + np.eye(len(idx)) * 1e9
        i, j = np.unravel_index(np.argmin(D), D.shape)
        names = list(table)
        print("  closest pair: %s / %s, %.5f apart (%.1f%% of the bbox diagonal), %d edges apart (min over all pairs: %d)"
              % (names[i], names[j], D[i, j], 100 * D[i, j] / np.linalg.norm(np.ptp(m.V, axis=0)),
                 hops[i, j], hops.min()))
        if len(m.boundary):
            db = m.dist(m.boundary)
            print("  mesh has %d boundary vertices; nearest feature to a boundary: %.5f" % (len(m.boundary), db[idx].min()))
            ok &= bool(db[idx].min() > 0)
    if list(BUNNY) != list(GARGOYLE):
        print("ERROR: bunny and gargoyle feature names differ")
        ok = False
    return ok


def main():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--meshes", default=os.path.join(root, "..", "shared", "meshes"),
                    help="directory holding horse.obj, armadillo.obj, bunny.obj, gargoyle.obj")
    ap.add_argument("--out", default=os.path.join(root, "tests", "data", "features"))
    ap.add_argument("--check", action="store_true", help="re-run the rules against the meshes (numpy, scipy)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    for out_name, _, _, table in FILES:
        with open(os.path.join(args.out, out_name), "w") as fh:
            fh.write(file_text(out_name, table))
    print("wrote %s" % ", ".join(f[0] for f in FILES))
    if args.check:
        return 0 if check(args.meshes) else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
