"""Reads a pipeline run's outputs with readers that are not diefill's (OpenVDB's Python module,
VTK, meshio, hashlib) and prints what they find as JSON, for tests/test_pipeline.cpp to assert.
    python3 read_outputs.py RUN_DIR DIE_MESH"""
import csv
import hashlib
import json
import sys

import meshio
import numpy as np
import pyopenvdb as vdb
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLImageDataReader

run, die = sys.argv[1], sys.argv[2]
out = {}

grids, _ = vdb.readAll(run + "/density.vdb")
g = {x.name: x for x in grids}
out["vdb_names"] = sorted(g)
phi, cav = g["solid_fraction"], g["cavity_fraction"]
out["vdb_metadata"] = {k: phi[k] for k in ("die_sha256", "die", "coarse_graining", "units", "method")}
out["vdb_voxel_m"] = phi["voxel_size_m"]
out["die_sha256"] = hashlib.sha256(open(die, "rb").read()).hexdigest()
h = phi.transform.voxelSize()[0]
acc = phi.getConstAccessor()
cavity = weighted = 0.0
vdb_values = {}
for item in cav.citerOnValues():
    value = acc.getValue(item.min)
    vdb_values[item.min] = value
    cavity += item.value * h ** 3
    weighted += item.value * value * h ** 3
out["vdb_cavity_volume_m3"] = cavity
out["vdb_solid_fraction_mean"] = weighted / cavity
out["vdb_merged_voxels"] = sum(1 for item in g["merged"].citerOnValues() if item.value > 0)
smoothed = g["smoothed_solid_fraction"]
out["vdb_smoothed_voxel_m"] = smoothed.transform.voxelSize()[0]
out["vdb_smoothed_width_m"] = float(smoothed["width_m"])

reader = vtkXMLImageDataReader()
reader.SetFileName(run + "/density.vti")
reader.Update()
image = reader.GetOutput()
nx, ny, nz = (e - 1 for e in image.GetDimensions())
out["vti_spacing_m"] = image.GetSpacing()[0]
out["vti_arrays"] = sorted(image.GetCellData().GetArrayName(k) for k in range(image.GetCellData().GetNumberOfArrays()))
values = vtk_to_numpy(image.GetCellData().GetArray("solid_fraction")).reshape(nz, ny, nx)
out["vti_vdb_max_difference"] = max(abs(float(values[k, j, i]) - v) for (i, j, k), v in vdb_values.items())
reader = vtkXMLImageDataReader()
reader.SetFileName(run + "/density_smoothed.vti")
reader.Update()
out["smoothed_vti_spacing_m"] = reader.GetOutput().GetSpacing()[0]

grains = meshio.read(run + "/final.vtu")
rows = list(csv.DictReader(open(run + "/particles.csv")))
out["vtu_points"] = len(grains.points)
out["csv_rows"] = len(rows)
radius = np.asarray(grains.point_data["radius"], dtype=float)
out["vtu_csv_max_radius_difference"] = float(max(abs(radius - np.array([float(r["radius"]) for r in rows]))))
out["vtu_csv_max_position_difference"] = float(
    np.abs(grains.points - np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in rows])).max())
print(json.dumps(out))
