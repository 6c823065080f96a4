"""Camera pictures as ROS messages carry them: Gazebo's image formats and their encodings, the depth image, the
organized point cloud and image noise, as gazebo_plugins compute them (see ``camera.py`` for the formulas)."""
from typing import Dict, Optional, Tuple

import numpy as np

# <image><format> -> (ROS encoding, bytes per pixel), as GazeboRosCameraUtils::Init.
FORMAT_ENCODINGS: Dict[str, Tuple[str, int]] = {
    "L8": ("mono8", 1), "L_INT8": ("mono8", 1),
    "L16": ("mono16", 2), "L_INT16": ("mono16", 2),
    "R8G8B8": ("rgb8", 3), "RGB_INT8": ("rgb8", 3),
    "B8G8R8": ("bgr8", 3), "BGR_INT8": ("bgr8", 3),
    "R16G16B16": ("rgb16", 6), "RGB_INT16": ("rgb16", 6),
    "BAYER_RGGB8": ("bayer_rggb8", 1), "BAYER_BGGR8": ("bayer_bggr8", 1),
    "BAYER_GBRG8": ("bayer_gbrg8", 1), "BAYER_GRBG8": ("bayer_grbg8", 1),
}
# Channel (0 R, 1 G, 2 B) of each pixel of a 2x2 Bayer tile, row-major.
_BAYER_TILES = {"bayer_rggb8": (0, 1, 1, 2), "bayer_bggr8": (2, 1, 1, 0),
                "bayer_gbrg8": (1, 2, 0, 1), "bayer_grbg8": (1, 0, 2, 1)}

# PointCloud2 layout Gazebo builds with setPointCloud2FieldsByString(2, "xyz", "rgb").
POINT_STEP = 32
POINT_FIELDS = (("x", 0), ("y", 4), ("z", 8), ("rgb", 16))  # all FLOAT32, count 1


def image_encoding(image_format: str) -> Tuple[str, int, bool]:
    """(encoding, bytes per pixel, known); Gazebo publishes an unknown format as bgr8."""
    if image_format in FORMAT_ENCODINGS:
        return FORMAT_ENCODINGS[image_format] + (True,)
    return "bgr8", 3, False


def convert_image(rgb: np.ndarray, encoding: str) -> np.ndarray:
    """An (H, W, 3) uint8 RGB picture as the bytes of ``encoding``: (H, W, channels), C-contiguous."""
    if encoding == "rgb8":
        return np.ascontiguousarray(rgb)
    if encoding == "bgr8":
        return np.ascontiguousarray(rgb[..., ::-1])
    if encoding == "rgb16":
        return rgb.astype("<u2") * 257
    grey = (rgb @ np.array([0.299, 0.587, 0.114], dtype=np.float32)).round().astype(np.uint8)[..., np.newaxis]
    if encoding == "mono8":
        return grey
    if encoding == "mono16":
        return grey.astype("<u2") * 257
    tile = _BAYER_TILES[encoding]
    height, width = rgb.shape[:2]
    rows, cols = np.ogrid[:height, :width]
    channel = np.asarray(tile, dtype=np.intp).reshape(2, 2)[rows % 2, cols % 2]
    return np.take_along_axis(rgb, channel[..., np.newaxis], axis=2)


def linear_depth(buffer: np.ndarray, near: float, far: float) -> np.ndarray:
    """OpenGL depth-buffer values in [0, 1] as z-depth in metres; +inf where nothing was drawn."""
    buffer = np.asarray(buffer, dtype=np.float32)
    with np.errstate(divide="ignore"):
        depth = (far * near) / (far - (far - near) * buffer)
    depth[buffer >= 1.0] = np.inf
    return depth


def depth_in_range(depth: np.ndarray, cutoff: float, cutoff_max: float = np.inf) -> np.ndarray:
    """The depth image: NaN outside the open interval (cutoff, cutoff_max)."""
    valid = (depth > cutoff) & (depth < cutoff_max)
    return np.where(valid, depth, np.float32(np.nan)).astype(np.float32)


def depth_16uc1(depth: np.ndarray) -> np.ndarray:
    """16UC1 millimetres as Gazebo converts (truncating); NaN becomes 0, beyond 65.535 m saturates."""
    millimetres = np.nan_to_num(depth * 1000.0, nan=0.0, posinf=0.0)
    return np.clip(millimetres, 0, 65535).astype("<u2")


def point_cloud(depth: np.ndarray, hfov: float, rgb: Optional[np.ndarray]) -> Tuple[bytes, bool]:
    """Gazebo's organized cloud of an in-range depth image (NaN = no point): (data, is_dense).

    Points are x = z·(i − (W−1)/2)/f, y = z·(j − (H−1)/2)/f, z in the optical frame, f = W/(2·tan(hfov/2));
    rgb bytes 0..2 are the image's first three channels (R, G, B for rgb8), as Gazebo copies them.
    """
    height, width = depth.shape
    f = width / (2.0 * np.tan(hfov / 2.0))
    u = ((np.arange(width, dtype=np.float32) - 0.5 * (width - 1)) / f) if width > 1 else np.zeros(1, np.float32)
    v = ((np.arange(height, dtype=np.float32) - 0.5 * (height - 1)) / f) if height > 1 else np.zeros(1, np.float32)
    points = np.zeros((height, width, POINT_STEP // 4), dtype=np.float32)
    points[..., 0] = depth * u[np.newaxis, :]
    points[..., 1] = depth * v[:, np.newaxis]
    points[..., 2] = depth
    if rgb is not None and rgb.dtype == np.uint8 and rgb.shape[2] in (1, 3):
        colour = points.view(np.uint8).reshape(height, width, POINT_STEP)
        colour[..., 16:19] = rgb if rgb.shape[2] == 3 else rgb[..., :1]
    return points.tobytes(), bool(np.isfinite(depth).all())


def add_image_noise(rgb: np.ndarray, mean: float, stddev: float, rng: np.random.Generator) -> np.ndarray:
    """Gazebo's image noise: N(mean, stddev) in [0, 1] colour units on every channel, clamped."""
    noise = rng.normal(mean * 255.0, stddev * 255.0, rgb.shape).astype(np.float32)
    return np.clip(rgb + noise, 0, 255).astype(np.uint8)
