"""Reads a run's `series.pvd` as ParaView's reader does, with Python's XML parser and VTK's XML
readers (not diefill's code), and prints what it finds as JSON for tests/test_sharp_dies.cpp.
    python3 read_series.py RUN_DIR"""
import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader

run = Path(sys.argv[1])
parts = {}
for d in ET.parse(run / "series.pvd").getroot().iter("DataSet"):
    parts.setdefault(d.get("part"), []).append((float(d.get("timestep")), d.get("file")))


def read(reader_type, file):
    reader = reader_type()
    reader.SetFileName(str(run / file))
    reader.Update()
    return reader.GetOutput()


grains = [read(vtkXMLUnstructuredGridReader, f) for _, f in parts["0"]]
die = read(vtkXMLPolyDataReader, parts["1"][0][1])
shoes = [read(vtkXMLPolyDataReader, f) for _, f in parts["2"]]
print(json.dumps({
    "times": [t for t, _ in parts["0"]],
    "same_times_in_every_part": [t for t, _ in parts["0"]] == [t for t, _ in parts["1"]] == [t for t, _ in parts["2"]],
    "grains": [g.GetNumberOfPoints() for g in grains],
    "die_triangles": die.GetNumberOfCells(),
    "die_bounds": list(die.GetBounds()),
    "shoe_x_min": [s.GetBounds()[0] for s in shoes],
}))
