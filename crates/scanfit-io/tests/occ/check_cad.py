#!/usr/bin/env python3
"""Read scanfit's STEP (and IGES) files back with OpenCASCADE and compare.

    python3 check_cad.py SAMPLES.json FILE.stp [FILE.igs ...]

SAMPLES.json: {"surfaces": [[[u, v, x, y, z], ...], ...], "curves": [[[t, x, y, z], ...], ...]}
in file order. Every face's surface and every free curve (not a face boundary)
is evaluated by OpenCASCADE at the given parameters and compared with scanfit's
points; prints the largest difference per file and exits 1 above 1e-9.
Needs `pip install cadquery-ocp`.
"""
import json
import sys

from OCP.BRep import BRep_Tool
from OCP.IFSelect import IFSelect_RetDone
from OCP.IGESControl import IGESControl_Reader
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS


def shapes(path):
    reader = STEPControl_Reader() if path.lower().endswith((".stp", ".step")) else IGESControl_Reader()
    status = reader.ReadFile(path)
    if status != IFSelect_RetDone:
        raise SystemExit(f"{path}: OpenCASCADE could not read the file (status {status})")
    reader.TransferRoots()
    return [reader.Shape(i) for i in range(1, reader.NbShapes() + 1)]


def faces_and_free_edges(path):
    faces, edges = [], []
    for shape in shapes(path):
        exp = TopExp_Explorer(shape, TopAbs_FACE)
        while exp.More():
            faces.append(TopoDS.Face(exp.Current()))
            exp.Next()
        # edges outside faces: the free curves
        exp = TopExp_Explorer(shape, TopAbs_EDGE, TopAbs_FACE)
        while exp.More():
            edges.append(TopoDS.Edge(exp.Current()))
            exp.Next()
    return faces, edges


def main():
    samples = json.load(open(sys.argv[1]))
    worst_all = 0.0
    for path in sys.argv[2:]:
        faces, edges = faces_and_free_edges(path)
        if len(faces) != len(samples["surfaces"]) or len(edges) != len(samples["curves"]):
            raise SystemExit(
                f"{path}: OpenCASCADE found {len(faces)} faces and {len(edges)} free curves, "
                f"expected {len(samples['surfaces'])} and {len(samples['curves'])}"
            )
        worst = 0.0
        for face, pts in zip(faces, samples["surfaces"]):
            surf = BRep_Tool.Surface_s(face)
            for u, v, x, y, z in pts:
                p = surf.Value(u, v)
                worst = max(worst, abs(p.X() - x), abs(p.Y() - y), abs(p.Z() - z))
        for edge, pts in zip(edges, samples["curves"]):
            curve = BRep_Tool.Curve_s(edge, 0.0, 1.0)
            for t, x, y, z in pts:
                p = curve.Value(t)
                worst = max(worst, abs(p.X() - x), abs(p.Y() - y), abs(p.Z() - z))
        print(f"{path}: {len(faces)} faces, {len(edges)} curves, max |OCC - scanfit| = {worst:.3e}")
        worst_all = max(worst_all, worst)
    sys.exit(0 if worst_all <= 1e-9 else 1)


if __name__ == "__main__":
    main()
