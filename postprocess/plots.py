#!/usr/bin/python3
"""Pictures diefill draws from the data it writes.

    plots.py density OUT_DIR  ->  OUT_DIR/top_view.png, section.png, histogram.png, profiles.png
                                  (from OUT_DIR/plot_data.json)
    plots.py clump NAME_errors.csv  ->  NAME_errors.png: a clump's errors and cost against its
                                        sphere count
    plots.py study DIR/NAME.json  ->  every chart the study lists under "charts", into DIR
    plots.py fill_curve DIR/fill_curve.csv STRIKE_OFF_S  ->  DIR/fill_curve.png: the mass in the
                                  cavity against time and against the shoe's position

Each picture has axes with units and, where colour carries a value, a colour bar.
"""
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def density(out_dir: Path) -> None:
    data = json.loads((out_dir / "plot_data.json").read_text())
    h_mm = data["voxel_m"] * 1e3
    ox, oy, oz = (c * 1e3 for c in data["origin_m"])
    nx, ny, nz = data["shape"]
    extent_xy = [ox, ox + nx * h_mm, oy, oy + ny * h_mm]

    top = np.array(data["top_view"], dtype=float).T
    cavity = np.array(data["top_cavity_voxels"], dtype=float).T
    top = np.ma.masked_less(top, 0)
    values = np.array(data["histogram_values"], dtype=float)
    lo, hi = (np.percentile(values, 1), np.percentile(values, 99)) if values.size else (0, 1)

    fig, ax = plt.subplots(figsize=(6, 5))
    im = ax.imshow(top, origin="lower", extent=extent_xy, cmap="viridis", vmin=lo, vmax=hi, interpolation="nearest")
    ax.contour(np.linspace(ox + h_mm / 2, ox + (nx - 0.5) * h_mm, nx), np.linspace(oy + h_mm / 2, oy + (ny - 0.5) * h_mm, ny),
               cavity / max(cavity.max(), 1e-12), levels=[0.5], colors="white", linewidths=1.0)
    ax.set_xlabel("x [mm] (shoe travel)")
    ax.set_ylabel("y [mm]")
    ax.set_title("Fill density, column average (top view)")
    fig.colorbar(im, ax=ax, label="solid fraction [-]")
    fig.tight_layout()
    fig.savefig(out_dir / "top_view.png", dpi=120)
    plt.close(fig)

    section = np.ma.masked_less(np.array(data["section"], dtype=float).T, 0)
    fig, ax = plt.subplots(figsize=(6, 4))
    im = ax.imshow(section, origin="lower", extent=[ox, ox + nx * h_mm, oz, oz + nz * h_mm], cmap="viridis",
                   vmin=lo, vmax=hi, interpolation="nearest", aspect="equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("z [mm]")
    ax.set_title(f"Vertical section at y = {data['section_y_m'] * 1e3:.2f} mm")
    fig.colorbar(im, ax=ax, label="solid fraction [-]")
    fig.tight_layout()
    fig.savefig(out_dir / "section.png", dpi=120)
    plt.close(fig)

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
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
    for ax, (axis, label) in zip(axes, [("z", "height z [mm]"), ("r", "radius from the die axis [mm]"), ("x", "x along the shoe path [mm]")]):
        if axis in profiles:
            p = profiles[axis]
            ax.plot(np.array(p["position_m"]) * 1e3, p["solid_fraction"], marker="o", markersize=3)
        ax.set_xlabel(label)
        ax.set_ylabel("solid fraction [-]")
        ax.grid(alpha=0.3)
    fig.suptitle("Fill density profiles")
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


if __name__ == "__main__":
    if sys.argv[1] == "fill_curve":
        fill_curve(Path(sys.argv[2]), float(sys.argv[3]))
    else:
        {"density": density, "clump": clump, "study": study}[sys.argv[1]](Path(sys.argv[2]))
