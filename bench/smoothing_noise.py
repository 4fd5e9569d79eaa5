#!/usr/bin/python3
"""Noise of the smoothed density field against its resolution, from two seeds of one scene.

    bench/smoothing_noise.py RUN_A RUN_B DIE [WIDTH_MM ...]

RUN_A and RUN_B are two runs' die folders (OUT/<die name>/, particles.csv) of the same scene with
different seeds. For each Gaussian width (voxel = width; default: a quarter, half, one and two
grain diameters), `diefill density` bins each run's cavity grains (centres below the table) and
the per-voxel noise of one run is the cavity-weighted RMS difference of the two fields over
sqrt(2), over voxels at least half inside the cavity. Prints one JSON line per width (the
README's choice of the default width rests on it)."""
import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLImageDataReader

DIEFILL = Path(__file__).resolve().parent.parent / "build" / "diefill"


def cavity_grains(run: Path, into: Path) -> tuple:
    rows = [r for r in csv.DictReader(open(run / "particles.csv")) if float(r["z"]) < 0]
    with open(into, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)
    return 2 * max(float(r["radius"]) for r in rows), json.loads((run / "report.json").read_text())


def smoothed(particles: Path, die: str, width_mm: float, alpha: float, out: Path) -> tuple:
    subprocess.run([str(DIEFILL), "density", str(particles), "--die", die, "--smoothed-width", str(width_mm),
                    "--coarse-graining", str(alpha), "-o", str(out)], check=True, capture_output=True)
    reader = vtkXMLImageDataReader()
    reader.SetFileName(str(out / "density_smoothed.vti"))
    reader.Update()
    data = reader.GetOutput().GetCellData()
    return vtk_to_numpy(data.GetArray("solid_fraction")), vtk_to_numpy(data.GetArray("cavity_fraction"))


def main() -> None:
    run_a, run_b, die = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3]
    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        d_m, report = cavity_grains(run_a, work / "a.csv")
        cavity_grains(run_b, work / "b.csv")
        alpha = report["powder"]["coarse_graining"]
        widths = [float(w) for w in sys.argv[4:]] or [f * d_m * 1e3 for f in (0.25, 0.5, 1.0, 2.0)]
        for w in widths:
            phi_a, cavity = smoothed(work / "a.csv", die, w, alpha, work / f"a{w}")
            phi_b, _ = smoothed(work / "b.csv", die, w, alpha, work / f"b{w}")
            keep = cavity >= 0.5
            weight = cavity[keep]
            diff = (phi_b - phi_a)[keep]
            noise = float(np.sqrt(np.sum(weight * diff * diff) / np.sum(weight)) / np.sqrt(2))
            mean = float(np.sum(weight * phi_a[keep]) / np.sum(weight))
            print(json.dumps({"width_mm": w, "width_over_diameter": w / (d_m * 1e3), "voxels": int(keep.sum()),
                              "mean_solid_fraction": mean, "noise_per_voxel": noise, "relative_noise": noise / mean}))


if __name__ == "__main__":
    main()
