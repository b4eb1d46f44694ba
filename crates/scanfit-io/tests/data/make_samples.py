"""Writes the golden sample files of tests/golden.rs with independent
implementations: plyfile (PLY), pypcd4 + python-lzf (PCD), laspy + lazrs
(LAS/LAZ). The values are dyadic, so every encoding holds them exactly.

    pip install plyfile pypcd4 laspy lazrs   # plyfile 1.1, pypcd4 1.5, laspy 2.7
    cd crates/scanfit-io/tests/data && python3 make_samples.py
"""

import numpy as np
from plyfile import PlyData, PlyElement
from pypcd4 import PointCloud, Encoding
import laspy

# ---- PLY: 4 vertices with normals, colour, label, u, v and a list; 2 faces
V = np.array(
    [
        (0.5, -1.25, 2.0, 0.0, 0.0, 1.0, 255, 0, 16, -3, 0.0, 0.125, [1, 2]),
        (1.5, 1024.0, -0.0625, 0.6, 0.8, 0.0, 1, 2, 3, 7, 0.25, 0.5, []),
        (-8.0, 0.375, 1e-3, -1.0, 0.0, 0.0, 10, 20, 30, 0, 0.75, 0.875, [9]),
        (3.0, 4.0, 5.0, 0.0, -1.0, 0.0, 0, 128, 255, 65535, 1.0, 1.0, [4, 5, 6]),
    ],
    dtype=[
        ("x", "f4"), ("y", "f4"), ("z", "f8"),
        ("nx", "f4"), ("ny", "f4"), ("nz", "f4"),
        ("red", "u1"), ("green", "u1"), ("blue", "u1"),
        ("label", "i4"), ("u", "f8"), ("v", "f8"),
        ("tags", "O"),
    ],
)
for row in V:
    row["tags"] = np.array(row["tags"], dtype="i2")
F = np.empty(2, dtype=[("vertex_indices", "O"), ("quality", "f4")])
F["vertex_indices"] = [np.array([0, 1, 2], dtype="i4"), np.array([0, 2, 3, 1], dtype="i4")]
F["quality"] = [0.5, 2.0]


vertex = PlyElement.describe(V, "vertex", len_types={"tags": "u1"}, val_types={"tags": "i2"})
face = PlyElement.describe(F, "face", len_types={"vertex_indices": "u1"})
PlyData([vertex, face], text=True, comments=["scanfit golden sample"]).write("sample_ascii.ply")
PlyData([vertex, face], text=False, byte_order="<").write("sample_binary_le.ply")
# big-endian with the faces BEFORE the vertices. plyfile 1.1 writes the
# scalar properties of an element that has a list property in little-endian
# order even in a big-endian file (its own reader then reads garbage), so the
# big-endian vertices leave the `tags` list out (fixed-size records) and the
# faces keep only their list.
fixed = [n for n in V.dtype.names if n != "tags"]
VB = np.empty(len(V), dtype=[(n, V.dtype[n].newbyteorder(">")) for n in fixed])
for n in fixed:
    VB[n] = V[n]
vertex_be = PlyElement.describe(VB, "vertex")
FB = np.empty(2, dtype=[("vertex_indices", "O")])
FB["vertex_indices"] = [np.array([0, 1, 2], dtype=">i4"), np.array([0, 2, 3, 1], dtype=">i4")]
face_be = PlyElement.describe(FB, "face", len_types={"vertex_indices": "u1"})
PlyData([face_be, vertex_be], text=False, byte_order=">", obj_info=["faces first"]).write("sample_binary_be.ply")
check = PlyData.read("sample_binary_be.ply")["vertex"].data
assert check["y"][1] == 1024.0 and check["label"][3] == 65535, check

# ---- PCD: 5 points (one NaN), intensity, a packed colour, a 2-count field
xyz = np.array(
    [[0.5, -1.25, 2.0], [1.5, 1024.0, -0.0625], [np.nan, np.nan, np.nan],
     [-8.0, 0.375, 0.125], [3.0, 4.0, 5.0]], dtype=np.float32)
intensity = np.array([0.0, 0.5, 1.0, 100.25, 7.0], dtype=np.float32)
rgb = np.array([[255, 0, 16], [1, 2, 3], [0, 0, 0], [10, 20, 30], [0, 128, 255]], dtype=np.uint32)
packed = (rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]
ring = np.array([[1, -1], [2, -2], [0, 0], [3, -300], [4, 32767]], dtype=np.int16)
# pypcd4 writes a COUNT > 1 field of binary_compressed data as one block per
# element (ring_0 of all points, then ring_1), where PCL keeps a point's COUNT
# values together (the layout read here, tested in src/pcd.rs): the
# compressed sample leaves that field out.
for enc, name, rgb_type in [
    (Encoding.ASCII, "ascii", np.uint32),  # pypcd4 prints floats with %.10f: keep rgb an integer
    (Encoding.BINARY, "binary", np.float32),
    (Encoding.BINARY_COMPRESSED, "binary_compressed", np.float32),
]:
    rgb_col = packed.astype(np.uint32).view(np.float32) if rgb_type == np.float32 else packed
    # from_points checks one array per field; a COUNT 2 field is two arrays
    # in the record array, so build the metadata with count 1 and the data
    # with the metadata's COUNT 2 dtype
    columns = [xyz[:, 0], xyz[:, 1], xyz[:, 2], intensity, rgb_col]
    fields = ["x", "y", "z", "intensity", "rgb"]
    types = [np.float32, np.float32, np.float32, np.float32, rgb_type]
    if enc != Encoding.BINARY_COMPRESSED:
        columns.append(ring[:, 0])
        fields.append("ring")
        types.append(np.int16)
    meta = PointCloud.from_points(columns, fields, types).metadata
    if enc != Encoding.BINARY_COMPRESSED:
        meta.count = [1, 1, 1, 1, 1, 2]
        columns.append(ring[:, 1])
    pc = PointCloud(meta, np.rec.fromarrays(columns, dtype=meta.build_dtype()))
    pc.save(f"sample_{name}.pcd", encoding=enc)

# ---- LAS 1.2 point format 3 (gps time + colour) and the same as LAZ
header = laspy.LasHeader(point_format=3, version="1.2")
header.scales = np.array([0.001, 0.001, 0.01])
header.offsets = np.array([500000.0, 4100000.0, 100.0])
las = laspy.LasData(header)
las.X = np.array([123456, -1, 999999], dtype=np.int32)
las.Y = np.array([654321, 0, 5], dtype=np.int32)
las.Z = np.array([1234, -250, 0], dtype=np.int32)
las.intensity = np.array([100, 0, 65535], dtype=np.uint16)
las.return_number = np.array([1, 2, 3], dtype=np.uint8)
las.number_of_returns = np.array([1, 3, 3], dtype=np.uint8)
las.classification = np.array([2, 5, 6], dtype=np.uint8)
las.point_source_id = np.array([7, 7, 8], dtype=np.uint16)
las.gps_time = np.array([1.5, 250000.25, 0.0])
las.red = np.array([65535, 0, 256], dtype=np.uint16)
las.green = np.array([0, 32768, 512], dtype=np.uint16)
las.blue = np.array([1, 2, 3], dtype=np.uint16)
las.write("sample.las")
las.write("sample.laz")
