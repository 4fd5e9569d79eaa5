"""The FEM hand-off's elements against the grains themselves and against the smoothed field, read
with meshio, OpenVDB's Python module and the CSV module (not diefill's code): for the elements with
a face on the die's walls or floor, and for the others, the volume-weighted means of the elements'
solid fraction, of the truth (the share of random points of each element that lie inside a grain
of particles.csv) and of the smoothed field sampled at those points. Prints JSON for
tests/test_pipeline.cpp.
    python3 fem_wall_layer.py RUN_DIR"""
import csv
import json
import sys

import meshio
import numpy as np
import pyopenvdb as vdb

run = sys.argv[1]
mesh = meshio.read(run + "/fem/fill.vtu")
nodes = mesh.points
tets = mesh.cells_dict["tetra"]
phi = np.asarray(mesh.cell_data_dict["solid_fraction"]["tetra"], dtype=float)
grids, _ = vdb.readAll(run + "/density.vdb")
smoothed = {g.name: g for g in grids}["smoothed_solid_fraction"]
values = smoothed.getConstAccessor()

# A face on the boundary belongs to one element; one below the table's plane is on the die.
faces = {}
for e, t in enumerate(tets):
    for skip in range(4):
        key = tuple(sorted(int(t[k]) for k in range(4) if k != skip))
        faces.setdefault(key, []).append(e)
top = nodes[:, 2].max()
at_wall = np.zeros(len(tets), dtype=bool)
for face, owners in faces.items():
    if len(owners) == 1 and nodes[list(face), 2].min() < top - 1e-9:
        at_wall[owners[0]] = True

rows = list(csv.DictReader(open(run + "/particles.csv")))
centres = np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in rows])
radii = np.array([float(r["radius"]) for r in rows])

random = np.random.default_rng(1)
corners = nodes[tets]  # [elements, 4, 3]
volume = np.abs(np.einsum("ij,ij->i", np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                          corners[:, 3] - corners[:, 0])) / 6
samples = 256
sampled = np.zeros(len(tets))
truth = np.zeros(len(tets))
for e in range(len(tets)):
    weights = random.dirichlet(np.ones(4), size=samples)
    points = weights @ corners[e]
    lo, hi = corners[e].min(axis=0), corners[e].max(axis=0)
    near = np.all((centres + radii[:, None] > lo) & (centres - radii[:, None] < hi), axis=1)
    if near.any():
        apart = np.linalg.norm(points[:, None, :] - centres[near][None, :, :], axis=2)
        truth[e] = np.mean(np.any(apart < radii[near][None, :], axis=1))
    read = []
    for p in points:
        ijk = smoothed.transform.worldToIndexCellCentered(tuple(float(x) for x in p))
        value, active = values.probeValue(ijk)
        if active:
            read.append(value)
    sampled[e] = np.mean(read) if read else np.nan

out = {}
for name, chosen in (("wall", at_wall), ("interior", ~at_wall)):
    ok = chosen & np.isfinite(sampled)
    out[name] = {"elements": int(chosen.sum()),
                 "element_mean": float(np.sum(volume[ok] * phi[ok]) / np.sum(volume[ok])),
                 "truth_mean": float(np.sum(volume[ok] * truth[ok]) / np.sum(volume[ok])),
                 # The truth's sampling error: each element's binomial variance, volume-weighted.
                 "truth_sigma": float(np.sqrt(np.sum(volume[ok] ** 2 * truth[ok] * (1 - truth[ok]) / samples)) / np.sum(volume[ok])),
                 "smoothed_mean": float(np.sum(volume[ok] * sampled[ok]) / np.sum(volume[ok]))}
print(json.dumps(out))
