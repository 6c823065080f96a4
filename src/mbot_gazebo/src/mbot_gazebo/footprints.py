"""Top views of a world's collision shapes, for the tools that draw or check maps (the demo picture, the soak
run, the room-scan test): each shape's footprint as a convex polygon in the world XY plane."""
from typing import Tuple

import numpy as np
from mbot_sim_bridge.core.description.world_description import Shape

Polygon = Tuple[Tuple[float, float], ...]


def footprint(shape: Shape, segments: int = 32) -> Polygon:
    """Counter-clockwise convex polygon of the shape seen from above (() for a plane, which has no bounds)."""
    return convex_hull_2d(shape.world_points(segments)[:, :2])


def convex_hull_2d(points: np.ndarray) -> Polygon:
    """Counter-clockwise convex polygon of 2-D points, no repeated first point (scipy's Qhull)."""
    from scipy.spatial import ConvexHull, QhullError  # only the map tools need it; it costs start-up 0.5 s
    # Micrometres: below that, PyBullet's single-precision transforms make straight edges look bent.
    unique = np.unique(np.round(points, 6) + 0.0, axis=0)
    if len(unique) < 3:
        return tuple((float(x), float(y)) for x, y in unique)
    try:
        hull = ConvexHull(unique)
    except QhullError:  # all points on one line: its two ends
        return tuple((float(x), float(y)) for x, y in (unique[0], unique[-1]))
    return tuple((float(x), float(y)) for x, y in unique[hull.vertices])  # 2-D hulls come counter-clockwise
