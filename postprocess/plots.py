#!/usr/bin/python3
"""Pictures diefill draws from the data it writes.

    plots.py density OUT_DIR  ->  OUT_DIR/top_view.png, sections.png, histogram.png, profiles.png
                                  (from OUT_DIR/plot_data.json)
    plots.py clump NAME_errors.csv  ->  NAME_errors.png: a clump's errors and cost against its
                                        sphere count
    plots.py study DIR/NAME.json  ->  every chart the study lists under "charts", into DIR
    plots.py fill_curve DIR/fill_curve.csv STRIKE_OFF_S  ->  DIR/fill_curve.png: the mass in the
                                  cavity against time and against the shoe's position
    plots.py compare DIR  ->  DIR/compare.png (from DIR/compare_plot.json): two runs' difference
    plots.py sweep DIR/sweep.json  ->  DIR/sweep.png: fill ratio against the swept key
    plots.py ladder DIR/ladder.json  ->  DIR/extrapolation.png: a grain-size ladder's levels and fit

Each picture has axes with units and, where colour carries a value, a colour bar.
"""
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
import numpy as np  # noqa: E402


MERGED = "x: value merged with a neighbour by the wall correction"


def _mm(metres: float) -> str:
    """A coordinate in mm to 0.01, without a minus sign on zero."""
    return f"{round(metres * 1e3, 2) + 0.0:.2f}"


def _outline(ax, segments) -> None:
    """The die's outline where the view cuts it (segments u0, v0, u1, v1 in metres)."""
    if segments:
        lines = np.array(segments, dtype=float).reshape(-1, 2, 2) * 1e3
        ax.add_collection(LineCollection(lines, colors="black", linewidths=1.2))


def _crop_to(ax, values, extent_mm, shape) -> None:
    """Axes limits on the cavity's voxels (one voxel of margin): nothing below the floor."""
    inside = np.argwhere(values >= 0)
    if inside.size == 0:
        return
    u0, u1, v0, v1 = extent_mm
    du, dv = (u1 - u0) / shape[0], (v1 - v0) / shape[1]
    (i0, k0), (i1, k1) = inside.min(axis=0), inside.max(axis=0)
    ax.set_xlim(u0 + (i0 - 0.5) * du, u0 + (i1 + 1.5) * du)
    ax.set_ylim(v0 + (k0 - 0.5) * dv, v0 + (k1 + 1.5) * dv)


def _merged(ax, flags, extent_mm) -> None:
    """Voxels (or columns) whose value comes from the wall correction's merge: a small cross."""
    flags = np.array(flags, dtype=float)
    where = np.argwhere(flags > 0)
    if where.size == 0:
        return
    u0, u1, v0, v1 = extent_mm
    du, dv = (u1 - u0) / flags.shape[0], (v1 - v0) / flags.shape[1]
    ax.plot(u0 + (where[:, 0] + 0.5) * du, v0 + (where[:, 1] + 0.5) * dv, "x", color="white", markersize=4)


def _section(ax, section, outline, lo, hi, xlabel, title):
    """A vertical section of the field with the die's outline, cropped to the cavity."""
    values = np.array(section["values"], dtype=float)
    extent = [c * 1e3 for c in section["extent_m"]]
    im = ax.imshow(np.ma.masked_less(values, 0).T, origin="lower", extent=extent, cmap="viridis", vmin=lo, vmax=hi,
                   interpolation="nearest", aspect="equal")
    _outline(ax, outline)
    _crop_to(ax, values, extent, values.shape)
    if "merged" in section:
        _merged(ax, section["merged"], extent)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("z [mm]")
    ax.set_title(title, fontsize="small")
    return im


def _stderr_panel(ax, data, top, extent_xy, outline) -> None:
    """An ensemble's standard error of each column's mean, relative to the fill, with the columns
    over the stated fraction marked."""
    error = np.array(data["top_stderr"], dtype=float)
    fraction = data["stderr_marked_fraction"]
    relative = np.where(top > 0, error / np.maximum(data["mean"], 1e-12), -1.0)
    im = ax.imshow(np.ma.masked_less(relative, 0).T * 100, origin="lower", extent=extent_xy, cmap="magma",
                   interpolation="nearest")
    _outline(ax, outline["top"])
    _crop_to(ax, top, extent_xy, top.shape)
    over = np.argwhere(relative > fraction)
    if over.size:
        u0, u1, v0, v1 = extent_xy
        du, dv = (u1 - u0) / relative.shape[0], (v1 - v0) / relative.shape[1]
        ax.plot(u0 + (over[:, 0] + 0.5) * du, v0 + (over[:, 1] + 0.5) * dv, "+", color="cyan", markersize=5)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(f"Standard error of the column means over the seeds\n+: above {fraction * 100:.0f} % of the fill",
                 fontsize="small")
    plt.colorbar(im, ax=ax, label="standard error / mean fill [%]")


def density(out_dir: Path) -> None:
    data = json.loads((out_dir / "plot_data.json").read_text())
    h_mm = data["voxel_m"] * 1e3
    ox, oy, _ = (c * 1e3 for c in data["origin_m"])
    nx, ny, _ = data["shape"]
    extent_xy = [ox, ox + nx * h_mm, oy, oy + ny * h_mm]
    lo, hi = data["colour_range"]
    outline = data["outline"]

    top = np.array(data["top_view"], dtype=float)
    ensemble = "top_stderr" in data
    fig, axes = plt.subplots(1, 2 if ensemble else 1, figsize=(12.4 if ensemble else 6.4, 5.4), squeeze=False)
    ax = axes[0][0]
    im = ax.imshow(np.ma.masked_less(top, 0).T, origin="lower", extent=extent_xy, cmap="viridis", vmin=lo, vmax=hi,
                   interpolation="nearest")
    _outline(ax, outline["top"])
    _crop_to(ax, top, extent_xy, top.shape)
    _merged(ax, data["top_merged"], extent_xy)
    ax.set_xlabel("x [mm]    shoe travel \u2192 (+x)")
    ax.set_ylabel("y [mm]")
    what = "the seeds' mean, " if ensemble else ""
    ax.set_title(f"Fill density, {what}column average of the wall-corrected field\n{MERGED}", fontsize="small")
    fig.colorbar(im, ax=ax, label="solid fraction [-]", extend="both")
    if ensemble:
        _stderr_panel(axes[0][1], data, top, extent_xy, outline)
    fig.tight_layout()
    fig.savefig(out_dir / "top_view.png", dpi=120)
    plt.close(fig)

    rows = [("", data["sections"], h_mm)]
    if "smoothed" in data:
        rows.append(("smoothed ", data["smoothed"]["sections"], data["smoothed"]["width_m"] * 1e3))
    fig, axes = plt.subplots(len(rows), 2, figsize=(11, 3.6 * len(rows)), squeeze=False)
    for row, (kind, sections, size_mm) in zip(axes, rows):
        along, across = sections["along"], sections["across"]
        what = f"smoothed: Gaussian width and voxel {size_mm:.2g} mm" if kind else f"{size_mm:.2g} mm voxels, exact"
        im = _section(row[0], along, outline["along"], lo, hi, "x [mm]    shoe travel \u2192 (+x)",
                      f"Along the shoe's path, y = {_mm(along['at_m'])} mm\n{what}")
        _section(row[1], across, outline["across"], lo, hi, "y [mm]", f"Across it, x = {_mm(across['at_m'])} mm\n{what}")
        fig.colorbar(im, ax=row.tolist(), label="solid fraction [-]", extend="both", shrink=0.9)
    fig.suptitle(f"Sections through the die's centre ({MERGED})", fontsize="medium")
    fig.savefig(out_dir / "sections.png", dpi=120, bbox_inches="tight")
    plt.close(fig)

    values = np.array(data["histogram_values"], dtype=float)
    fig, ax = plt.subplots(figsize=(6, 4))
    if values.size:
        ax.hist(values, bins=40, weights=np.array(data["histogram_weights"]), color="tab:blue")
        ax.axvline(data["mean"], color="k", linestyle="--", label=f"mean {data['mean']:.3f}")
        ax.legend()
    ax.set_xlabel("solid fraction [-]")
    ax.set_ylabel("cavity volume [voxels]")
    ax.set_title("Distribution of the fill density")
    fig.tight_layout()
    fig.savefig(out_dir / "histogram.png", dpi=120)
    plt.close(fig)

    profiles = data.get("profiles", {})
    smoothed = data.get("smoothed", {}).get("profiles", {})
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.8))
    for ax, (axis, label) in zip(axes, [("z", "height z [mm]"), ("r", "radius from the die axis [mm]"), ("x", "x along the shoe path [mm]")]):
        if axis in profiles and profiles[axis]["position_m"]:
            p = profiles[axis]
            ax.errorbar(np.array(p["position_m"]) * 1e3, p["solid_fraction"], yerr=p["spread"], marker="o", markersize=3,
                        capsize=3, linestyle="none", label=f"{h_mm:.2g} mm bins (bars: spread of their voxels)")
        if axis in smoothed and smoothed[axis]["position_m"]:
            p = smoothed[axis]
            ax.plot(np.array(p["position_m"]) * 1e3, p["solid_fraction"], color="tab:orange", linewidth=1.2,
                    label=f"smoothed field, {data['smoothed']['width_m'] * 1e3:.2g} mm bins")
        if ax.has_data():
            ax.legend(fontsize="x-small")
        ax.set_xlabel(label)
        ax.set_ylabel("solid fraction [-]")
        ax.grid(alpha=0.3)
    fig.suptitle("Fill density profiles (bins one voxel wide; bins mostly outside the cavity left out)")
    fig.tight_layout()
    fig.savefig(out_dir / "profiles.png", dpi=120)
    plt.close(fig)


def clump(csv: Path) -> None:
    data = np.genfromtxt(csv, delimiter=",", names=True)
    data = np.atleast_1d(data)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.semilogy(data["spheres"], data["volume_error"], "o-", label="volume error")
    ax.semilogy(data["spheres"], data["hausdorff_error"], "s-", label="Hausdorff error / equivalent diameter")
    ax.set_xlabel("spheres per grain")
    ax.set_ylabel("relative error [-]")
    ax.grid(alpha=0.3, which="both")
    cost = ax.twinx()
    cost.plot(data["spheres"], data["relative_cost"], "k:", label="relative cost")
    cost.set_ylabel("time per step relative to spheres [-]")
    lines = ax.get_legend_handles_labels()
    more = cost.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], loc="upper center")
    ax.set_title(f"Clump of {csv.stem.removesuffix('_errors')}")
    fig.tight_layout()
    fig.savefig(csv.with_suffix(".png"), dpi=120)
    plt.close(fig)


def study(document: Path) -> None:
    """Charts described by the study itself: series of points (with error bars) or lines."""
    data = json.loads(document.read_text())
    markers = iter("osD^vP*X" * 4)
    for chart in data["charts"]:
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        for series in chart["series"]:
            if not series["x"]:
                continue
            if series["style"] == "line":
                ax.plot(series["x"], series["y"], "-", label=series["label"])
            else:
                error = series["error"] if series["error"] else None
                ax.errorbar(series["x"], series["y"], yerr=error, fmt=next(markers), capsize=3, label=series["label"])
        if chart["log_x"]:
            ax.set_xscale("log")
        if chart["log_y"]:
            ax.set_yscale("log")
        if chart["y_ticks"]:
            ax.set_yticks(range(len(chart["y_ticks"])))
            ax.set_yticklabels(chart["y_ticks"])
            ax.set_ylim(-0.5, len(chart["y_ticks"]) - 0.5)
        ax.set_xlabel(chart["x_label"])
        ax.set_ylabel(chart["y_label"])
        ax.set_title(chart["title"])
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize="small")
        fig.tight_layout()
        fig.savefig(document.parent / chart["file"], dpi=120)
        plt.close(fig)


def fill_curve(csv: Path, strike_off_s: float) -> None:
    rows = np.genfromtxt(csv, delimiter=",", names=True)
    t, x, fraction = np.atleast_1d(rows["t_s"]), np.atleast_1d(rows["shoe_x_m"]) * 1e3, np.atleast_1d(rows["fraction_of_capacity"])
    mass_g = np.atleast_1d(rows["mass_in_cavity_kg"]) * 1e3
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    left.plot(t, mass_g, color="tab:blue")
    if "mass_in_cavity_kg_stderr" in rows.dtype.names:  # a seed ensemble: its mean with a band of 2 standard errors
        band_g = 2 * np.atleast_1d(rows["mass_in_cavity_kg_stderr"]) * 1e3
        left.fill_between(t, mass_g - band_g, mass_g + band_g, color="tab:blue", alpha=0.25, label="\u00b12 standard errors")
    left.axvline(strike_off_s, color="k", linestyle="--", label=f"strike-off, t = {strike_off_s:.3f} s")
    left.set_xlabel("time [s]")
    left.set_ylabel("mass in the cavity [g]")
    if fraction.max() > 0:  # the same curve on the capacity's scale
        capacity_g = mass_g.max() / fraction.max()
        twin = left.twinx()
        twin.set_ylim(*(np.array(left.get_ylim()) / capacity_g))
        twin.set_ylabel("fraction of the cavity's capacity [-]")
    left.legend(loc="lower right")
    left.grid(alpha=0.3)
    moving = np.concatenate([[True], np.diff(x) != 0])
    right.plot(x[moving], mass_g[moving], color="tab:orange")
    right.set_xlabel("shoe centre x [mm] (shoe travel, +x)")
    right.set_ylabel("mass in the cavity [g]")
    right.grid(alpha=0.3)
    fig.suptitle("Fill curve: powder delivered into the die")
    fig.tight_layout()
    fig.savefig(csv.with_suffix(".png"), dpi=120)
    plt.close(fig)


def compare(out_dir: Path) -> None:
    """Two runs side by side: the top view of B - A and both runs' profiles."""
    data = json.loads((out_dir / "compare_plot.json").read_text())
    top = np.ma.masked_less(np.array(data.get("top_difference", [[-2.0]]), dtype=float), -1.5)
    reach = max(float(np.abs(top).max()) if top.count() else 0.0, 1e-6)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.4))
    im = axes[0].imshow(top.T, origin="lower", extent=[c * 1e3 for c in data.get("extent_m", [0, 1, 0, 1])], cmap="RdBu_r", vmin=-reach,
                        vmax=reach, interpolation="nearest")
    fig.colorbar(im, ax=axes[0], label="solid fraction, B - A [-]")
    axes[0].set_xlabel("x [mm]    shoe travel \u2192 (+x)")
    axes[0].set_ylabel("y [mm]")
    axes[0].set_title("Difference, column mean (cavity-weighted)", fontsize="medium")
    for ax, (axis, label) in zip(axes[1:], [("z", "height z [mm]"), ("r", "radius from the die axis [mm]")]):
        for run, label_run, colour in zip(("a", "b"), data["labels"], ("tab:blue", "tab:orange")):
            p = data["profiles"][run].get(axis)
            if p and p["position_m"]:
                ax.errorbar(np.array(p["position_m"]) * 1e3, p["solid_fraction"], yerr=p.get("spread"), marker="o",
                            markersize=3, capsize=3, color=colour, label=label_run)
        ax.set_xlabel(label)
        ax.set_ylabel("solid fraction [-]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize="x-small")
    fig.suptitle("Two runs compared")
    fig.tight_layout()
    fig.savefig(out_dir / "compare.png", dpi=120)
    plt.close(fig)


def sweep(summary: Path) -> None:
    """Fill ratio against the swept key's value."""
    data = json.loads(summary.read_text())
    cases = data["cases"]
    try:
        x = [float(c["value"]) for c in cases]
    except ValueError:  # a key whose values are words: one tick each
        x = list(range(len(cases)))
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.plot(x, [c["fill_ratio"] for c in cases], "o-")
    if not all(isinstance(v, float) for v in x):
        ax.set_xticks(x)
        ax.set_xticklabels([c["value"] for c in cases])
    ax.set_xlabel(data["key"])
    ax.set_ylabel("fill ratio [-]")
    ax.set_title(f"Fill ratio against {data['key']}")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(summary.with_suffix(".png"), dpi=120)
    plt.close(fig)


def compaction(document: Path) -> None:
    """The worked CalculiX example: each element's axial stress against its fill solid fraction."""
    data = json.loads(document.read_text())
    phi = np.array(data["solid_fraction"], dtype=float)
    stress = -np.array(data["axial_stress_pa"], dtype=float) / 1e6  # compressive positive
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.scatter(phi, stress, s=4, alpha=0.4)
    ax.set_xlabel("fill solid fraction of the element [-]")
    ax.set_ylabel("axial stress, compressive [MPa]")
    ax.set_title(f"Punch at {100 * data['axial_strain']:.3g} % strain: {data['punch_force_n'] / 1e3:.4g} kN\n"
                 "(linear elastic, E tabulated against the fill; CalculiX)", fontsize="medium")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(document.with_suffix(".png"), dpi=120)
    plt.close(fig)


def ladder(document: Path) -> None:
    """A grain-size ladder: each level's fill ratio (2 standard errors) against the grain diameter,
    the fitted line with its band, and the extrapolated answer."""
    data = json.loads(document.read_text())
    d = np.array([level["grain_diameter_m"] for level in data["levels"]]) * 1e3
    y = np.array([level["fill_ratio"] for level in data["levels"]])
    se = np.array([level["fill_ratio_stderr"] for level in data["levels"]])
    target = data["to_grain_diameter_m"] * 1e3
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.errorbar(d, y, yerr=2 * se, fmt="o", color="tab:blue", capsize=3, label="levels (\u00b12 standard errors)")
    line = np.linspace(min(target, d.min()), d.max(), 50)
    slope = data["slope_per_m"] * 1e-3
    at_target = data["fill_ratio"]
    ax.plot(line, at_target + slope * (line - target), color="tab:blue", linewidth=1)
    ax.errorbar([target], [at_target], yerr=[2 * data["fill_ratio_stderr"]], fmt="s", color="tab:red", capsize=3,
                label=f"extrapolated to \u03b1 = {data['to_coarse_graining']:.3g}: {at_target:.4f} \u00b1 {data['fill_ratio_stderr']:.4f}")
    ax.set_xlabel("grain diameter [mm]")
    ax.set_ylabel("fill ratio [-]")
    title = "Fill ratio against the grain size, affine fit"
    if data.get("refused"):
        title += "\nrefused: the levels lie off a line beyond their noise"
    ax.set_title(title, fontsize="medium")
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(document.parent / "extrapolation.png", dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    if sys.argv[1] == "fill_curve":
        fill_curve(Path(sys.argv[2]), float(sys.argv[3]))
    else:
        {"density": density, "clump": clump, "study": study, "compare": compare, "sweep": sweep,
         "compaction": compaction, "ladder": ladder}[sys.argv[1]](Path(sys.argv[2]))
