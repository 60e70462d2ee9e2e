#!/usr/bin/env python3
# Rebuilds the per-mesh OBJ files that ../shared/scenes/breakfast-room/scene_mitsuba.xml names
# (models/MeshNNN.obj), which the shared copy ships merged into breakfast_room.obj (one
# "o MeshNNN" object each; the XML's own rectangle and sun sphere are in the OBJ too and are
# skipped). Writes OUT/scene_mitsuba.xml and OUT/models/*.obj, so that drift can load the
# Mitsuba scene as its author wrote it. The merged OBJ is in world space; the two shapes whose
# toWorld is not the identity get their vertices back in their local space (its inverse).
# Usage:
#   python3 split_breakfast_room.py ../shared/scenes/breakfast-room OUT
import os, re, shutil, sys

src, out = sys.argv[1], sys.argv[2]
os.makedirs(os.path.join(out, "models"), exist_ok=True)
shutil.copy(os.path.join(src, "scene_mitsuba.xml"), out)
xml = open(os.path.join(src, "scene_mitsuba.xml")).read()
to_world = {}  # MeshNNN -> 3x4 row-major matrix
for shape in re.findall(r'<shape type="obj">(.*?)</shape>', xml, re.S):
    name = re.search(r'models/(Mesh\d+)\.obj', shape).group(1)
    m = re.search(r'<matrix value="([^"]+)"', shape)
    if m:
        to_world[name] = [float(x) for x in m.group(1).split()]


def inverse_affine(m):
    a = [[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]]
    t = [m[3], m[7], m[11]]
    det = (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
    inv = [[(a[(j + 1) % 3][(i + 1) % 3] * a[(j + 2) % 3][(i + 2) % 3] -
             a[(j + 1) % 3][(i + 2) % 3] * a[(j + 2) % 3][(i + 1) % 3]) / det
            for j in range(3)] for i in range(3)]
    it = [-sum(inv[i][k] * t[k] for k in range(3)) for i in range(3)]
    return inv, it


def local_vertex(line, inverse):
    inv, it = inverse
    p = [float(x) for x in line.split()[1:4]]
    q = [sum(inv[i][k] * p[k] for k in range(3)) + it[i] for i in range(3)]
    return "v %.7g %.7g %.7g\n" % tuple(q)


def local_normal(line, m):
    # World normals are M^-T times local ones, so the local normal is M^T times the world one.
    n = [float(x) for x in line.split()[1:4]]
    a = [[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]]
    q = [sum(a[k][i] * n[k] for k in range(3)) for i in range(3)]
    return "vn %.7g %.7g %.7g\n" % tuple(q)


v, vt, vn = [], [], []
objects = {}  # name -> list of face lines (global indices)
current = None
with open(os.path.join(src, "breakfast_room.obj")) as f:
    for line in f:
        if line.startswith("v "):
            v.append(line)
        elif line.startswith("vt "):
            vt.append(line)
        elif line.startswith("vn "):
            vn.append(line)
        elif line.startswith("o "):
            current = line.split()[1]
            objects[current] = []
        elif line.startswith("f ") and current:
            objects[current].append(line.split()[1:])
for name, faces in objects.items():
    if not name.startswith("Mesh"):
        continue
    maps = [{}, {}, {}]
    lists = [[], [], []]
    sources = [v, vt, vn]
    out_faces = []
    for face in faces:
        corners = []
        for corner in face:
            parts = corner.split("/")
            new = []
            for k, p in enumerate(parts):
                if not p:
                    new.append("")
                    continue
                i = int(p)
                i = i - 1 if i > 0 else len(sources[k]) + i
                if i not in maps[k]:
                    maps[k][i] = len(lists[k]) + 1
                    lists[k].append(sources[k][i])
                new.append(str(maps[k][i]))
            corners.append("/".join(new))
        out_faces.append("f " + " ".join(corners) + "\n")
    m = to_world.get(name)
    if m and m != [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]:
        inverse = inverse_affine(m)
        lists[0] = [local_vertex(l, inverse) for l in lists[0]]
        lists[2] = [local_normal(l, m) for l in lists[2]]
    with open(os.path.join(out, "models", name + ".obj"), "w") as g:
        g.writelines(lists[0] + lists[1] + lists[2] + out_faces)
