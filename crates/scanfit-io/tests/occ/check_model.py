#!/usr/bin/env python3
"""Read a scanfit multi-patch STEP file back with OpenCASCADE and compare it
with the model's JSON document (schema scanfit-model/1).

    python3 check_model.py MODEL.json FILE.stp [SAMPLES_PER_SIDE]

Prints one JSON object on stdout:

    {"shells": 1, "faces": 6, "solids": 1, "valid": true,
     "invalid": [],                       # sub-shapes BRepCheck finds invalid
     "free_edges": 0, "free_edge_length": 0.0,
     "volume": 1.0,                       # of the solid(s), null without one
     "area": 6.0,
     "json_patches": 6, "max_face_diff": 3e-16,
     "orientations": ["FORWARD", ...],    # of every face as read
     "degenerated": 0,                    # degenerated edges OpenCASCADE added
     "max_tolerance": 1e-07}              # largest edge/vertex tolerance

* shells/faces/solids: counts in the transferred shape (TopExp_Explorer);
* valid: BRepCheck_Analyzer on the whole shape;
* free edges: ShapeAnalysis_FreeBounds on the shape (edges used by one face
  only: the open border), with their total length (GProp);
* volume: BRepGProp.VolumeProperties of every solid (summed);
* max_face_diff: every face's surface (BRep_Tool.Surface) is evaluated by
  OpenCASCADE at a grid of parameters over the JSON patch's domain and
  compared with the JSON patch's B-spline evaluated here independently
  (Cox-de Boor in plain Python, rational by homogeneous coordinates); faces
  and patches are matched in file order;
* orientations: each face's orientation in the shell as read. A face written
  with same_sense .T. reads FORWARD unless OpenCASCADE had to turn it (it
  orients a solid's shell outwards itself), so comparing with what was
  written shows whether the file's orientation was already right;
* degenerated: edges OpenCASCADE marked degenerated (it adds one at the apex
  of a three-sided face whose collapsed side is not in the file);
* max_tolerance: the largest edge and vertex tolerance after reading
  (OpenCASCADE raises tolerances to cover gaps, so this measures the sewing).

Exits 0 when the file was read (the caller asserts on the numbers), 2 when
OpenCASCADE could not read it. Needs `pip install cadquery-ocp`.
"""
import json
import sys

from OCP.BRep import BRep_Tool
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.IFSelect import IFSelect_RetDone
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_SHELL, TopAbs_SOLID, TopAbs_VERTEX, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS


def read_step(path):
    reader = STEPControl_Reader()
    status = reader.ReadFile(path)
    if status != IFSelect_RetDone:
        print(json.dumps({"error": f"OpenCASCADE could not read {path} (status {status})"}))
        sys.exit(2)
    reader.TransferRoots()
    if reader.NbShapes() != 1:
        print(json.dumps({"error": f"{path}: {reader.NbShapes()} root shapes, expected 1"}))
        sys.exit(2)
    return reader.OneShape()


def explore(shape, kind):
    out = []
    exp = TopExp_Explorer(shape, kind)
    while exp.More():
        out.append(exp.Current())
        exp.Next()
    return out


def find_span(knots, p, u):
    n = len(knots) - p - 2
    if u >= knots[n + 1]:
        # the last non-empty span
        s = n
        while s > p and knots[s] == knots[s + 1]:
            s -= 1
        return s
    if u <= knots[p]:
        s = p
        while knots[s + 1] == knots[s]:
            s += 1
        return s
    lo, hi = p, n + 1
    mid = (lo + hi) // 2
    while u < knots[mid] or u >= knots[mid + 1]:
        if u < knots[mid]:
            hi = mid
        else:
            lo = mid
        mid = (lo + hi) // 2
    return mid


def basis(knots, p, s, u):
    n = [1.0] + [0.0] * p
    left = [0.0] * (p + 1)
    right = [0.0] * (p + 1)
    for j in range(1, p + 1):
        left[j] = u - knots[s + 1 - j]
        right[j] = knots[s + j] - u
        saved = 0.0
        for r in range(j):
            t = n[r] / (right[r + 1] + left[j - r])
            n[r] = saved + right[r + 1] * t
            saved = left[j - r] * t
        n[j] = saved
    return n


def domain(knots, p):
    return knots[p], knots[len(knots) - 1 - p]


def eval_surface(doc, u, v):
    p, q = doc["degree_u"], doc["degree_v"]
    ku, kv = doc["knots_u"], doc["knots_v"]
    nv = doc["count_v"]
    ctrl = doc["control_points"]
    w = doc.get("weights")
    su, sv = find_span(ku, p, u), find_span(kv, q, v)
    bu, bv = basis(ku, p, su, u), basis(kv, q, sv, v)
    acc = [0.0, 0.0, 0.0, 0.0]
    for a in range(p + 1):
        i = su - p + a
        for b in range(q + 1):
            j = sv - q + b
            k = i * nv + j
            wt = bu[a] * bv[b] * (w[k] if w else 1.0)
            c = ctrl[k]
            acc[0] += c[0] * wt
            acc[1] += c[1] * wt
            acc[2] += c[2] * wt
            acc[3] += wt
    return acc[0] / acc[3], acc[1] / acc[3], acc[2] / acc[3]


def length(edges):
    total = 0.0
    for e in edges:
        props = GProp_GProps()
        BRepGProp.LinearProperties_s(e, props)
        total += props.Mass()
    return total


def invalid_subshapes(shape):
    """Validity, and the sub-shapes BRepCheck finds invalid (kind and index)."""
    analyzer = BRepCheck_Analyzer(shape)
    if analyzer.IsValid():
        return True, []
    bad = []
    for kind, name in [
        (TopAbs_VERTEX, "vertex"),
        (TopAbs_EDGE, "edge"),
        (TopAbs_WIRE, "wire"),
        (TopAbs_FACE, "face"),
        (TopAbs_SHELL, "shell"),
        (TopAbs_SOLID, "solid"),
    ]:
        for i, sub in enumerate(explore(shape, kind)):
            if not analyzer.IsValid(sub):
                # (the status list itself is not exposed by every OCP build)
                bad.append(f"{name} {i}")
    return False, bad


def main():
    model = json.load(open(sys.argv[1]))
    shape = read_step(sys.argv[2])
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 7
    shells = explore(shape, TopAbs_SHELL)
    faces = [TopoDS.Face(f) for f in explore(shape, TopAbs_FACE)]
    solids = explore(shape, TopAbs_SOLID)
    valid, invalid = invalid_subshapes(shape)

    fb = ShapeAnalysis_FreeBounds(shape, False, False, False)
    free = explore(fb.GetClosedWires(), TopAbs_EDGE) + explore(fb.GetOpenWires(), TopAbs_EDGE)

    volume = None
    if solids:
        volume = 0.0
        for s in solids:
            props = GProp_GProps()
            BRepGProp.VolumeProperties_s(s, props)
            volume += props.Mass()
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, props)
    area = props.Mass()

    orientations = [str(f.Orientation()).split(".")[-1].replace("TopAbs_", "") for f in faces]
    edges = [TopoDS.Edge(e) for e in explore(shape, TopAbs_EDGE)]
    degenerated = sum(1 for e in edges if BRep_Tool.Degenerated_s(e))
    tolerances = [BRep_Tool.Tolerance_s(e) for e in edges]
    tolerances += [BRep_Tool.Tolerance_s(TopoDS.Vertex(v)) for v in explore(shape, TopAbs_VERTEX)]

    patches = model["patches"]
    worst = None
    if len(patches) == len(faces):
        worst = 0.0
        for face, patch in zip(faces, patches):
            doc = patch["surface"]
            surf = BRep_Tool.Surface_s(face)
            u0, u1 = domain(doc["knots_u"], doc["degree_u"])
            v0, v1 = domain(doc["knots_v"], doc["degree_v"])
            for i in range(n + 1):
                for j in range(n + 1):
                    u = u0 + (u1 - u0) * i / n
                    v = v0 + (v1 - v0) * j / n
                    x, y, z = eval_surface(doc, u, v)
                    p = surf.Value(u, v)
                    worst = max(worst, abs(p.X() - x), abs(p.Y() - y), abs(p.Z() - z))
    print(
        json.dumps(
            {
                "shells": len(shells),
                "faces": len(faces),
                "solids": len(solids),
                "valid": bool(valid),
                "invalid": invalid,
                "free_edges": len(free),
                "free_edge_length": length(free),
                "volume": volume,
                "area": area,
                "json_patches": len(patches),
                "max_face_diff": worst,
                "orientations": orientations,
                "degenerated": degenerated,
                "max_tolerance": max(tolerances) if tolerances else None,
            }
        )
    )


if __name__ == "__main__":
    main()
