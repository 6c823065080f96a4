"""Top view of a demo run: the world's obstacles, the driven path and the lidar hits, and optionally a camera
picture of the world beside it, as one PNG.

Pure matplotlib (Agg canvas, no pyplot state) and numpy, so it runs anywhere without ROS or a display::

    frame = draw_demo(parse_world("worlds/playground.world"), path_xy, scan_xy, "out/demo.png",
                      headings=yaw, title="mbot demo", summary_lines=["distance driven: 4.2 m"])
    frame.to_pixels(path_xy)   # where each path point landed in the PNG, (column, row) from the top left

Obstacles are the convex top-view footprints of the world's collision shapes (planes are the ground, shown
as the axes background). The view is framed on the path, the scan points and the obstacles near them, so an
infinite ground plane or a far-away wall does not shrink the run to a dot.
"""
import json
from dataclasses import asdict, dataclass
from typing import Sequence, Tuple

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Polygon

from .footprints import footprint

IMAGE_SIZE = (1000, 750)  # PNG width, height in pixels
GROUND_COLOUR = "#eef1e6"
OBSTACLE_COLOUR = "#7d8590"
OBSTACLE_EDGE_COLOUR = "#4a5059"
PATH_COLOUR = "#1f5fbf"
SCAN_COLOUR = "#e8590c"
START_COLOUR = "#2b9348"
END_COLOUR = "#c1121f"
NEAR = 1.0  # metres: obstacles this close to the path or a scan point are framed too
MARGIN = 0.5  # metres around everything framed

_DPI = 100
# Axes box: figure fractions across, pixels from the top and bottom; the legend takes the right-hand column.
_LEFT, _WIDTH = 0.07, 0.65
_TOP_PX, _BOTTOM_PX, _SUMMARY_LINE_PX = 36, 52, 16


@dataclass(frozen=True)
class PlotFrame:
    """Where the top view sits in the saved PNG: axes limits in metres and the axes box in pixels.

    ``left``/``right`` are pixel columns and ``top``/``bottom`` pixel rows (origin at the image's top left)
    of the data area edges, which show ``xlim`` and ``ylim``. Equal aspect means metres per pixel are the
    same along both axes.
    """
    width: int
    height: int
    xlim: Tuple[float, float]
    ylim: Tuple[float, float]
    left: float
    right: float
    top: float
    bottom: float

    def to_pixels(self, points_xy) -> np.ndarray:
        """(N, 2) world points in metres -> (N, 2) float (column, row) in the PNG.

        Pixel column c covers [c, c + 1) and row r covers [r, r + 1): floor() gives the pixel a point is in.
        """
        points = np.asarray(points_xy, dtype=float).reshape(-1, 2)
        x_fraction = (points[:, 0] - self.xlim[0]) / (self.xlim[1] - self.xlim[0])
        y_fraction = (points[:, 1] - self.ylim[0]) / (self.ylim[1] - self.ylim[0])
        return np.stack([self.left + x_fraction * (self.right - self.left),
                         self.bottom - y_fraction * (self.bottom - self.top)], axis=1)

    def save(self, path: str) -> None:
        """Write the frame as JSON, e.g. next to the PNG for a check made by another process."""
        with open(path, "w") as stream:
            json.dump(asdict(self), stream, indent=2)

    @classmethod
    def load(cls, path: str) -> "PlotFrame":
        with open(path) as stream:
            fields = json.load(stream)
        return cls(**{key: tuple(value) if isinstance(value, list) else value for key, value in fields.items()})


def draw_demo(world, path_xy, scan_points_xy, out_path: str, title: str = "", summary_lines: Sequence[str] = (),
              headings=None, camera_image=None, camera_caption: str = "") -> PlotFrame:
    """Draw ``world`` (a WorldDescription), the driven path and the lidar hits, and save a PNG at ``out_path``.

    ``path_xy`` (N, 2) and ``scan_points_xy`` (M, 2) are in metres in the odom frame, which is the world frame
    for a robot spawned at the origin. ``headings`` (N,) in radians, if given, puts an arrow on the final
    pose. ``summary_lines`` are printed under the plot. ``camera_image`` (H, W, 3) uint8, if given, is shown
    under the legend with ``camera_caption`` above it. Returns the PlotFrame of the saved image.
    """
    path = _finite_points(path_xy)
    scan = _finite_points(scan_points_xy)
    obstacles = [np.asarray(footprint(shape)) for shape in world.shapes if shape.kind != "plane"]
    obstacles = [outline for outline in obstacles if len(outline) >= 3]

    figure = Figure(figsize=(IMAGE_SIZE[0] / _DPI, IMAGE_SIZE[1] / _DPI), dpi=_DPI)
    canvas = FigureCanvasAgg(figure)
    # A fixed axes box rather than a layout engine: constrained layout moves the box after the equal aspect
    # has been applied, which leaves the two axes' scales apart by a pixel or so.
    summary_px = _SUMMARY_LINE_PX * len(summary_lines)
    bottom_px = _BOTTOM_PX + summary_px
    box_px = (_WIDTH * IMAGE_SIZE[0], IMAGE_SIZE[1] - _TOP_PX - bottom_px)
    axes = figure.add_axes([_LEFT, bottom_px / IMAGE_SIZE[1], _WIDTH, box_px[1] / IMAGE_SIZE[1]])
    axes.set_facecolor(GROUND_COLOUR)

    handles = []
    for outline in obstacles:
        axes.add_patch(Polygon(outline, closed=True, facecolor=OBSTACLE_COLOUR, edgecolor=OBSTACLE_EDGE_COLOUR,
                               linewidth=0.8, zorder=1))
    if obstacles:
        handles.append(Patch(facecolor=OBSTACLE_COLOUR, edgecolor=OBSTACLE_EDGE_COLOUR,
                             label="obstacles (SDF collisions)"))
    if len(scan):
        handles.append(axes.scatter(scan[:, 0], scan[:, 1], s=8, color=SCAN_COLOUR, linewidths=0, zorder=2,
                                    label=f"lidar hits ({len(scan)})"))
    xlim, ylim = _fit_box(*_frame_limits(path, scan, obstacles), box_px)
    if len(path):
        handles += axes.plot(path[:, 0], path[:, 1], color=PATH_COLOUR, linewidth=2.5, solid_capstyle="round",
                             zorder=3, label="driven path (odometry)")
        handles += axes.plot(*path[0], "o", color=START_COLOUR, markersize=9, zorder=4, label="start")
        handles += axes.plot(*path[-1], "s", color=END_COLOUR, markersize=8, zorder=4, label="end")
        if headings is not None and len(headings):
            length = 0.06 * max(xlim[1] - xlim[0], ylim[1] - ylim[0])
            handles.append(_heading_arrow(axes, path[-1], float(np.asarray(headings, dtype=float)[-1]), length))

    axes.set_xlim(*xlim)
    axes.set_ylim(*ylim)
    axes.set_aspect("equal", adjustable="datalim")  # the limits already fit the box; this keeps them equal
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    axes.grid(True, color="white", linewidth=0.8)
    axes.set_axisbelow(True)
    if handles:
        axes.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, fontsize=9)
    if title:
        axes.set_title(title)
    if summary_lines:
        figure.text(_LEFT, (summary_px + _SUMMARY_LINE_PX / 2) / IMAGE_SIZE[1], "\n".join(summary_lines),
                    va="top", ha="left", family="monospace", fontsize=9)

    if camera_image is not None:
        _camera_view(figure, np.asarray(camera_image), camera_caption, bottom_px)

    # Saving draws the figure, which settles the equal-aspect limits that the frame reports.
    figure.savefig(out_path, dpi=_DPI)
    return _plot_frame(canvas, axes)


def _camera_view(figure, image: np.ndarray, caption: str, bottom_px: float):
    """The camera picture in the right-hand column, below the legend, at the bottom of the plot's box."""
    width = 1.0 - _WIDTH - _LEFT - 0.05
    height = width * IMAGE_SIZE[0] / IMAGE_SIZE[1] * image.shape[0] / image.shape[1]
    axes = figure.add_axes([_LEFT + _WIDTH + 0.03, bottom_px / IMAGE_SIZE[1], width, height])
    axes.imshow(image, interpolation="bilinear")
    axes.set_xticks([])
    axes.set_yticks([])
    if caption:
        axes.set_title(caption, fontsize=8)


def _finite_points(points) -> np.ndarray:
    array = np.asarray(points, dtype=float).reshape(-1, 2)
    return array[np.all(np.isfinite(array), axis=1)]


def _heading_arrow(axes, position, heading: float, length: float) -> Line2D:
    """An arrow from ``position`` along ``heading``; returns a legend handle for it (annotations have none)."""
    tip = position + length * np.array([np.cos(heading), np.sin(heading)])
    axes.annotate("", xy=tip, xytext=position, zorder=5,
                  arrowprops=dict(arrowstyle="-|>", color=END_COLOUR, linewidth=2.0, mutation_scale=18))
    return Line2D([], [], marker=r"$\rightarrow$", linestyle="none", color=END_COLOUR, markersize=12,
                  label="final heading")


def _frame_limits(path: np.ndarray, scan: np.ndarray, obstacles) -> Tuple[Tuple[float, float], Tuple[float, float]]:
    """x and y limits: the path and scan points, obstacles within NEAR of them (cropped there), plus MARGIN."""
    points = np.concatenate([path, scan])
    if len(points):
        low, high = points.min(axis=0), points.max(axis=0)
        near_low, near_high = low - NEAR, high + NEAR
        for outline in obstacles:
            outline_low, outline_high = outline.min(axis=0), outline.max(axis=0)
            if np.all(outline_high >= near_low) and np.all(outline_low <= near_high):
                low = np.minimum(low, np.maximum(outline_low, near_low))
                high = np.maximum(high, np.minimum(outline_high, near_high))
    elif obstacles:  # nothing recorded: show the world
        stacked = np.concatenate(obstacles)
        low, high = stacked.min(axis=0), stacked.max(axis=0)
    else:
        low, high = np.zeros(2), np.zeros(2)
    low, high = low - MARGIN, high + MARGIN
    return (float(low[0]), float(high[0])), (float(low[1]), float(high[1]))


def _fit_box(xlim, ylim, box_px) -> Tuple[Tuple[float, float], Tuple[float, float]]:
    """Widen the narrower of the two ranges about its centre so that both have the box's metres per pixel.

    Left to itself, matplotlib's "datalim" adjustment may narrow a range instead, cutting off what was framed.
    """
    scale = max((xlim[1] - xlim[0]) / box_px[0], (ylim[1] - ylim[0]) / box_px[1])
    return tuple((sum(limits) / 2 - scale * size / 2, sum(limits) / 2 + scale * size / 2)
                 for limits, size in zip((xlim, ylim), box_px))


def _plot_frame(canvas: FigureCanvasAgg, axes) -> PlotFrame:
    width, height = canvas.get_width_height()
    # Display coordinates have their origin at the bottom left; PNG rows count from the top.
    (left, bottom), (right, top) = axes.transData.transform([(axes.get_xlim()[0], axes.get_ylim()[0]),
                                                             (axes.get_xlim()[1], axes.get_ylim()[1])])
    return PlotFrame(width=width, height=height, xlim=tuple(map(float, axes.get_xlim())),
                     ylim=tuple(map(float, axes.get_ylim())), left=float(left), right=float(right),
                     top=float(height - top), bottom=float(height - bottom))
