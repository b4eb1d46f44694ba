#!/usr/bin/env python3
"""Read STEP / IGES files back with OpenCASCADE and describe their faces.

    python3 check_faces.py FILE.stp|FILE.igs [...]

Prints one JSON object per file on its own line:
{"path": ..., "faces": [{"valid": bool, "wires": n, "area": a}, ...],
 "bbox": [xmin, ymin, zmin, xmax, ymax, zmax], "units": [names] (STEP only)}
Lengths are as OpenCASCADE holds them after reading: in millimetres, the
file's declared unit converted. `valid` is BRepCheck_Analyzer on the face,
`wires` the number of wires bounding it (outer + holes), `area` its area by
BRepGProp. Needs `pip install cadquery-ocp`.
"""
import json
import sys

from OCP.Bnd import Bnd_Box
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.IFSelect import IFSelect_RetDone
from OCP.IGESControl import IGESControl_Reader
from OCP.STEPControl import STEPControl_Reader

try:  # the sequence type's name differs between OCP releases
    from OCP.TColStd import TColStd_SequenceOfAsciiString as AsciiStrings
except ImportError:
    from OCP.OCP.collections import Sequence_TCollection_AsciiString as AsciiStrings
from OCP.TopAbs import TopAbs_FACE, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS


def describe(path):
    step = path.lower().endswith((".stp", ".step"))
    reader = STEPControl_Reader() if step else IGESControl_Reader()
    status = reader.ReadFile(path)
    if status != IFSelect_RetDone:
        raise SystemExit(f"{path}: OpenCASCADE could not read the file (status {status})")
    units = []
    if step:
        lengths = AsciiStrings()
        angles = AsciiStrings()
        solids = AsciiStrings()
        reader.FileUnits(lengths, angles, solids)
        units = [lengths.Value(i).ToCString() for i in range(1, lengths.Length() + 1)]
    reader.TransferRoots()
    faces = []
    box = Bnd_Box()
    for i in range(1, reader.NbShapes() + 1):
        shape = reader.Shape(i)
        BRepBndLib.Add_s(shape, box)
        exp = TopExp_Explorer(shape, TopAbs_FACE)
        while exp.More():
            face = TopoDS.Face(exp.Current())
            wires = 0
            w = TopExp_Explorer(face, TopAbs_WIRE)
            while w.More():
                wires += 1
                w.Next()
            props = GProp_GProps()
            BRepGProp.SurfaceProperties_s(face, props)
            faces.append(
                {
                    "valid": bool(BRepCheck_Analyzer(face).IsValid()),
                    "wires": wires,
                    "area": props.Mass(),
                }
            )
            exp.Next()
    bbox = [] if box.IsVoid() else [box.CornerMin().X(), box.CornerMin().Y(), box.CornerMin().Z(),
                                    box.CornerMax().X(), box.CornerMax().Y(), box.CornerMax().Z()]
    return {"path": path, "faces": faces, "bbox": bbox, "units": units}


def main():
    for path in sys.argv[1:]:
        print(json.dumps(describe(path)))


if __name__ == "__main__":
    main()
